// Failures of a coupled run: a side that exits, crashes, is killed, hangs,
// freezes, speaks another protocol version or sends garbage; a dead coupler.
// Each must be detected within a bounded time, name the failed side and the
// step, leave history.csv readable, and leave no process running.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <memory>
#include <zmq.hpp>

#include "coupled_support.hpp"

namespace hfmpm::test {
namespace {

// Fast liveness settings so each failure is found in about a second.
// Wall-clock bounds: a detection that works takes its timeout plus moments
// (measured: an exit 0.27 s, a hang the 2 s step timeout + 2 s, a freeze the
// 1 s heartbeat timeout + 2 s, a silent coupler 1.15 s). The bounds add
// kBusyMarginS to the timeout, so a machine busy enough to stall a process
// for many seconds does not fail them, while a detection that waits for a
// default timeout (10 s step, 3 s heartbeat, 60 s welcome) or never comes
// still does.
constexpr double kBusyMarginS = 20;

const std::vector<std::string> kFastLiveness{"--set", "coupling.heartbeat_interval_s=0.1",
                                             "--set", "coupling.heartbeat_timeout_s=1",
                                             "--set", "coupling.step_timeout_s=2"};

// Rows in a run's history.csv so far (0 before the coupler has created it).
std::size_t history_rows(const std::string& out) {
  try {
    return read_csv(out + "/history.csv").rows.size();
  } catch (const std::exception&) {
    return 0;
  }
}

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
  expect_clean_failure(newer, "fluid", "was built with scene schema version 99; this coupler's scenes are version 2",
                       0);
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

// The stand-in scene run once without strangers, and a coupler on plain tcp
// (--insecure-tcp, so strangers reach it) waiting for sides started by hand.
struct StrangerRun {
  std::string reference, out, endpoint;
  std::unique_ptr<Process> coupler;
};

StrangerRun start_insecure_coupler(const std::string& name) {
  StrangerRun r;
  r.reference = scratch_dir(name + "-ref");
  EXPECT_EQ(run_scene(prescribed_scene(), r.reference, {}).exit_code, 0);
  r.out = scratch_dir(name);
  const std::string scene = r.out + "/scene.scene";
  write_file(scene, prescribed_scene());
  r.coupler = std::make_unique<Process>(std::vector<std::string>{
      bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--insecure-tcp", "--out", r.out, "--quiet"});
  r.endpoint = wait_for_endpoint(r.out + "/run.json", 10);
  return r;
}

// The real sides join; the run completes with the history of the run without strangers.
void join_sides_and_expect_the_same_run(StrangerRun& r) {
  Process solid(
      {bin("hfmpm-prescribed-solid"), "--connect", r.endpoint, "--out", r.out, "--advertise-host", "127.0.0.1"});
  Process fluid({bin("hfmpm-prescribed-fluid"), "--connect", r.endpoint, "--out", r.out});
  ASSERT_TRUE(r.coupler->wait(60));
  EXPECT_EQ(r.coupler->exit_code(), 0) << r.coupler->err();
  expect_same_history(read_csv(r.reference + "/history.csv"), read_csv(r.out + "/history.csv"));
}

// Plain tcp (--insecure-tcp): bytes that are not ZMTP on the coupler's tcp
// port, and a ZeroMQ peer that is neither side sending garbage: both are
// refused and the run goes on unchanged.
TEST(Failure, StrangersOnTheControlPortAreIgnored) {
  auto run = start_insecure_coupler("strangers");
  const std::string& endpoint = run.endpoint;
  ASSERT_FALSE(endpoint.empty());
  const int port = std::stoi(endpoint.substr(endpoint.rfind(':') + 1));

  const int raw = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(connect(raw, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  const std::string junk(4096, '\xa5');
  EXPECT_GT(write(raw, junk.data(), junk.size()), 0);

  zmq::context_t context;
  zmq::socket_t stranger(context, zmq::socket_type::dealer);
  stranger.set(zmq::sockopt::linger, 0);
  stranger.set(zmq::sockopt::routing_id, "intruder");
  stranger.connect(endpoint);
  stranger.send(zmq::str_buffer("\x08\xff\xff garbage"), zmq::send_flags::none);

  join_sides_and_expect_the_same_run(run);
  close(raw);
  EXPECT_NE(read_file(run.out + "/coupler.log").find("ignored a message from an unknown peer 'intruder'"),
            std::string::npos);
}

// SIGINT, SIGTERM and SIGHUP stop `hfmpm run` at its next control round: the
// sides shut down in order, run.json says "interrupted" with the step, the
// history and the HDF5-free stand-in outputs stay readable, the ipc
// directory is removed, and the exit status is 128 + the signal.
void interrupt_mid_run(int signal, const std::string& name) {
  const auto out = scratch_dir("interrupted");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  Process coupler({bin("hfmpm"), "run", scene, "--out", out, "--quiet"});
  pid_t solid = 0, fluid = 0;
  for (int i = 0; i < 500 && history_rows(out) < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::string started = read_file(out + "/run.json");
  solid = static_cast<pid_t>(json_number(started, "solid_pid"));
  fluid = static_cast<pid_t>(json_number(started, "fluid_pid"));
  const std::string endpoint = json_string(started, "control_endpoint");
  ASSERT_EQ(endpoint.rfind("ipc://", 0), 0u) << endpoint;
  const std::string ipc_dir = std::filesystem::path(endpoint.substr(6)).parent_path().string();
  EXPECT_TRUE(std::filesystem::exists(ipc_dir));
  EXPECT_EQ(json_number(started, "coupler_pid"), coupler.pid());
  kill(coupler.pid(), signal);
  ASSERT_TRUE(coupler.wait(20));
  EXPECT_EQ(coupler.exit_code(), 128 + signal) << coupler.err();
  EXPECT_NE(coupler.err().find("interrupted by " + name + " at step"), std::string::npos) << coupler.err();
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_EQ(json_string(manifest, "status"), "interrupted");
  EXPECT_EQ(json_string(manifest, "interrupted_by"), name);
  const double step = json_number(manifest, "interrupted_at_step");
  EXPECT_GT(step, 0);
  // The history ends with the step the run stopped at.
  const Csv history = read_csv(out + "/history.csv");
  ASSERT_GE(history.rows.size(), 3u);
  EXPECT_EQ(history.rows.back()[history.column("step")], step);
  // The sides were shut down (not killed) and are gone; so is the socket directory.
  EXPECT_FALSE(pid_alive(solid));
  EXPECT_FALSE(pid_alive(fluid));
  EXPECT_EQ(read_file(out + "/solid.log").find("killed"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(ipc_dir));
}

TEST(Failure, SigintStopsTheRunInOrder) { interrupt_mid_run(SIGINT, "SIGINT"); }
TEST(Failure, SigtermStopsTheRunInOrder) { interrupt_mid_run(SIGTERM, "SIGTERM"); }
TEST(Failure, SighupStopsTheRunInOrder) { interrupt_mid_run(SIGHUP, "SIGHUP"); }

// A second signal ends the run at once; the sides die with the coupler, the
// socket directory is removed, and run.json does not say "running".
TEST(Failure, ASecondSignalStopsAtOnce) {
  const auto out = scratch_dir("aborted");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(100.0, 0.01));
  Process coupler({bin("hfmpm"), "run", scene, "--out", out, "--quiet"});
  for (int i = 0; i < 500 && history_rows(out) < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::string started = read_file(out + "/run.json");
  const auto solid = static_cast<pid_t>(json_number(started, "solid_pid"));
  const std::string ipc_dir =
      std::filesystem::path(json_string(started, "control_endpoint").substr(6)).parent_path().string();
  // Stop the sides from answering, so the first signal's orderly stop cannot finish first.
  kill(solid, SIGSTOP);
  kill(coupler.pid(), SIGTERM);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  kill(coupler.pid(), SIGTERM);
  ASSERT_TRUE(coupler.wait(10));
  EXPECT_EQ(coupler.exit_code(), 128 + SIGTERM) << coupler.err();
  EXPECT_NE(coupler.err().find("SIGTERM again: stopping at once"), std::string::npos) << coupler.err();
  EXPECT_EQ(json_string(read_file(out + "/run.json"), "status"), "aborted by SIGTERM");
  for (int i = 0; i < 200 && pid_alive(solid); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_FALSE(pid_alive(solid));
  EXPECT_FALSE(std::filesystem::exists(ipc_dir));
  EXPECT_GE(read_csv(out + "/history.csv").rows.size(), 1u);
}

// CURVE (the default on tcp): an impostor fluid that joins first, one with
// its own key pair (even knowing the coupler's public key) and one with no
// keys, never reaches the coupler; the real sides join after them and the
// run is the same as without strangers. The refusal is logged, once a second.
TEST(Failure, ImpostorsWithoutTheSideKeyCannotJoin) {
  const auto reference = scratch_dir("impostor-ref");
  ASSERT_EQ(run_scene(prescribed_scene(), reference, {}).exit_code, 0);
  const auto out = scratch_dir("impostor");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene());
  const auto keys = make_keys(out);
  const auto other = make_keys(out + "/other");
  // The impostor's file: the real coupler's public key, its own pair.
  auto value = [](const std::string& file, const std::string& name) {
    const std::string text = read_file(file);
    return text.substr(text.find(name + " = ") + name.size() + 3, 40);
  };
  const std::string forged = out + "/forged.keys";
  write_file(forged, "server_public = " + value(keys.side, "server_public") +
                         "\nclient_public = " + value(other.side, "client_public") +
                         "\nclient_secret = " + value(other.side, "client_secret") + "\n");
  chmod(forged.c_str(), 0600);
  Process coupler(
      {bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--keys", keys.coupler, "--out", out, "--quiet"});
  const std::string endpoint = wait_for_endpoint(out + "/run.json", 10);
  ASSERT_FALSE(endpoint.empty());
  Process forged_fluid(
      {bin("hfmpm-prescribed-fluid"), "--connect", endpoint, "--keys", forged, "--welcome-timeout", "1.5"});
  Process plain_fluid({bin("hfmpm-prescribed-fluid"), "--connect", endpoint, "--welcome-timeout", "1.5"});
  ASSERT_TRUE(forged_fluid.wait(10));
  ASSERT_TRUE(plain_fluid.wait(10));
  EXPECT_NE(forged_fluid.err().find("no answer to Hello"), std::string::npos) << forged_fluid.err();
  EXPECT_NE(plain_fluid.err().find("no answer to Hello"), std::string::npos) << plain_fluid.err();
  Process solid(
      {bin("hfmpm-prescribed-solid"), "--connect", endpoint, "--keys", keys.side, "--advertise-host", "127.0.0.1"});
  Process fluid({bin("hfmpm-prescribed-fluid"), "--connect", endpoint, "--keys", keys.side});
  ASSERT_TRUE(coupler.wait(60));
  EXPECT_EQ(coupler.exit_code(), 0) << coupler.err();
  const std::string log = read_file(out + "/coupler.log");
  EXPECT_NE(log.find("without this run's side key"), std::string::npos) << log;
  EXPECT_EQ(log.find("ignored a message"), std::string::npos) << log;
  expect_same_history(read_csv(reference + "/history.csv"), read_csv(out + "/history.csv"));
}

// Join mode on tcp without keys is refused with the way out named; a key
// file open to others is refused.
TEST(Failure, TcpCouplerNeedsKeysOrInsecureTcp) {
  const auto out = scratch_dir("nokeys");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene());
  const auto result = run({bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--out", out, "--quiet"}, 20);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("needs --keys FILE"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("--insecure-tcp"), std::string::npos) << result.err;
  const auto keys = make_keys(out);
  chmod(keys.coupler.c_str(), 0644);
  const auto open = run(
      {bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--keys", keys.coupler, "--out", out, "--quiet"},
      20);
  EXPECT_EQ(open.exit_code, 1);
  EXPECT_NE(open.err.find("chmod 600"), std::string::npos) << open.err;
  const auto again = run({bin("hfmpm"), "keygen", out + "/keys"}, 20);
  EXPECT_NE(again.exit_code, 0);
  EXPECT_NE(again.err.find("does not overwrite"), std::string::npos) << again.err;
}

// Plain tcp: a stranger that takes a side's name ("fluid") and sends a frame
// above the coupler's message limit (4 MiB) is disconnected by ZeroMQ before
// the frame is kept or delivered; the run goes on and is unchanged.
TEST(Failure, OversizedFrameFromAStrangerIsDropped) {
  auto run = start_insecure_coupler("oversized");
  const std::string& endpoint = run.endpoint;
  ASSERT_FALSE(endpoint.empty());
  zmq::context_t context;
  zmq::socket_t stranger(context, zmq::socket_type::dealer);
  stranger.set(zmq::sockopt::linger, 0);
  stranger.set(zmq::sockopt::routing_id, "fluid");
  stranger.connect(endpoint);
  const std::string big(std::size_t{32} << 20, '\x01');
  stranger.send(zmq::buffer(big), zmq::send_flags::none);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  stranger.close();
  join_sides_and_expect_the_same_run(run);
}

// With --transport inproc the sides are threads of the coupler's process:
// stopping the process (SIGSTOP) for four heartbeat timeouts stops them all.
// The coupler sees that it did not run itself and does not blame a side; the
// run completes with the same history as without the stop.
TEST(Failure, AStoppedInprocCouplerBlamesNoSide) {
  const auto reference = scratch_dir("stopped-ref");
  ASSERT_EQ(run_scene(prescribed_scene(2.0), reference, {"--transport", "inproc"}).exit_code, 0);
  const auto out = scratch_dir("stopped");
  const std::string scene = out + "/scene.scene";
  write_file(scene, prescribed_scene(2.0));
  std::vector<std::string> argv{bin("hfmpm"), "run", scene, "--out", out, "--quiet", "--transport", "inproc"};
  argv.insert(argv.end(), kFastLiveness.begin(), kFastLiveness.end());
  Process coupler(argv);
  for (int i = 0; i < 500 && history_rows(out) < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  kill(coupler.pid(), SIGSTOP);
  std::this_thread::sleep_for(std::chrono::seconds(4));  // the heartbeat timeout is 1 s
  kill(coupler.pid(), SIGCONT);
  ASSERT_TRUE(coupler.wait(60 + kBusyMarginS));
  EXPECT_EQ(coupler.exit_code(), 0) << coupler.err();
  EXPECT_NE(read_file(out + "/coupler.log").find("the coupler did not run for"), std::string::npos);
  expect_same_history(read_csv(reference + "/history.csv"), read_csv(out + "/history.csv"));
}

}  // namespace
}  // namespace hfmpm::test
