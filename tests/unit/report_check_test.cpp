// Every number a side reports must be finite (non_finite_report_fields,
// coupler_schedule.cpp). A side that sent NaN in diagnostics.inlet_pressure
// used to give a run that completed (exit 0) with NaN in every history row
// after it. Here: NaN, +inf and -inf in each double field of a StepReport's
// Diagnostics and in its own numbers, named with the field; a Ready the same;
// stable_dt's +inf ("no limit") allowed. Then the coupler with a stand-in
// fluid (in-process) whose diagnostics turn NaN: the run fails naming the
// side, the field and the step, and the history rows before it are kept.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "prescribed_fluid_side.hpp"
#include "prescribed_solid_side.hpp"
#include "solid_scene_rules.hpp"
#include "test_support.hpp"

namespace {

using hfmpm::coupling::non_finite_report_fields;
using ::testing::HasSubstr;
namespace protocol = hfmpm::protocol;
namespace scene = hfmpm::scene;
namespace pb = google::protobuf;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A report as a side sends it, every number finite.
protocol::StepReport sound_report() {
  protocol::StepReport r;
  r.set_step(20);
  r.set_t(1e-3);
  r.set_stable_dt(5e-5);
  r.set_status(protocol::StepReport::OK);
  r.set_compute_s(0.01);
  r.set_exchange_s(0.002);
  auto* d = r.mutable_diagnostics();
  const auto* descriptor = d->GetDescriptor();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const auto* field = descriptor->field(i);
    if (field->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE) d->GetReflection()->SetDouble(d, field, 1.5 + i);
  }
  return r;
}

TEST(ReportCheck, ASoundReportPasses) { EXPECT_EQ(non_finite_report_fields(sound_report()), ""); }

TEST(ReportCheck, EveryDiagnosticThatIsNotFiniteIsNamed) {
  const auto* descriptor = protocol::Diagnostics::descriptor();
  int doubles = 0;
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const auto* field = descriptor->field(i);
    if (field->cpp_type() != pb::FieldDescriptor::CPPTYPE_DOUBLE) continue;
    ++doubles;
    for (const auto& [value, text] : {std::pair{kNaN, "nan"}, {kInf, "inf"}, {-kInf, "-inf"}}) {
      auto report = sound_report();
      report.mutable_diagnostics()->GetReflection()->SetDouble(report.mutable_diagnostics(), field, value);
      EXPECT_EQ(non_finite_report_fields(report), "diagnostics." + field->name() + " = " + text);
    }
  }
  EXPECT_GE(doubles, 11) << "the diagnostics' numbers (kinetic_energy ... released_energy)";
}

TEST(ReportCheck, TheReportsOwnNumbersAndSeveralAtOnce) {
  for (const char* name : {"t", "compute_s", "exchange_s"}) {
    auto report = sound_report();
    const auto* field = report.GetDescriptor()->FindFieldByName(name);
    ASSERT_NE(field, nullptr) << name;
    report.GetReflection()->SetDouble(&report, field, kNaN);
    EXPECT_EQ(non_finite_report_fields(report), std::string(name) + " = nan");
  }
  auto report = sound_report();
  report.set_compute_s(kInf);
  report.mutable_diagnostics()->set_inlet_pressure(kNaN);
  EXPECT_EQ(non_finite_report_fields(report), "diagnostics.inlet_pressure = nan, compute_s = inf")
      << "every one, in field order";
}

TEST(ReportCheck, StableDtMayBePlusInfinityOnly) {
  auto report = sound_report();
  report.set_stable_dt(kInf);  // the side sets no limit
  EXPECT_EQ(non_finite_report_fields(report), "");
  report.set_stable_dt(-kInf);
  EXPECT_EQ(non_finite_report_fields(report), "stable_dt = -inf");
  report.set_stable_dt(kNaN);
  EXPECT_EQ(non_finite_report_fields(report), "stable_dt = nan");
}

