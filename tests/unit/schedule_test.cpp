// The schedule of output rows and checkpoints (next_time_after,
// coupler_schedule.cpp): the next time after t, from the last one, by whole
// intervals. The coupler used to add the interval until the time passed t:
// with output.interval_s = 1e-300 (or 1e-17 against t = 1) the sum never
// changed and the coupler spun forever. Now the usual case gives the same
// sums as before (rows at the same times, bit for bit), many intervals are
// taken at once, and the time returned is past t whatever the interval. The
// validator refuses such intervals (output_interval_tiny.scene and its
// neighbours in tests/data/bad_scenes); a coupler handed one anyway ends.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/checkpoint.hpp"
#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "prescribed_fluid_side.hpp"
#include "prescribed_solid_side.hpp"
#include "solid_scene_rules.hpp"
#include "test_support.hpp"

namespace {

using hfmpm::coupling::next_time_after;
namespace scene = hfmpm::scene;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The loop the coupler had, for intervals it can add.
double added_one_by_one(double next, double interval, double t) {
  while (next <= t * (1 + 1e-12)) next += interval;
  return next;
}

// A run's steps as the coupler counts them (t summed step by step), the
// schedule advanced after each step as after an output row: the same times as
// the loop before, bit for bit, with one interval per row and with several
// per step (a step longer than the interval).
TEST(Schedule, TheUsualCaseGivesTheSameTimesAsBefore) {
  for (const auto& [dt, interval] : {std::pair{5e-5, 0.01}, {1e-4, 0.05}, {3e-7, 1e-5}, {5e-5, 1e-5}, {1e-3, 1.3e-4}}) {
    SCOPED_TRACE("dt " + std::to_string(dt) + ", interval " + std::to_string(interval));
    double t = 0, next = interval, before = interval;
    for (int step = 0; step < 20000; ++step) {
      t += dt;
      if (next > t * (1 + 1e-12)) continue;  // no row at this step
      next = next_time_after(next, interval, t);
      before = added_one_by_one(before, interval, t);
      ASSERT_EQ(next, before) << "step " << step;
    }
  }
}

// A step of 0.5 s against an interval of 1e-6 s: 500,000 intervals at once,
// the time a whole number of intervals, the first past t.
TEST(Schedule, ManyIntervalsAtOnceAreWholeIntervals) {
  const double interval = 1e-6, t = 0.5;
  const double next = next_time_after(interval, interval, t);
  EXPECT_GT(next, t * (1 + 1e-12));
  EXPECT_LE(next - t, interval * (1 + 1e-6));
  EXPECT_NEAR(next / interval, std::round(next / interval), 1e-6);
}

// Intervals that vanish against t (1e-300 and 1e-17 at t = 1, the smallest
// double, one at t = 1e300) and ones that are not intervals at all: the
// time returned is finite and past t, so the step loop always goes on.
TEST(Schedule, AnIntervalBelowTheTimesPrecisionStillMovesPastT) {
  for (const double t : {1.0, 0.37, 1e300}) {
    for (const double interval : {1e-300, 1e-17, 4.9e-324, 0.0, -1.0, kNaN}) {
      SCOPED_TRACE("t " + std::to_string(t) + ", interval " + std::to_string(interval));
      const double limit = t * (1 + 1e-12);
      const double next = next_time_after(t, interval, t);
      EXPECT_GT(next, limit);
      EXPECT_TRUE(std::isfinite(next));
      EXPECT_LE(next, std::nextafter(limit, kInf) + (interval > 0 ? 8 * interval : 0)) << "not far past t";
    }
  }
  // A next time already past t is kept.
  EXPECT_EQ(next_time_after(2.0, 1e-300, 1.0), 2.0);
}

// The floor the validator puts on both intervals: end_s / 1e9, the step of
// the longest run allowed; against any time up to end_s such an interval is
// added one by one without vanishing.
TEST(Schedule, TheValidatorsFloorIsAddedWithoutVanishing) {
  for (const double end : {1e-6, 1.0, 3600.0, 1e12}) {
    const double interval = hfmpm::coupling::min_time_interval(end);
    EXPECT_EQ(interval, end / hfmpm::coupling::kMaxRunSteps);
    EXPECT_GT(end + interval, end);
    EXPECT_EQ(next_time_after(end, interval, end), end + interval);
  }
}

struct Run {
  hfmpm::coupling::RunSummary summary;
  std::size_t rows = 0;  // in history.csv
};

Run run_inproc(scene::Scene s, const std::string& name) {
  s.mutable_coupling()->set_transport(scene::Coupling::INPROC);
  s.mutable_output()->set_hdf5(false);
  hfmpm::coupling::RunOptions options;
  options.output_dir = hfmpm::test::scratch_dir(name);
  options.progress = false;
  options.inproc_factory = [](hfmpm::protocol::Role role, const scene::Scene&) {
    return role == hfmpm::protocol::SOLID ? hfmpm::solid::make_prescribed_solid_side()
                                          : hfmpm::fluid::make_prescribed_fluid_side();
  };
  Run run{hfmpm::coupling::run_coupled(s, options)};
  run.summary.error += "\n" + hfmpm::test::read_file(options.output_dir + "/coupler.log");
  run.rows = hfmpm::test::read_csv(options.output_dir + "/history.csv").rows.size();
  return run;
}

// Handed to the coupler past the validator (as a scene of an older build
// would be): the run ends, with a row at every step, as for any interval
// shorter than the step.
TEST(Schedule, ACouplerGivenAVanishingIntervalEnds) {
  for (const double interval : {1e-300, 1e-17}) {
    auto s = hfmpm::coupling::load_scene(hfmpm::test::source("tests/data/minimal.scene"),
                                         {hfmpm::solid::scene_rules(), hfmpm::fluid::scene_rules()});
    s.mutable_time()->set_end_s(0.01);  // 200 steps of 5e-5 s
    s.mutable_output()->set_interval_s(interval);
    const auto run = run_inproc(s, "tiny-interval");
    EXPECT_TRUE(run.summary.ok) << run.summary.error;
    EXPECT_EQ(run.summary.steps, 200u);
    EXPECT_EQ(run.rows, 201u) << "a row at the start and after every step";
  }
}

// A restart keeps history.csv's rows up to its checkpoint, one per step: a history written before
// the fix of issue 49 (a run stopped by a signal right after an output row wrote that step twice,
// the second row with the next block's dt) continues with the first row only, as the uninterrupted
// run has it. truncate_history returns the step of the last row kept.
TEST(Schedule, ARestartKeepsOneRowPerStep) {
  const std::string dir = hfmpm::test::scratch_dir("truncate-history");
  const std::string path = dir + "/history.csv";
  const std::string header = "time_s,step,crack_length_m,dt_s\n";
  const std::string rows = "0,0,0.1,5e-05\n0.001,20,0.1,5e-05\n0.002,40,0.1,5e-05\n";
  const std::string doubled = "0.002,40,0.1,6e-05\n";
  const std::string after = "0.003,60,0.1,6e-05\n0.004,80,0.";  // past the checkpoint, the last cut short
  hfmpm::test::write_file(path, header + rows + doubled + after);
  EXPECT_EQ(hfmpm::coupling::truncate_history(path, 40), std::optional<std::uint64_t>(40));
  EXPECT_EQ(hfmpm::test::read_file(path), header + rows);
  hfmpm::test::write_file(path, header + rows + doubled + after);
  EXPECT_EQ(hfmpm::coupling::truncate_history(path, 50), std::optional<std::uint64_t>(40));
  EXPECT_EQ(hfmpm::test::read_file(path), header + rows);
  EXPECT_EQ(hfmpm::coupling::truncate_history(path, 60), std::optional<std::uint64_t>(40));  // idempotent
  EXPECT_EQ(hfmpm::test::read_file(path), header + rows);
  hfmpm::test::write_file(path, header);
  EXPECT_EQ(hfmpm::coupling::truncate_history(path, 40), std::nullopt);
  EXPECT_EQ(hfmpm::test::read_file(path), header);
}

}  // namespace
