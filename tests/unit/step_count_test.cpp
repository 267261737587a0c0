// The coupler's step count against time.end_s (coupler_schedule.cpp), with the
// stand-in sides as threads (INPROC): scenes the validator would refuse are
// handed to run_coupled directly, as a side reporting such a step would.
// - A step that needs more than 1e9 steps to reach end_s (here 1e-300 s; a
//   stiff solid gives the same) fails the run before the first step, naming
//   dt, the side whose stable step set it and end_s. It used to overflow the
//   step count's conversion to an integer: 0 steps were commanded and the
//   solid was blamed for not making progress.
// - A step longer than end_s is run (one step, ending at t = dt past end_s)
//   and a warning in coupler.log says so: the sides' steps are authoritative
//   here; the validator refuses such a scene when it knows every side's step.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "prescribed_fluid_side.hpp"
#include "prescribed_solid_side.hpp"
#include "solid_scene_rules.hpp"
#include "test_support.hpp"

namespace {

using ::testing::HasSubstr;
namespace scene = hfmpm::scene;

hfmpm::coupling::RunSummary run_inproc(scene::Scene s, const std::string& name) {
  s.mutable_coupling()->set_transport(scene::Coupling::INPROC);
  s.mutable_output()->set_hdf5(false);
  hfmpm::coupling::RunOptions options;
  options.output_dir = hfmpm::test::scratch_dir(name);
  options.progress = false;
  options.inproc_factory = [](hfmpm::protocol::Role role, const scene::Scene&) {
    return role == hfmpm::protocol::SOLID ? hfmpm::solid::make_prescribed_solid_side()
                                          : hfmpm::fluid::make_prescribed_fluid_side();
  };
  auto summary = hfmpm::coupling::run_coupled(s, options);
  summary.error += "\n" + hfmpm::test::read_file(options.output_dir + "/coupler.log");
  return summary;
}

scene::Scene minimal() {
  return hfmpm::coupling::load_scene(hfmpm::test::source("tests/data/minimal.scene"),
                                     {hfmpm::solid::scene_rules(), hfmpm::fluid::scene_rules()});
}

TEST(StepCount, TooManyStepsFailTheRunNamingTheStepAndEndTime) {
  auto s = minimal();
  s.mutable_solid()->mutable_prescribed_crack()->set_stable_dt_s(1e-300);
  const auto summary = run_inproc(s, "step_count_many");
  EXPECT_FALSE(summary.ok);
  EXPECT_THAT(summary.error, HasSubstr("the run would need 2e+300 steps to reach time.end_s"));
  EXPECT_THAT(summary.error, HasSubstr("dt = 5e-301 s"));
  EXPECT_THAT(summary.error, HasSubstr("time.end_s = 1 s"));
  EXPECT_THAT(summary.error, HasSubstr("at most 1e+09 steps"));
  EXPECT_THAT(summary.error, HasSubstr("the stable step of the solid"));
  EXPECT_EQ(summary.steps, 0u);
}

TEST(StepCount, OneStepPastTheEndIsRunAndReported) {
  auto s = minimal();
  s.mutable_solid()->mutable_prescribed_crack()->set_stable_dt_s(10);
  s.mutable_fluid()->mutable_prescribed_pressure()->set_stable_dt_s(10);
  const auto summary = run_inproc(s, "step_count_one");
  EXPECT_TRUE(summary.ok) << summary.error;
  EXPECT_EQ(summary.steps, 1u);
  EXPECT_DOUBLE_EQ(summary.t, 5.0);  // safety factor 0.5 x 10 s
  EXPECT_THAT(summary.error, HasSubstr("warning: a single step reaches the end"));
  EXPECT_THAT(summary.error, HasSubstr("ends at t = 5 s, past time.end_s"));
}

}  // namespace
