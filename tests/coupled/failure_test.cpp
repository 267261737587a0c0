// Failures of a coupled run: a side that exits, crashes, is killed, hangs,
// freezes, speaks another protocol version or sends garbage; a dead coupler.
// Each must be detected within a bounded time, name the failed side and the
// step, leave history.csv readable, and leave no process running.
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "failure_support.hpp"

namespace hfmpm::test {
namespace {

struct FailedRun {
  RunResult result;
  std::string out;
  double wall_s = 0;
};

FailedRun run_with(const std::string& side, const std::vector<std::string>& side_args, double end_s = 0.2) {
  FailedRun failed;
  failed.out = scratch_dir("fail");
  std::string list;
  for (const auto& a : side_args) list += (list.empty() ? "\"" : ", \"") + a + "\"";
  std::vector<std::string> extra = kFastLiveness;
  extra.insert(extra.end(), {"--set", "coupling." + side + "_args=[" + list + "]"});
  const auto start = std::chrono::steady_clock::now();
  failed.result = run_scene(prescribed_scene(end_s), failed.out, extra, 60);
  failed.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return failed;
}

// What every failure must leave behind.
void expect_clean_failure(const FailedRun& run, const std::string& side, const std::string& detail,
                          std::size_t min_rows = 1) {
  EXPECT_FALSE(run.result.timed_out);
  EXPECT_EQ(run.result.exit_code, 1) << run.result.err;
  EXPECT_NE(run.result.err.find("the " + side + " side"), std::string::npos) << run.result.err;
  EXPECT_NE(run.result.err.find("step"), std::string::npos) << run.result.err;
  EXPECT_NE(run.result.err.find(detail), std::string::npos) << run.result.err;
  const Csv history = read_csv(run.out + "/history.csv");  // throws if unreadable
  EXPECT_GE(history.rows.size(), min_rows);
  const std::string manifest = read_file(run.out + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "failed");
  EXPECT_NE(json_string(manifest, "error").find(side), std::string::npos);
  for (const char* name : {"solid_pid", "fluid_pid"}) {
    const auto pid = static_cast<pid_t>(json_number(manifest, name));
    if (pid > 0) {
      EXPECT_FALSE(pid_alive(pid)) << name << " " << pid << " still running";
    }
  }
}

TEST(Failure, FluidExitsAbruptly) {
  const auto run = run_with("fluid", {"--fault", "exit@50"});
  expect_clean_failure(run, "fluid", "exited with status 7");
  EXPECT_LT(run.wall_s, kBusyMarginS);  // no timeout involved
}

TEST(Failure, SolidCrashes) {
  const auto run = run_with("solid", {"--fault", "crash@50"});
  expect_clean_failure(run, "solid", "SIGABRT");
}

TEST(Failure, FluidHangsWhileTheSolidWaitsForIt) {
  const auto run = run_with("fluid", {"--fault", "hang@50"});
  expect_clean_failure(run, "fluid", "stopped making progress");
  // Both sides are silent on the data plane, but only the fluid is to blame.
  EXPECT_EQ(run.result.err.find("solid and fluid"), std::string::npos) << run.result.err;
  EXPECT_LT(run.wall_s, 2 + kBusyMarginS);  // the 2 s step timeout
}

TEST(Failure, SolidFreezes) {
  const auto run = run_with("solid", {"--fault", "freeze@50"});
  expect_clean_failure(run, "solid", "stopped answering");
  EXPECT_LT(run.wall_s, 1 + kBusyMarginS);  // the 1 s heartbeat timeout
}

TEST(Failure, FluidWithAnotherProtocolVersionIsRejected) {
  const auto run = run_with("fluid", {"--protocol-version", "2"});
  // Refused at the handshake: history.csv has its header and no row yet.
  expect_clean_failure(run, "fluid", "speaks protocol version 2; this coupler speaks version 1", 0);
}

// A side built before scene schema versions (it sends 0) or with another
// scene.proto is refused at the handshake with the versions named.
TEST(Failure, SideWithAnotherSceneSchemaIsRejected) {
  const auto older = run_with("solid", {"--scene-schema-version", "0"});
  expect_clean_failure(older, "solid", "was built with scene schema version 0 (before scenes were versioned)", 0);
  const auto newer = run_with("fluid", {"--scene-schema-version", "99"});
  expect_clean_failure(newer, "fluid", "was built with scene schema version 99; this coupler's scenes are version 10",
                       0);
}

// A side repeats its Hello until the coupler answers (a Hello sent on a
// connection the coupler's ROUTER refused is lost); the coupler takes the
// first and ignores the others, and the run goes on as if there were one.
TEST(Failure, RepeatedHellosAreIgnored) {
  const auto run = run_with("fluid", {"--extra-hellos", "3"});
  EXPECT_EQ(run.result.exit_code, 0) << run.result.err;
  EXPECT_NE(read_file(run.out + "/coupler.log").find("fluid side: a repeated Hello ignored"), std::string::npos);
  EXPECT_EQ(json_string(read_file(run.out + "/run.json"), "status"), "completed");
}

TEST(Failure, GarbageFromASideIsRejected) {
  const auto run = run_with("fluid", {"--fault", "garbage@30"});
  expect_clean_failure(run, "fluid", "malformed message from the fluid side");
}

TEST(Failure, NonFiniteDataOnTheDataPlaneIsRejected) {
  const auto run = run_with("solid", {"--fault", "nan@30"});
  // The fluid refuses the frame and says why; the coupler names it.
  expect_clean_failure(run, "fluid", "'width[0]' is not finite");
}

void kill_side_mid_run(const std::string& side) {
  const auto out = scratch_dir("kill");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  std::vector<std::string> argv{bin("hfmpm"), "run", scene, "--out", out, "--quiet"};
  argv.insert(argv.end(), kFastLiveness.begin(), kFastLiveness.end());
  Process coupler(argv);
  pid_t pid = 0;
  for (int i = 0; i < 500 && (pid == 0 || history_rows(out) < 3); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    pid = static_cast<pid_t>(json_number(read_file(out + "/run.json"), side + "_pid"));
  }
  ASSERT_GT(pid, 0);
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  ASSERT_TRUE(coupler.wait(10)) << "coupler did not notice the killed " << side;
  FailedRun run{{coupler.exit_code(), coupler.term_signal(), false, coupler.out(), coupler.err()}, out, 0};
  expect_clean_failure(run, side, "killed by signal 9 (SIGKILL)");
}

TEST(Failure, SolidKilledWithSignal9) { kill_side_mid_run("solid"); }
TEST(Failure, FluidKilledWithSignal9) { kill_side_mid_run("fluid"); }

TEST(Failure, SidesDieWithAKilledCoupler) {
  const auto out = scratch_dir("coupler-dies");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  Process coupler({bin("hfmpm"), "run", scene, "--out", out, "--quiet"});
  pid_t solid = 0, fluid = 0;
  for (int i = 0; i < 500 && (solid == 0 || fluid == 0 || history_rows(out) < 3); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::string manifest = read_file(out + "/run.json");
    solid = static_cast<pid_t>(json_number(manifest, "solid_pid"));
    fluid = static_cast<pid_t>(json_number(manifest, "fluid_pid"));
  }
  ASSERT_GT(solid, 0);
  kill(coupler.pid(), SIGKILL);
  coupler.wait(5);
  for (int i = 0; i < 200 && (pid_alive(solid) || pid_alive(fluid)); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_FALSE(pid_alive(solid));
  EXPECT_FALSE(pid_alive(fluid));
  EXPECT_GE(read_csv(out + "/history.csv").rows.size(), 1u);
}

// A coupler killed with SIGKILL cannot write anything: its run.json stays at
// "running". The next hfmpm that reads the directory (hfmpm status, hfmpm run
// --restart) finds the recorded coupler gone and records the run as stopped.
TEST(Failure, AKilledCouplerIsRecordedByTheNextHfmpm) {
  const auto out = scratch_dir("coupler-killed");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  Process coupler({bin("hfmpm"), "run", scene, "--out", out, "--quiet"});
  for (int i = 0; i < 500 && json_string(read_file(out + "/run.json"), "status") != "running"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(json_string(read_file(out + "/run.json"), "status"), "running");
  const std::string pid = std::to_string(coupler.pid());

  // While it runs: reported as running, with its pid; run.json untouched; no restart.
  const auto live = run({bin("hfmpm"), "status", out}, 20);
  EXPECT_EQ(live.exit_code, 0) << live.err;
  EXPECT_NE(live.out.find(": running (coupler pid " + pid + " on "), std::string::npos) << live.out;
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "running");
  const auto restart_live = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 20);
  EXPECT_EQ(restart_live.exit_code, 2);
  EXPECT_NE(restart_live.err.find("is still running (coupler pid " + pid), std::string::npos) << restart_live.err;
  EXPECT_TRUE(coupler.running()) << "the refused restart left the run alone";

  ASSERT_EQ(kill(coupler.pid(), SIGKILL), 0);
  ASSERT_TRUE(coupler.wait(5));
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "running") << "SIGKILL leaves it as it was";

