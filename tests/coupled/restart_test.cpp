// Checkpoint and restart (docs/reliability.md, "Checkpoint and restart"): a
// coupled MPM run killed with SIGKILL after a checkpoint and continued with
// `hfmpm run --restart DIR` ends with the uninterrupted run's history,
// exchange data and HDF5 frames, bit for bit, with either coupling scheme,
// two wings, a released growth step or sides started by hand. Damaged,
// refused and stopped checkpoints: restart_checkpoint_test.cpp.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <thread>

#include "coupled_support.hpp"
#include "h5_reader.hpp"
#include "hfmpm/checkpoint.pb.h"
#include "hfmpm/coupling/checkpoint.hpp"
#include "hfmpm/output/checkpoint_file.hpp"
#include "hfmpm/proto/envelope.hpp"
#include "restart_support.hpp"

namespace hfmpm::test {
namespace {

namespace fs = std::filesystem;

std::uint64_t last_history_step(const std::string& out) {
  std::ifstream in(out + "/history.csv");
  std::string line, last;
  while (std::getline(in, line)) last = line;
  const auto comma = last.find(',');
  if (comma == std::string::npos) return 0;
  try {
    return std::stoull(last.substr(comma + 1));
  } catch (const std::exception&) {
    return 0;  // the header, or a row being written
  }
}

// The rows of an exchange log (17 significant digits) after `step`.
std::vector<std::string> exchange_rows_after(const std::string& path, std::uint64_t step) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> rows;
  std::getline(in, line);
  while (std::getline(in, line)) {
    if (std::stoull(line.substr(0, line.find(','))) > step) rows.push_back(line);
  }
  return rows;
}

TEST(Restart, AfterKillNineEqualsTheUninterruptedRun) {
  const auto dir = scratch_dir("restart");
  const std::string a = dir + "/a", b = dir + "/b";
  const auto whole = run(run_args(a), 120);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  ASSERT_EQ(complete_checkpoints(a).size(), 2u) << "checkpoints at 0.15 and 0.3 s";

  // The same run, killed with SIGKILL once it has written a history row past its first checkpoint.
  std::uint64_t checkpoint = 0;
  {
    Process coupler(run_args(b));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      const auto done = complete_checkpoints(b);
      if (!done.empty() && last_history_step(b) > done.back()) {
        checkpoint = done.back();
        break;
      }
      ASSERT_TRUE(coupler.running()) << "the run ended before it could be killed: " << coupler.err();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_GT(checkpoint, 0u) << "no checkpoint within 60 s";
    ASSERT_EQ(kill(coupler.pid(), SIGKILL), 0);
    ASSERT_TRUE(coupler.wait(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the sides die with it (parent-death signal)
  ASSERT_GT(last_history_step(b), checkpoint) << "the killed run's history has rows past its checkpoint";
  if (complete_checkpoints(b).back() != checkpoint) checkpoint = complete_checkpoints(b).back();

  const auto restarted = run({bin("hfmpm"), "run", "--restart", b, "--quiet"}, 120);
  ASSERT_EQ(restarted.exit_code, 0) << restarted.err;
  // The killed run's run.json said "running"; the restart found its coupler gone and says so.
  EXPECT_NE(restarted.err.find("stopped without finishing (coupler killed?): its coupler (pid"), std::string::npos)
      << restarted.err;
  EXPECT_EQ(json_string(read_file(b + "/run.json"), "previous_status"), "stopped without finishing (coupler killed?)");

  // history.csv: the same rows (none twice, none missing) and values, but the wall clock.
  expect_same_history(read_csv(a + "/history.csv"), read_csv(b + "/history.csv"));
  // The data that crossed the data plane, 17 digits: after the checkpoint, and the whole log
  // (the restart keeps the rows up to the checkpoint and drops the killed run's later ones).
  for (const std::string role : {"solid", "fluid"}) {
    const auto x = exchange_rows_after(a + "/" + role + "_received.csv", checkpoint);
    const auto y = exchange_rows_after(b + "/" + role + "_received.csv", checkpoint);
    EXPECT_GT(x.size(), 100u);
    EXPECT_EQ(x, y) << role << "_received.csv after step " << checkpoint;
    EXPECT_EQ(read_file(a + "/" + role + "_received.csv"), read_file(b + "/" + role + "_received.csv")) << role;
  }
  // The logs go on: the first run's lines are kept.
  const std::string log = read_file(b + "/coupler.log");
  EXPECT_NE(log.find("checkpoint checkpoints/step-"), std::string::npos) << log;
  EXPECT_NE(log.find("restarting from checkpoints/step-"), std::string::npos) << log;
  // The side's frame files: every frame, bit for bit (the killed run's frames past the checkpoint were dropped).
  std::size_t datasets = 0;
  expect_same_frames(a + "/solid.h5", b + "/solid.h5", datasets);
  expect_same_frames(a + "/fluid.h5", b + "/fluid.h5", datasets);
  EXPECT_GT(datasets, 100u);
  const std::string manifest = read_file(b + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "completed");
  EXPECT_EQ(json_number(manifest, "restart_step"), static_cast<double>(checkpoint));
  EXPECT_NE(json_string(manifest, "restarted_from").find("checkpoints/step-"), std::string::npos);
}

// The other schemes: IMPLICIT (a block ends with the solid's next step begun, its grid
// mid-step) on kgd-paper-field-ci, and Jacobi with an exchange every second step. The run's
// directory is copied, its last checkpoint removed, and the copy continued from the one
// before: it must end as the original did.
void expect_continued_run_equal(const std::vector<std::string>& run_argv, const std::string& dir) {
  const std::string a = dir + "/a", b = dir + "/b";
  std::vector<std::string> argv = run_argv;
  argv.insert(argv.end(), {"--out", a, "--quiet"});
  const auto whole = run(argv, 120);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const auto steps = complete_checkpoints(a);
  ASSERT_EQ(steps.size(), 2u);
  fs::copy(a, b, fs::copy_options::recursive);
  std::ostringstream last;
  last << b << "/checkpoints/step-" << std::setw(12) << std::setfill('0') << steps.back();
  fs::remove_all(last.str());
  const auto restarted = run({bin("hfmpm"), "run", "--restart", b, "--quiet"}, 120);
  ASSERT_EQ(restarted.exit_code, 0) << restarted.err;
  EXPECT_EQ(json_number(read_file(b + "/run.json"), "restart_step"), static_cast<double>(steps.front()));
  expect_same_history(read_csv(a + "/history.csv"), read_csv(b + "/history.csv"));
  std::size_t datasets = 0;
  expect_same_frames(a + "/solid.h5", b + "/solid.h5", datasets);
  expect_same_frames(a + "/fluid.h5", b + "/fluid.h5", datasets);
  for (const std::string role : {"solid", "fluid"}) {
    EXPECT_EQ(read_file(a + "/" + role + "_received.csv"), read_file(b + "/" + role + "_received.csv")) << role;
  }
}

TEST(Restart, ImplicitAndJacobiSchemesContinueBitForBit) {
  const auto dir = scratch_dir("restart-schemes");
  expect_continued_run_equal(
      {bin("hfmpm"), "run", source("scenarios/kgd-paper-field-ci.scene"), "--set", "time.end_s=30", "--set",
       "output.interval_s=2", "--set", "output.checkpoint_interval_s=10", "--set", "output.exchange_log=true"},
      dir + "/implicit");
  expect_continued_run_equal(
      with_kgd_viscosity_ci_method(
          {bin("hfmpm"), "run", source("scenarios/kgd-viscosity-ci.scene"), "--set", "time.end_s=0.2", "--set",
           "output.interval_s=0.05", "--set", "output.checkpoint_interval_s=0.06", "--set", "output.exchange_log=true",
           "--set", "coupling.scheme=JACOBI", "--set", "coupling.exchange_interval=2", "--set",
           "fluid.mpm.bulk_modulus_pa=2e6"}),  // Jacobi is explicit: the 2 MPa stand-in, not the scene's water
      dir + "/jacobi");
}

// A crack entered inside the body (kgd-two-wing-ci, to 1 s): the fluid's two
// wings and their junction, the solid's wetted interval and both tips'
// growth waits go through a checkpoint; restarted at 0.4 s, the run passes
// the first growth of both tips (0.5-0.75 s) as the uninterrupted one did.
TEST(Restart, TwoWingCrackContinuesBitForBit) {
  expect_continued_run_equal(
      {bin("hfmpm"), "run", source("scenarios/kgd-two-wing-ci.scene"), "--set", "time.end_s=1", "--set",
       "output.interval_s=0.1", "--set", "output.checkpoint_interval_s=0.4", "--set", "output.exchange_log=true"},
      scratch_dir("restart-two-wing"));
}

// A growth step being released (kgd-toughness-ci, fracture.release_transits:
// its first step, at 0.54-0.55 s, has its face load applied over 0.024 s):
// the release's start, duration and length go through the checkpoint at
// 0.56 s (the earlier of the two kept, at 0.56 and 0.84 s, which the restart
// takes; checkpoints fall on output rows, hence rows every 0.01 s), and each
// crack particle's unloaded share is derived again on loading. Without
// either, the history differs from 0.57 s on (checked by hand).
TEST(Restart, ReleasedGrowthStepContinuesBitForBit) {
  expect_continued_run_equal(
      {bin("hfmpm"), "run", source("scenarios/kgd-toughness-ci.scene"), "--set", "time.end_s=0.9", "--set",
       "output.interval_s=0.01", "--set", "output.checkpoint_interval_s=0.28", "--set", "output.exchange_log=true"},
      scratch_dir("restart-release"));
}

// `hfmpm coupler --restart DIR` with the sides started by hand: the coupler
// continues from its checkpoint, each side reads its own file under its output
// directory (here the coupler's, from the Welcome), and the run ends as the
// uninterrupted one did.
TEST(Restart, CouplerWithSidesStartedByHandContinues) {
  const auto dir = scratch_dir("restart-join");
  const std::string a = dir + "/a", b = dir + "/b";
  const auto steps = run_with_two_checkpoints(a);
  ASSERT_EQ(steps.size(), 2u);
  fs::copy(a, b, fs::copy_options::recursive);
  std::ostringstream last;
  last << b << "/checkpoints/step-" << std::setw(12) << std::setfill('0') << steps.back();
  fs::remove_all(last.str());

  const std::string endpoint = "ipc://" + dir + "/control";
  Process coupler({bin("hfmpm"), "coupler", "--restart", b, "--bind", endpoint, "--quiet"});
  Process solid({bin("hfmpm-solid"), "--connect", endpoint});
  Process fluid({bin("hfmpm-fluid"), "--connect", endpoint});
  ASSERT_TRUE(coupler.wait(120));
  EXPECT_EQ(coupler.exit_code(), 0) << coupler.err();
  EXPECT_TRUE(solid.wait(10));
  EXPECT_TRUE(fluid.wait(10));
  EXPECT_EQ(solid.exit_code(), 0) << solid.err();
  const std::string manifest = read_file(b + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "completed");
  EXPECT_EQ(json_number(manifest, "restart_step"), static_cast<double>(steps.front()));
  EXPECT_EQ(json_string(manifest, "previous_status"), "completed");
  expect_same_history(read_csv(a + "/history.csv"), read_csv(b + "/history.csv"));
  std::size_t datasets = 0;
  expect_same_frames(a + "/solid.h5", b + "/solid.h5", datasets);
  expect_same_frames(a + "/fluid.h5", b + "/fluid.h5", datasets);
  EXPECT_GT(datasets, 100u);

  // --restart is for run and coupler only.
  const auto validate = run({bin("hfmpm"), "validate", "--restart", b}, 20);
  EXPECT_EQ(validate.exit_code, 2);
  EXPECT_NE(validate.err.find("--restart is for 'hfmpm run' and 'hfmpm coupler'"), std::string::npos) << validate.err;
}

}  // namespace
}  // namespace hfmpm::test