TEST(ReportCheck, AReadyIsCheckedTheSameWay) {
  protocol::Ready ready;
  ready.set_stable_dt(kInf);
  ready.mutable_diagnostics()->set_fluid_volume(1e-6);
  EXPECT_EQ(non_finite_report_fields(ready), "");
  ready.mutable_diagnostics()->set_front_position(-kInf);
  EXPECT_EQ(non_finite_report_fields(ready), "diagnostics.front_position = -inf");
}

// The prescribed fluid, whose inlet pressure turns NaN after `steps` steps:
// what a side with a numerical blow-up it does not notice itself would send.
class NaNAfter : public hfmpm::coupling::SideModel {
 public:
  explicit NaNAfter(std::uint64_t steps) : inner_(hfmpm::fluid::make_prescribed_fluid_side()), left_(steps) {}
  void setup(const scene::Scene& scene, const std::string& output_dir) override { inner_->setup(scene, output_dir); }
  double stable_dt() const override { return inner_->stable_dt(); }
  std::string stable_dt_limit() const override { return inner_->stable_dt_limit(); }
  void advance(double dt) override {
    inner_->advance(dt);
    if (left_ > 0) --left_;
  }
  void publish(protocol::DataFrame& frame) override { inner_->publish(frame); }
  void receive(const protocol::DataFrame& frame) override { inner_->receive(frame); }
  hfmpm::SideDiagnostics diagnostics() const override {
    auto d = inner_->diagnostics();
    if (left_ == 0) d.inlet_pressure = kNaN;
    return d;
  }
  void write_output(std::uint64_t frame, double t) override { inner_->write_output(frame, t); }
  void finish() override { inner_->finish(); }

 private:
  std::unique_ptr<hfmpm::coupling::SideModel> inner_;
  std::uint64_t left_;
};

TEST(ReportCheck, ACouplerFailsTheRunOnANaNDiagnosticAndKeepsTheRowsBefore) {
  auto s = hfmpm::coupling::load_scene(hfmpm::test::source("tests/data/minimal.scene"),
                                       {hfmpm::solid::scene_rules(), hfmpm::fluid::scene_rules()});
  s.mutable_time()->set_end_s(0.01);  // 200 steps of 5e-5 s; rows every 1e-3 s (20 steps)
  s.mutable_output()->set_interval_s(1e-3);
  s.mutable_output()->set_hdf5(false);
  s.mutable_coupling()->set_transport(scene::Coupling::INPROC);
  hfmpm::coupling::RunOptions options;
  options.output_dir = hfmpm::test::scratch_dir("nan-report");
  options.progress = false;
  options.inproc_factory = [](protocol::Role role, const scene::Scene&) -> std::unique_ptr<hfmpm::coupling::SideModel> {
    if (role == protocol::SOLID) return hfmpm::solid::make_prescribed_solid_side();
    return std::make_unique<NaNAfter>(50);
  };
  const auto summary = hfmpm::coupling::run_coupled(s, options);
  EXPECT_FALSE(summary.ok);
  EXPECT_THAT(summary.error, HasSubstr("the fluid side reported diagnostics.inlet_pressure = nan in its StepReport "
                                       "for step 60 (t = 0.003 s); every number a side reports must be finite"));
  const std::string manifest = hfmpm::test::read_file(options.output_dir + "/run.json");
  EXPECT_EQ(hfmpm::test::json_string(manifest, "status"), "failed");
  EXPECT_THAT(hfmpm::test::json_string(manifest, "error"), HasSubstr("diagnostics.inlet_pressure = nan"));
  const auto history = hfmpm::test::read_csv(options.output_dir + "/history.csv");
  ASSERT_EQ(history.rows.size(), 3u) << "steps 0, 20 and 40: the rows before the report";
  EXPECT_EQ(history.values("step").back(), 40);
  for (const double p : history.values("inlet_pressure_pa")) EXPECT_TRUE(std::isfinite(p));
}

}  // namespace