  const auto found = run({bin("hfmpm"), "status", out}, 20);
  EXPECT_EQ(found.exit_code, 0) << found.err;
  EXPECT_NE(found.out.find("stopped without finishing (coupler killed?): run.json said \"running\", but its coupler "
                           "(pid " +
                           pid + ") no longer exists"),
            std::string::npos)
      << found.out;
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "stopped without finishing (coupler killed?)");
  EXPECT_EQ(json_string(manifest, "status_before_check"), "running");
  EXPECT_NE(json_string(manifest, "stopped_reason").find("no longer exists"), std::string::npos) << manifest;
  EXPECT_EQ(json_number(manifest, "coupler_pid"), static_cast<double>(coupler.pid())) << "the rest is kept";
  EXPECT_GE(read_csv(out + "/history.csv").rows.size(), 1u);
  // Recorded: the next reader sees a final status.
  const auto again = run({bin("hfmpm"), "status", out}, 20);
  EXPECT_EQ(again.out, out + ": stopped without finishing (coupler killed?)\n") << again.out;

  // A pid that now belongs to another process (this test, started at another
  // time than the start time recorded) is not the run's coupler.
  std::string text = read_file(out + "/run.json");
  auto set_field = [&](const std::string& key, const std::string& value) {
    const auto at = text.find("\"" + key + "\": ");
    ASSERT_NE(at, std::string::npos) << key;
    const auto end = text.find_first_of(",\n", at);
    text.replace(at, end - at, "\"" + key + "\": " + value);
  };
  set_field("status", "\"running\"");
  set_field("coupler_pid", std::to_string(getpid()));
  set_field("coupler_start_ticks", "\"1\"");
  write_file(out + "/run.json", text);
  const auto reused = run({bin("hfmpm"), "status", out}, 20);
  EXPECT_NE(reused.out.find("pid " + std::to_string(getpid()) + " is now another process"), std::string::npos)
      << reused.out;
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "stopped without finishing (coupler killed?)");

  // On another host it cannot tell, and says so without changing anything.
  text = read_file(out + "/run.json");
  set_field("status", "\"running\"");
  set_field("coupler_host", "\"elsewhere.example\"");
  write_file(out + "/run.json", text);
  const auto other = run({bin("hfmpm"), "status", out}, 20);
  EXPECT_NE(other.out.find("running according to run.json, but its coupler ran on elsewhere.example"),
            std::string::npos)
      << other.out;
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "running");

  // No run.json: a clear error.
  const auto none = run({bin("hfmpm"), "status", out + "/nothing"}, 20);
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.err.find("no run.json in this directory"), std::string::npos) << none.err;
}

