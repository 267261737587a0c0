// Intrusions into a coupled run and stops from outside: strangers and
// impostors on the control port, oversized frames, keys for tcp, and the
// signals that stop `hfmpm run` in order. Each must leave the run unchanged
// or stopped cleanly, with its outputs readable and no process left.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <memory>
#include <zmq.hpp>

#include "failure_support.hpp"

namespace hfmpm::test {
namespace {

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
// the frame is kept or delivered; the run goes on and is unchanged. The real
// fluid connects 2 s after the stranger has closed: while a peer holds the
// routing id "fluid" the coupler's ROUTER refuses a second one, and a side's
// Hello sent on a refused connection is lost and not sent again (the side
// then waits out its Welcome timeout). With 0.5 s this failed once in a CI
// run on a loaded machine (5 December); a side that repeats its Hello until
// answered is the fix, not built.
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
  std::this_thread::sleep_for(std::chrono::seconds(2));
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
