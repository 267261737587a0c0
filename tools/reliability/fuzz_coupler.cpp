// `hfmpm-reliability fuzz`, phase 1, the coupler: `hfmpm coupler` on plain tcp (--insecure-tcp, so a
// stranger reaches it; with CURVE a peer without the sides' key is refused
// before the coupler sees a byte) receives batches of random and mutated
// messages from stranger peers and raw tcp garbage; then the real sides join.
// The coupler must complete or fail with a message: never die by a signal,
// never hang.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <zmq.hpp>

#include "common.hpp"
#include "coupled_support.hpp"
#include "fuzz.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "messages.hpp"

namespace hfmpm::reliability {
namespace {

namespace fs = std::filesystem;

// A tcp connection that writes garbage (sometimes after a ZeroMQ greeting).
int raw_garbage(int port, Rng& rng) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return -1;
  }
  std::string bytes;
  if (rng.chance(0.5)) {
    // ZMTP 3.0 greeting: signature, version 3.0, mechanism NULL, as-server 0, filler.
    bytes = std::string("\xff\0\0\0\0\0\0\0\x01\x7f\x03\x00NULL", 16) + std::string(48, '\0');
    if (rng.chance(0.5)) bytes = mutate(bytes, rng);
  }
  bytes += rng.bytes(rng.between(1, 4096));
  (void)::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  return fd;
}

std::string routing_id(Rng& rng, bool side_names) {
  static const std::vector<std::string> sides{"solid", "fluid", "solid.hb", "fluid.hb"};
  static const std::vector<std::string> others{
      "solid.x", "fluid.hb.hb", "solid.",    ".hb",        "SOLID",
      "coupler", "fluid.HB",    "solid.hb ", "solidfluid", std::string(255, 's')};
  if (side_names && rng.chance(0.05)) return rng.pick(sides);
  if (rng.chance(0.5)) return rng.pick(others);
  std::string id = rng.bytes(rng.between(1, 32));
  if (id[0] == '\0') id[0] = 'z';  // ids starting with a zero byte are ZeroMQ's own
  return id;
}

bool same_history(const test::Csv& a, const test::Csv& b) {
  if (a.header != b.header || a.rows.size() != b.rows.size()) return false;
  const std::size_t wall = a.column("wall_s");
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    for (std::size_t c = 0; c < a.header.size(); ++c) {
      if (c != wall && a.rows[i][c] != b.rows[i][c]) return false;
    }
  }
  return true;
}

}  // namespace