// Two runs into one directory used to mix their rows in history.csv and
// damage each other's files. The second (run, coupler, restart) is refused
// before it writes anything there, naming the live run; the first goes on.
TEST(Failure, OneLiveRunPerOutputDirectory) {
  const auto out = scratch_dir("one-live-run");
  const auto elsewhere = scratch_dir("second-run");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  write_file(elsewhere + "/scene.scene", prescribed_scene(0.1, 0.01));
  Process first({bin("hfmpm"), "run", scene, "--out", out, "--quiet"});
  for (int i = 0; i < 500 && history_rows(out) < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_GE(history_rows(out), 3u);
  const std::string pid = std::to_string(first.pid());
  const std::string manifest = read_file(out + "/run.json");
  const std::string lock = read_file(out + "/.lock");
  EXPECT_NE(lock.find("\"pid\": " + pid + ","), std::string::npos) << lock;
  const auto scene_json_written = std::filesystem::last_write_time(out + "/scene.json");
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(out)) files.insert(entry.path().filename().string());

  const std::string busy = "hfmpm: the directory '" + out + "' is in use by another run (coupler pid " + pid + " on ";
  const auto second = run({bin("hfmpm"), "run", elsewhere + "/scene.scene", "--out", out, "--quiet"}, 20);
  EXPECT_EQ(second.exit_code, 2) << second.err;
  EXPECT_NE(second.err.find(busy), std::string::npos) << second.err;
  EXPECT_NE(second.err.find("it holds " + out +
                            "/.lock): one live run per output directory; wait for it to end, "
                            "stop it (Ctrl-C, or kill " +
                            pid + "), or choose another --out"),
            std::string::npos)
      << second.err;
  const auto coupler = run({bin("hfmpm"), "coupler", elsewhere + "/scene.scene", "--bind", "tcp://127.0.0.1:*",
                            "--insecure-tcp", "--out", out, "--quiet"},
                           20);
  EXPECT_EQ(coupler.exit_code, 2) << coupler.err;
  EXPECT_NE(coupler.err.find(busy), std::string::npos) << coupler.err;
  const auto restart = run({bin("hfmpm"), "run", "--restart", out, "--quiet"}, 20);
  EXPECT_EQ(restart.exit_code, 2) << restart.err;
  EXPECT_NE(restart.err.find("the run in " + out + " is still running (coupler pid " + pid + " on "), std::string::npos)
      << restart.err;

  // Nothing of the refused ones in the directory; the first runs on.
  EXPECT_TRUE(first.running());
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "run_id"), json_string(manifest, "run_id"));
  EXPECT_EQ(read_file(out + "/.lock"), lock);
  EXPECT_EQ(std::filesystem::last_write_time(out + "/scene.json"), scene_json_written);
  std::set<std::string> files_after;
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    files_after.insert(entry.path().filename().string());
  }
  EXPECT_EQ(files_after, files);
  const std::size_t rows = history_rows(out);
  ASSERT_EQ(kill(first.pid(), SIGTERM), 0);
  ASSERT_TRUE(first.wait(20));
  EXPECT_EQ(first.exit_code(), 128 + SIGTERM) << first.err();
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "interrupted");
  // One run's rows: one header, each step after the one above it (the row the
  // interrupt writes is not written again when it stops at an output row's step).
  const Csv history = read_csv(out + "/history.csv");
  EXPECT_GE(history.rows.size(), rows);
  const auto steps = history.values("step");
  for (std::size_t i = 1; i < steps.size(); ++i) ASSERT_GT(steps[i], steps[i - 1]) << "row " << i;
}

