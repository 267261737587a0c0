// Checkpoints damaged, refused or taken at a stop (docs/reliability.md,
// "Damaged checkpoints", "History rows exactly once"): a damaged checkpoint is
// passed over to the one before, or refused naming every damaged file; a
// SIGTERM at a checkpoint step writes each history row once; a checkpoint of
// another scene, program version, format or step is refused, naming it.
// Continued runs: restart_test.cpp.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

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

// Moves the first particle of a solid checkpoint file by 0.5 m in x, in place (the issue's example of
// a damage that used to restart with exit 0 and another history).
void move_a_particle(const std::string& solid_file) {
  std::uint64_t offset = 0;
  {
    const H5Reader file(solid_file);
    offset = file.data_extent("/solid.particles.x").first;
  }
  ASSERT_GT(offset, 0u);
  std::string bytes = read_file(solid_file);
  double x = 0;
  std::memcpy(&x, bytes.data() + offset, sizeof x);
  x += 0.5;
  std::memcpy(bytes.data() + offset, &x, sizeof x);
  write_file(solid_file, bytes);
}

// Damaged checkpoints (docs/reliability.md, "Damaged checkpoints"): the last checkpoint's solid file
// with one particle moved by 0.5 m; the restart names it, passes over it to the checkpoint before and
// ends as the uninterrupted run did. With both kept checkpoints damaged (coupler.pb of the last, the
// fluid's file of the one before) it is refused, naming both, and writes nothing.
TEST(Restart, DamagedCheckpointFallsBackToTheOneBeforeOrIsRefused) {
  const auto dir = scratch_dir("restart-damaged");
  const std::string a = dir + "/a", b = dir + "/b", c = dir + "/c";
  const auto steps = run_with_two_checkpoints(a);
  ASSERT_EQ(steps.size(), 2u);
  fs::copy(a, b, fs::copy_options::recursive);
  fs::copy(a, c, fs::copy_options::recursive);

  const std::string damaged = step_directory(b, steps.back()) + "/solid.h5";
  move_a_particle(damaged);
  const auto restarted = run({bin("hfmpm"), "run", "--restart", b, "--quiet"}, 120);
  ASSERT_EQ(restarted.exit_code, 0) << restarted.err;
  const std::string last_name = step_directory("", steps.back()).substr(1);  // checkpoints/step-N
  const std::string before_name = step_directory("", steps.front()).substr(1);
  EXPECT_NE(restarted.err.find("hfmpm: warning: passing over the damaged checkpoint " + last_name + ": checkpoint " +
                               damaged + " is damaged: dataset solid.particles.x does not match its checksum"),
            std::string::npos)
      << restarted.err;
  EXPECT_NE(restarted.err.find("continuing from the complete checkpoint before it, " + before_name + " (step " +
                               std::to_string(steps.front()) + ")"),
            std::string::npos)
      << restarted.err;
  const std::string manifest = read_file(b + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "completed");
  EXPECT_EQ(json_number(manifest, "restart_step"), static_cast<double>(steps.front()));
  const auto list = manifest.find("\"damaged_checkpoints\": [");
  EXPECT_NE(list, std::string::npos) << manifest;
  EXPECT_NE(
      manifest.find("\"" + last_name + ": checkpoint " + damaged + " is damaged: dataset solid.particles.x", list),
      std::string::npos)
      << manifest;
  EXPECT_NE(read_file(b + "/coupler.log").find("passed over the damaged checkpoint " + last_name), std::string::npos);
  // The same run as the uninterrupted one, and the damaged checkpoint written again, whole.
  expect_same_history(read_csv(a + "/history.csv"), read_csv(b + "/history.csv"));
  std::size_t datasets = 0;
  expect_same_frames(a + "/solid.h5", b + "/solid.h5", datasets);
  expect_same_frames(a + "/fluid.h5", b + "/fluid.h5", datasets);
  EXPECT_GT(datasets, 100u);
  EXPECT_NO_THROW(output::verify_checkpoint(damaged));
  EXPECT_EQ(H5Reader(damaged).f64("/solid.particles.x"),
            H5Reader(step_directory(a, steps.back()) + "/solid.h5").f64("/solid.particles.x"));

  // Both checkpoints damaged: refused before anything starts, each named with its dataset or file.
  const std::string coupler_file = step_directory(c, steps.back()) + "/coupler.pb";
  std::string bytes = read_file(coupler_file);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x10);
  write_file(coupler_file, bytes);
  const std::string fluid_file = step_directory(c, steps.front()) + "/fluid.h5";
  const auto [offset, size] = H5Reader(fluid_file).data_extent("/fluid0.nodes.pressure");
  ASSERT_GT(size, 0u);
  bytes = read_file(fluid_file);
  bytes[offset] = static_cast<char>(bytes[offset] ^ 0x01);
  write_file(fluid_file, bytes);
  const std::string history_before = read_file(c + "/history.csv");
  const auto refused = run({bin("hfmpm"), "run", "--restart", c, "--quiet"}, 60);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(
      refused.err.find("hfmpm: --restart " + c + ": every complete checkpoint in " + c + "/checkpoints is damaged (" +
                       last_name + ": checkpoint " + coupler_file + " is damaged: it does not match its checksum"),
      std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find(before_name + ": checkpoint " + fluid_file +
                             " is damaged: dataset fluid0.nodes.pressure does not match its checksum"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("a checkpoint is used only if coupler.pb and each side's file match their checksums: "
                             "none can continue the run (start the scene afresh)"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(read_file(c + "/history.csv"), history_before);
}

// Whether a process is stopped (SIGSTOP): state T in /proc/PID/stat.
bool stopped(pid_t pid) {
  const std::string stat = read_file("/proc/" + std::to_string(pid) + "/stat");
  const auto paren = stat.rfind(')');
  return paren != std::string::npos && paren + 2 < stat.size() && stat[paren + 2] == 'T';
}

// SIGTERM at a checkpoint step (issue 49: the step's row was written twice, by the output row
// and by the stop, and `--restart` kept both, 3 of 3). The run is held at the checkpoint's block
// (the solid, started by hand, freezes itself at that step with --fault freeze@STEP), SIGTERM goes to
// the coupler while it waits for the block, and the solid is let go: the block ends with its output
// row and checkpoint, and the coupler stops at once. history.csv has that step's row once, and the
// restart from that checkpoint ends with the uninterrupted run's rows, none doubled.
TEST(Restart, SigtermAtACheckpointStepWritesEachRowOnce) {
  const auto dir = scratch_dir("restart-sigterm");
  const std::string a = dir + "/a", b = dir + "/b";
  std::vector<std::string> sets = kSets;
  sets[std::find(sets.begin(), sets.end(), "time.end_s=0.4") - sets.begin()] = "time.end_s=0.2";
  sets[std::find(sets.begin(), sets.end(), "output.checkpoint_interval_s=0.15") - sets.begin()] =
      "output.checkpoint_interval_s=0.06";
  std::vector<std::string> whole_argv{bin("hfmpm"), "run", source("scenarios/kgd-viscosity-ci.scene"),
                                      "--out",      a,     "--quiet"};
  whole_argv.insert(whole_argv.end(), sets.begin(), sets.end());
  const auto whole = run(whole_argv, 120);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const auto steps = complete_checkpoints(a);
  ASSERT_EQ(steps.size(), 2u);
  const std::uint64_t checkpoint = steps.front();

  const std::string endpoint = "ipc://" + dir + "/control";
  std::vector<std::string> coupler_argv{
      bin("hfmpm"), "coupler", source("scenarios/kgd-viscosity-ci.scene"), "--bind", endpoint, "--out", b, "--quiet"};
  coupler_argv.insert(coupler_argv.end(), sets.begin(), sets.end());
  Process coupler(coupler_argv);
  Process solid({bin("hfmpm-solid"), "--connect", endpoint, "--fault", "freeze@" + std::to_string(checkpoint)});
  Process fluid({bin("hfmpm-fluid"), "--connect", endpoint});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!stopped(solid.pid()) && std::chrono::steady_clock::now() < deadline) {
    ASSERT_TRUE(coupler.running()) << coupler.err();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(stopped(solid.pid())) << "the solid did not reach step " << checkpoint;
  ASSERT_LT(history_steps(b).back(), static_cast<double>(checkpoint)) << "the checkpoint's block has not ended";
  ASSERT_EQ(kill(coupler.pid(), SIGTERM), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the coupler's signal thread takes it
  ASSERT_EQ(kill(solid.pid(), SIGCONT), 0);
  ASSERT_TRUE(coupler.wait(60));
  EXPECT_EQ(coupler.exit_code(), 128 + SIGTERM) << coupler.err();
  EXPECT_TRUE(solid.wait(10));
  EXPECT_TRUE(fluid.wait(10));
  const std::string manifest = read_file(b + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "interrupted");
  EXPECT_EQ(json_number(manifest, "interrupted_at_step"), static_cast<double>(checkpoint));
  ASSERT_EQ(complete_checkpoints(b), std::vector<std::uint64_t>{checkpoint});
  // The interrupted history: the checkpoint's row once, last, and the rows of the uninterrupted run before it.
  auto interrupted = history_steps(b);
  EXPECT_EQ(std::count(interrupted.begin(), interrupted.end(), static_cast<double>(checkpoint)), 1)
      << read_file(b + "/history.csv");
  EXPECT_EQ(interrupted.back(), static_cast<double>(checkpoint));
  for (std::size_t i = 1; i < interrupted.size(); ++i) ASSERT_LT(interrupted[i - 1], interrupted[i]) << "row " << i;
  Csv before = read_csv(a + "/history.csv");
  before.rows.resize(interrupted.size());
  expect_same_history(before, read_csv(b + "/history.csv"));

  // Continued from that checkpoint: each step's row once, equal to the uninterrupted run's.
  const auto restarted = run({bin("hfmpm"), "run", "--restart", b, "--quiet"}, 120);
  ASSERT_EQ(restarted.exit_code, 0) << restarted.err;
  EXPECT_EQ(json_number(read_file(b + "/run.json"), "restart_step"), static_cast<double>(checkpoint));
  EXPECT_EQ(json_string(read_file(b + "/run.json"), "previous_status"), "interrupted");
  const auto continued = history_steps(b);
  for (std::size_t i = 1; i < continued.size(); ++i) ASSERT_LT(continued[i - 1], continued[i]) << "row " << i;
  expect_same_history(read_csv(a + "/history.csv"), read_csv(b + "/history.csv"));
}

TEST(Restart, RefusesAnotherSceneAnotherVersionOrNoCheckpoint) {
  const auto dir = scratch_dir("restart-refused");
  const std::string out = dir + "/run";
  const auto steps = run_with_two_checkpoints(out, "0.05");
  ASSERT_EQ(steps.size(), 2u) << "the last two complete checkpoints are kept";
  write_file(dir + "/history-first.csv", read_file(out + "/history.csv"));

  // Another scene: the same file with other --set values.
  std::vector<std::string> other{bin("hfmpm"), "run", "--restart", out, source("scenarios/kgd-viscosity-ci.scene")};
  other.insert(other.end(), kSets.begin(), kSets.end());
  const auto another = run(other, 60);
  EXPECT_EQ(another.exit_code, 2);
  EXPECT_NE(another.err.find("was written for another scene"), std::string::npos) << another.err;

  // No checkpoint at all.
  const auto none = run({bin("hfmpm"), "run", "--restart", dir}, 60);
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.err.find("no complete checkpoint"), std::string::npos) << none.err;

  // A side's file of another step in the last checkpoint: the side refuses it, naming the step.
  const std::string last = step_directory(out, steps.back()), before = step_directory(out, steps.front());
  fs::copy_file(last + "/fluid.h5", dir + "/fluid.h5");
  fs::copy_file(before + "/fluid.h5", last + "/fluid.h5", fs::copy_options::overwrite_existing);
  const auto mixed = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 60);
  EXPECT_EQ(mixed.exit_code, 1);
  EXPECT_NE(mixed.err.find("has step = '" + std::to_string(steps.front()) + "', this run needs '" +
                           std::to_string(steps.back()) + "'"),
            std::string::npos)
      << mixed.err;
  fs::copy_file(dir + "/fluid.h5", last + "/fluid.h5", fs::copy_options::overwrite_existing);

  // Another program version in the coupler's file.
  checkpoint::CouplerState state;
  {
    std::ifstream in(last + "/coupler.pb", std::ios::binary);
    ASSERT_TRUE(state.ParseFromIstream(&in));
  }
  const std::string good = read_file(last + "/coupler.pb");
  const std::string good_version = state.program_version();
  state.set_program_version("0.0.1");
  write_file(last + "/coupler.pb", coupling::coupler_checkpoint_bytes(state));  // with its checksum: not damaged
  const auto version = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 60);
  EXPECT_EQ(version.exit_code, 2);
  EXPECT_NE(version.err.find("was written by hfmpm 0.0.1; this is hfmpm"), std::string::npos) << version.err;

  // A coupler.pb of format 1, as written before checksums (no checksum at its end): refused as
  // another format, not read unchecked and not taken for damage.
  state.set_program_version(good_version);
  state.set_format(1);
  state.clear_checksum();  // parsed from the file; format 1 had no such field
  write_file(last + "/coupler.pb", state.SerializeAsString());
  const auto old_format = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 60);
  EXPECT_EQ(old_format.exit_code, 2);
  EXPECT_NE(old_format.err.find("was written by checkpoint format 1; this is checkpoint format 2: it cannot continue "
                                "that run (start the scene afresh)"),
            std::string::npos)
      << old_format.err;
  state.set_format(coupling::kCouplerCheckpointFormat);

  // A scene in the coupler's file that breaks a rule (its hash made to match,
  // as a foreign or hand-made checkpoint could): refused before any process
  // starts, with the file and the key named as for a scene file.
  state.set_program_version(good_version);
  state.mutable_scene()->mutable_time()->set_end_s(-1);
  state.set_scene_hash(proto::scene_hash(state.scene()));
  write_file(last + "/coupler.pb", coupling::coupler_checkpoint_bytes(state));
  const auto invalid = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 60);
  EXPECT_EQ(invalid.exit_code, 2);
  EXPECT_NE(invalid.err.find("/coupler.pb: time.end_s"), std::string::npos) << invalid.err;
  write_file(last + "/coupler.pb", good);

  // After the refusals the checkpoint still continues the run (with its own scene).
  const auto ok = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 60);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  expect_same_history(read_csv(dir + "/history-first.csv"), read_csv(out + "/history.csv"));
}

}  // namespace
}  // namespace hfmpm::test