std::uint64_t coupler_round(std::uint64_t round, std::uint64_t budget, const CommonOptions& options,
                            const std::string& root, const std::string& scene, const test::Csv& reference,
                            CouplerTotals& totals) {
  Rng rng(options.seed, 2, round);
  const std::string dir = make_dir(root, "round-" + std::to_string(round));
  const MessageContext context = make_context(dir);
  const bool side_names = round % 2 == 1;  // every other run: strangers may take the sides' names too
  const std::uint64_t batch = std::min(budget, rng.between(100, 400));
  Child coupler({test::bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--insecure-tcp", "--out", dir,
                 "--quiet", "--set", "coupling.join_timeout_s=30", "--set", "coupling.setup_timeout_s=20"},
                dir + "/coupler.stdout", dir + "/coupler.stderr");
  const auto start = Clock::now();
  std::string endpoint;
  while (endpoint.empty() && coupler.running() && seconds_since(start) < 20) {
    endpoint = test::json_string(test::read_file(dir + "/run.json"), "control_endpoint");
    if (endpoint.empty()) sleep_s(0.005);
  }
  if (endpoint.empty()) {
    totals.problems.push_back("round " + std::to_string(round) + ": the coupler did not start: " + coupler.err());
    return batch;
  }
  const int port = std::stoi(endpoint.substr(endpoint.rfind(':') + 1));
  ++totals.rounds;

  std::ofstream log(dir + "/messages.txt");
  std::uint64_t sent = 0;
  std::vector<int> raw;
  {
    zmq::context_t zmq_context;
    std::deque<zmq::socket_t> strangers;
    for (std::uint64_t i = 0; i < batch; ++i) {
      if (i % 50 == 0 && !coupler.running()) break;
      if (rng.chance(0.004)) {
        const int fd = raw_garbage(port, rng);
        if (fd >= 0) {
          raw.push_back(fd);
          ++totals.raw_connections;
        }
      }
      if (strangers.empty() || rng.chance(0.2)) {
        if (strangers.size() >= 16) strangers.pop_front();
        strangers.emplace_back(zmq_context, zmq::socket_type::dealer);
        auto& socket = strangers.back();
        socket.set(zmq::sockopt::linger, 300);
        const std::string id = routing_id(rng, side_names);
        socket.set(zmq::sockopt::routing_id, id);
        socket.connect(endpoint);
        log << "socket '" << hex(id) << "'\n";
        if (id == "solid" || id == "fluid" || id == "solid.hb" || id == "fluid.hb") ++totals.side_named;
      }
      const Message m = fuzz_message(rng, context, nullptr, kOversize, 0.001);
      auto& socket = strangers[rng.between(0, strangers.size() - 1)];
      if (send_message(socket, m)) {
        ++sent;
        log << m.kind << " " << m.frames.size() << " frame(s): " << hex(m.frames[0]) << "\n";
      }
      if (rng.chance(0.01)) sleep_s(0.002);
    }
    strangers.clear();
    zmq_context.close();  // waits for the linger: what was queued is delivered or dropped
  }
  for (int fd : raw) close(fd);
  totals.messages += sent;
  sleep_s(0.05);  // the coupler forgets the strangers' connections

  std::unique_ptr<Child> solid, fluid;
  if (coupler.running()) {
    solid = std::make_unique<Child>(
        std::vector<std::string>{test::bin("hfmpm-prescribed-solid"), "--connect", endpoint, "--out", dir,
                                 "--advertise-host", "127.0.0.1", "--welcome-timeout", "5"},
        dir + "/solid.stdout", dir + "/solid.stderr");
    fluid = std::make_unique<Child>(std::vector<std::string>{test::bin("hfmpm-prescribed-fluid"), "--connect", endpoint,
                                                             "--out", dir, "--welcome-timeout", "5"},
                                    dir + "/fluid.stdout", dir + "/fluid.stderr");
  }
  const bool finished = coupler.wait(std::max(1.0, kCouplerDeadlineS - seconds_since(start)));
  std::string line = "round " + std::to_string(round) + " (" + std::to_string(sent) + " messages" +
                     (side_names ? ", side names too" : ", strangers' names only") + "): ";
  bool problem = false;
  if (!finished) {
    ++totals.hangs;
    problem = true;
    line += "HANG: the coupler is still running after " + fixed(kCouplerDeadlineS, 0) + " s";
    coupler.kill_now();
  } else if (coupler.term_signal() != 0) {
    ++totals.crashes;
    problem = true;
    line += "CRASH: the coupler ended with " + coupler.how_it_ended() + ": " + coupler.err().substr(0, 400);
  } else if (coupler.exit_code() == 0) {
    ++totals.completed;
    try {
      if (!same_history(reference, test::read_csv(dir + "/history.csv"))) {
        ++totals.history_differs;
        problem = true;
        line += "completed, but history.csv differs from the run without strangers";
      } else {
        line += "completed, same history as without strangers";
      }
    } catch (const std::exception& e) {
      ++totals.history_differs;
      problem = true;
      line += std::string("completed, but history.csv is unreadable: ") + e.what();
    }
  } else {
    // The line that says why the run failed.
    const std::string all = coupler.err();
    const auto at = all.find("run failed: ");
    std::string err = at == std::string::npos ? all : all.substr(at + 12);
    err = err.substr(0, err.find('\n'));
    // "the solid side ..." or "rejected the solid side ...": the coupler blames a side.
    const bool named_side =
        err.find("the solid side") != std::string::npos || err.find("the fluid side") != std::string::npos;
    if (coupler.exit_code() == 1 && side_names && named_side) {
      ++totals.stranger_failed;
      // What kind of failure: the words after the side's name, up to the step or the details.
      std::string kind = err.substr(err.find(" side") + 6);
      if (err.rfind("rejected", 0) == 0) kind = "rejected at the handshake";
      kind = kind.substr(0, std::min({kind.find(" at step"), kind.find(':'), kind.find(" (")}));
      ++totals.failure_kinds[kind];
      line += "failed cleanly (exit 1) by a stranger message under a side's name: " + err.substr(0, 300);
    } else {
      ++totals.other_failed;
      problem = true;
      line += "FAILED (" + coupler.how_it_ended() + ") without a stranger under a side's name: " + err.substr(0, 400);
    }
  }
  for (auto* side : {solid.get(), fluid.get()}) {
    if (!side) continue;
    if (!side->wait(8))
      side->kill_now();  // still waiting for an answer from a coupler that gave up
    else if (side->term_signal() != 0) {
      ++totals.side_crashes;
      problem = true;
      line += "; a real side ended with " + side->how_it_ended();
    }
  }
  if (problem) totals.problems.push_back(line + " [seed " + std::to_string(options.seed) + ", " + dir + "]");
  if (problem || options.verbose) std::cout << line << "\n";
  if (!problem && !options.keep) {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  return sent > 0 ? sent : batch;
}

}  // namespace hfmpm::reliability