// The kernel drops a killed process's flock: the lock file it leaves, still
// naming it, does not block the next run.
TEST(Failure, ALockLeftByAKilledRunDoesNotBlock) {
  const auto out = scratch_dir("lock-left");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  Process killed({bin("hfmpm"), "run", scene, "--out", out, "--quiet"});
  for (int i = 0; i < 500 && history_rows(out) < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_GE(history_rows(out), 3u);
  const std::string pid = std::to_string(killed.pid());
  ASSERT_EQ(kill(killed.pid(), SIGKILL), 0);
  ASSERT_TRUE(killed.wait(5));
  EXPECT_NE(read_file(out + "/.lock").find("\"pid\": " + pid + ","), std::string::npos) << "left behind, naming it";

  write_file(scene, prescribed_scene(0.1, 0.01));
  const auto next = run({bin("hfmpm"), "run", scene, "--out", out, "--quiet"}, 60);
  EXPECT_EQ(next.exit_code, 0) << next.err;
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "completed");
  EXPECT_EQ(read_file(out + "/.lock").find("\"pid\": " + pid + ","), std::string::npos) << "the next run's name now";
}

// Sides started by hand (not children of the coupler) notice its silence.
TEST(Failure, HandStartedSidesExitWhenTheCouplerGoesSilent) {
  const auto out = scratch_dir("silent");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  const auto keys = make_keys(out);
  std::vector<std::string> argv{bin("hfmpm"), "coupler",    scene,   "--bind", "tcp://127.0.0.1:*",
                                "--keys",     keys.coupler, "--out", out,      "--quiet"};
  argv.insert(argv.end(), kFastLiveness.begin(), kFastLiveness.end());
  Process coupler(argv);
  const std::string endpoint = wait_for_endpoint(out + "/run.json", 10);
  Process solid(
      {bin("hfmpm-prescribed-solid"), "--connect", endpoint, "--keys", keys.side, "--advertise-host", "127.0.0.1"});
  Process fluid({bin("hfmpm-prescribed-fluid"), "--connect", endpoint, "--keys", keys.side});
  for (int i = 0; i < 500 && history_rows(out) < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(coupler.pid(), SIGSTOP);  // alive but silent: no heartbeats
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(solid.wait(1 + kBusyMarginS));
  EXPECT_TRUE(fluid.wait(1 + kBusyMarginS));
  // The 1 s heartbeat timeout, not the 60 s welcome timeout or a hang.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1 + kBusyMarginS);
  EXPECT_EQ(solid.exit_code(), 4) << solid.err();  // kSideCouplerLost
  EXPECT_EQ(fluid.exit_code(), 4) << fluid.err();
  EXPECT_NE(solid.err().find("nothing from the coupler"), std::string::npos) << solid.err();
  kill(coupler.pid(), SIGKILL);
  kill(coupler.pid(), SIGCONT);
}

TEST(Failure, NoSideJoinsWithinTheJoinTimeout) {
  const auto out = scratch_dir("nojoin");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene());
  const auto result = run({bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--insecure-tcp", "--out",
                           out, "--quiet", "--set", "coupling.join_timeout_s=1"},
                          20);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("within coupling.join_timeout_s"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("solid, fluid"), std::string::npos) << result.err;
}

// A full disk: the solid's frame fills a 3 MB tmpfs at its second frame. The
// run fails naming ENOSPC; run.json stays whole JSON with the failure in it
// (the space run.json.reserve kept is freed for its last save; before, the
// save on a full disk renamed an empty file over it); history.csv keeps its
// rows. Skipped where this process may not mount a tmpfs (needs root with
// CAP_SYS_ADMIN, as CI has).
TEST(Failure, AFullDiskFailsNamingItAndKeepsRunJsonWhole) {
  const std::string disk = scratch_dir("full_disk");
  if (std::system(("mount -t tmpfs -o size=3m tmpfs " + disk + " 2>/dev/null").c_str()) != 0) {
    GTEST_SKIP() << "no tmpfs can be mounted here";
  }
  const std::string out = disk + "/run";
  std::filesystem::create_directories(out);
  const auto result =
      run_scene(read_file(source("scenarios/kgd-viscosity-ci.scene")), out, {"--set", "time.end_s=2"}, 120);
  const std::string manifest = read_file(out + "/run.json");
  const std::string history = read_file(out + "/history.csv");
  const bool leftovers =
      std::filesystem::exists(out + "/run.json.tmp") || std::filesystem::exists(out + "/run.json.reserve");
  EXPECT_EQ(std::system(("umount " + disk).c_str()), 0);
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_NE(result.err.find("No space left on device"), std::string::npos) << result.err;
  ASSERT_FALSE(manifest.empty());
  EXPECT_EQ(manifest.front(), '{');
  EXPECT_EQ(manifest.substr(manifest.size() - 2), "}\n");
  EXPECT_EQ(json_string(manifest, "status"), "failed") << manifest;
  EXPECT_NE(json_string(manifest, "error").find("No space left on device"), std::string::npos) << manifest;
  EXPECT_GE(std::count(history.begin(), history.end(), '\n'), 2);  // the header and the first frame's row
  EXPECT_FALSE(leftovers);
}

}  // namespace
}  // namespace hfmpm::test
