// `hfmpm-reliability fuzz --messages N [--seed S]`.
//
// Phase 1, the coupler: `hfmpm coupler` on plain tcp (--insecure-tcp, so a
// stranger reaches it; with CURVE a peer without the sides' key is refused
// before the coupler sees a byte) receives batches of random and mutated
// messages from stranger peers and raw tcp garbage; then the real sides join.
// The coupler must complete or fail with a message: never die by a signal,
// never hang.
//
// Phase 2, a side: this tool plays the coupler (a ROUTER socket), starts
// hfmpm-prescribed-solid or -fluid against it, answers its Hello validly up
// to a random point and then with random and mutated messages. The side must
// exit with a clear error (or obey a Shutdown): never die by a signal, never hang.
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
#include "hfmpm/coupling/scene_loader.hpp"
#include "messages.hpp"

namespace hfmpm::reliability {
namespace {

namespace fs = std::filesystem;

constexpr double kCouplerDeadlineS = 60;  // a round that takes longer is a hang
constexpr double kSideDeadlineS = 15;     // a side still there this long after Shutdown is a hang
constexpr std::size_t kOversize = (std::size_t{4} << 20) + 4096;       // above the coupler's 4 MiB limit
constexpr std::size_t kSideOversize = (std::size_t{64} << 20) + 4096;  // above a side's 64 MiB limit

std::string hex(const std::string& bytes, std::size_t max = 64) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < max; ++i) {
    out += digits[static_cast<unsigned char>(bytes[i]) >> 4];
    out += digits[static_cast<unsigned char>(bytes[i]) & 15];
  }
  return out + (bytes.size() > max ? "..." : "");
}

// The frames of one fuzz message, and a line describing it (kept for a report).
struct Message {
  std::vector<std::string> frames;
  std::string kind;
};

// A message a stranger or the fake coupler sends: random bytes, a valid
// Envelope, a mutated one, several frames, an empty frame, or an oversized one.
Message fuzz_message(Rng& rng, const MessageContext& context, const protocol::Envelope* next, std::size_t oversize,
                     double oversize_chance) {
  Message m;
  const double r = rng.uniform(0, 1);
  auto envelope_bytes = [&]() {
    const auto envelope = next && rng.chance(0.5) ? *next : random_envelope(rng, context);
    return proto::encode(envelope);
  };
  if (rng.chance(oversize_chance)) {
    m.kind = "oversized";
    m.frames.push_back(std::string(oversize + rng.between(0, 1 << 20), '\x0a'));
  } else if (r < 0.15) {
    m.kind = "random bytes";
    m.frames.push_back(rng.bytes(rng.between(1, 512)));
  } else if (r < 0.40) {
    m.kind = "valid envelope";
    m.frames.push_back(envelope_bytes());
  } else if (r < 0.90) {
    m.kind = "mutated envelope";
    m.frames.push_back(mutate(envelope_bytes(), rng));
  } else if (r < 0.97) {
    m.kind = "multi-frame";
    const auto n = rng.between(2, 4);
    for (std::uint64_t i = 0; i < n; ++i) m.frames.push_back(rng.chance(0.5) ? envelope_bytes() : rng.bytes(8));
  } else {
    m.kind = "empty frame";
    m.frames.push_back("");
  }
  return m;
}

bool send_message(zmq::socket_t& socket, const Message& m) {
  for (std::size_t i = 0; i < m.frames.size(); ++i) {
    const auto flags =
        (i + 1 < m.frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none) | zmq::send_flags::dontwait;
    if (!socket.send(zmq::buffer(m.frames[i]), flags)) return false;
  }
  return true;
}

MessageContext make_context(const std::string& dir) {
  MessageContext context;
  context.coupled_scene = coupling::parse_scene(test::prescribed_scene(0.05, 0.01), "prescribed");
  context.dry_scene = context.coupled_scene;
  context.dry_scene.clear_fluid();
  context.data_endpoint = "ipc://" + dir + "/nobody";
  context.output_dir = dir;
  return context;
}

// ------------------------------------------------------------------ phase 1

struct CouplerTotals {
  std::uint64_t messages = 0, side_named = 0, raw_connections = 0, rounds = 0;
  int completed = 0, stranger_failed = 0, other_failed = 0, crashes = 0, hangs = 0, history_differs = 0;
  int side_crashes = 0;
  std::vector<std::string> problems;
  std::map<std::string, int> failure_kinds;
};

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

// ------------------------------------------------------------------ phase 2

struct SideTotals {
  int trials = 0, crashes = 0, hangs = 0, clean_errors = 0, shut_down = 0, coupler_lost = 0, unclear = 0;
  int errors_reported = 0, setup_failures = 0;
  std::uint64_t messages = 0;
  std::map<int, int> exit_codes;
  std::vector<std::string> problems;
};

struct Routed {
  std::string peer;
  std::vector<std::string> frames;
};

std::optional<Routed> receive(zmq::socket_t& router, double timeout_s) {
  zmq::pollitem_t item{router.handle(), 0, ZMQ_POLLIN, 0};
  zmq::poll(&item, 1, std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
  if (!(item.revents & ZMQ_POLLIN)) return std::nullopt;
  Routed routed;
  zmq::message_t part;
  bool first = true;
  do {
    (void)router.recv(part);
    if (first)
      routed.peer = part.to_string();
    else
      routed.frames.push_back(part.to_string());
    first = false;
  } while (part.more());
  return routed;
}

// Waits for a message of `body` from the side's control socket (heartbeats from
// "<role>.hb" are skipped); nullopt on timeout, on another message, or if the side ended.
std::optional<protocol::Envelope> await(zmq::socket_t& router, Child& side, const std::string& role,
                                        const std::string& body, double timeout_s, int& errors) {
  const auto start = Clock::now();
  while (seconds_since(start) < timeout_s) {
    auto routed = receive(router, 0.05);
    if (!routed) {
      if (!side.running()) return std::nullopt;
      continue;
    }
    if (routed->peer != role || routed->frames.size() != 1) continue;
    try {
      auto envelope = proto::decode(routed->frames[0].data(), routed->frames[0].size(), role);
      if (envelope.has_heartbeat()) continue;
      if (envelope.has_error()) ++errors;
      if (proto::body_name(envelope) == body) return envelope;
      return std::nullopt;
    } catch (const proto::ProtocolError&) {
      return std::nullopt;
    }
  }
  return std::nullopt;
}

void send_to(zmq::socket_t& router, const std::string& peer, const Message& m) {
  (void)router.send(zmq::buffer(peer), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
  for (std::size_t i = 0; i < m.frames.size(); ++i) {
    (void)router.send(zmq::buffer(m.frames[i]),
                      i + 1 < m.frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
  }
}

Message envelope_message(const protocol::Envelope& envelope) { return {{proto::encode(envelope)}, "valid"}; }

void side_trial(std::uint64_t index, const CommonOptions& options, const std::string& root, zmq::context_t& zmq_context,
                SideTotals& totals) {
  Rng rng(options.seed, 3, index);
  const std::string dir = make_dir(root, "side-" + std::to_string(index));
  MessageContext context = make_context(dir);
  const bool solid = rng.chance(0.75);
  const std::string role = solid ? "solid" : "fluid";
  const int depth = solid ? static_cast<int>(rng.between(0, 2)) : 0;  // 0: after Hello, 1: after Ready, 2: after steps
  const bool tcp = rng.chance(0.3);

  zmq::socket_t router(zmq_context, zmq::socket_type::router);
  router.set(zmq::sockopt::linger, 0);
  router.bind(tcp ? "tcp://127.0.0.1:*" : "ipc://" + dir + "/c");
  const std::string endpoint = router.get(zmq::sockopt::last_endpoint);
  Child side({test::bin(solid ? "hfmpm-prescribed-solid" : "hfmpm-prescribed-fluid"), "--connect", endpoint, "--out",
              dir + "/out", "--advertise-host", "127.0.0.1", "--welcome-timeout", "5"},
             dir + "/side.stdout", dir + "/side.stderr", std::uint64_t{4} << 30);
  ++totals.trials;
  std::ofstream log(dir + "/messages.txt");
  std::string line = "side trial " + std::to_string(index) + " (" + role + ", " + (tcp ? "tcp" : "ipc") +
                     ", fuzzed after " +
                     (depth == 0   ? "Hello"
                      : depth == 1 ? "Ready"
                                   : "valid steps") +
                     "): ";
  int errors = 0;
  bool problem = false;
  bool set_up = static_cast<bool>(await(router, side, role, "hello", 10, errors));
  protocol::Envelope next;
  if (set_up && depth >= 1) {
    protocol::Envelope welcome;
    welcome.mutable_welcome()->set_protocol_version(1);
    welcome.mutable_welcome()->set_run_id("0123456789ab");
    *welcome.mutable_welcome()->mutable_scene() = context.dry_scene;
    welcome.mutable_welcome()->mutable_data_plane()->set_mode(protocol::DataPlane::NONE);
    welcome.mutable_welcome()->set_output_dir(dir + "/out");
    welcome.mutable_welcome()->set_scene_schema_version(protocol::SCENE_SCHEMA_CURRENT);
    send_to(router, role, envelope_message(welcome));
    set_up = static_cast<bool>(await(router, side, role, "ready", 10, errors));
    for (int k = 0; set_up && depth == 2 && k < static_cast<int>(rng.between(1, 3)); ++k) {
      const auto command = next_command(rng, context);
      send_to(router, role, envelope_message(command));
      const auto report = await(router, side, role, "step_report", 10, errors);
      set_up = static_cast<bool>(report);
      if (report) {
        context.step = report->step_report().step();
        context.t = report->step_report().t();
      }
    }
  }
  if (!set_up) {
    ++totals.setup_failures;
    problem = true;
    line += "the valid exchange before the fuzz failed (" + side.how_it_ended() + "): " + side.err().substr(0, 300);
  } else {
    if (depth == 0) {
      // What the side waits for: a Welcome for its role (solid: BIND or NONE; fluid: CONNECT).
      next.mutable_welcome()->set_protocol_version(1);
      next.mutable_welcome()->set_run_id("0123456789ab");
      *next.mutable_welcome()->mutable_scene() = solid && rng.chance(0.5) ? context.dry_scene : context.coupled_scene;
      const bool dry = !next.welcome().scene().has_fluid();
      next.mutable_welcome()->mutable_data_plane()->set_mode(dry     ? protocol::DataPlane::NONE
                                                             : solid ? protocol::DataPlane::BIND
                                                                     : protocol::DataPlane::CONNECT);
      next.mutable_welcome()->mutable_data_plane()->set_endpoint(dry     ? ""
                                                                 : solid ? "tcp://127.0.0.1:*"
                                                                         : context.data_endpoint);
      next.mutable_welcome()->set_output_dir(dir + "/out");
      next.mutable_welcome()->set_scene_schema_version(protocol::SCENE_SCHEMA_CURRENT);
    } else {
      next = next_command(rng, context);
    }
    const auto count = rng.between(1, 4);
    for (std::uint64_t i = 0; i < count && side.running(); ++i) {
      Message m = fuzz_message(rng, context, &next, kSideOversize, 0.002);
      // A mutation into a valid command of many steps is obeyed, not refused: draw again.
      for (int redraw = 0; redraw < 20 && m.frames.size() == 1; ++redraw) {
        try {
          const auto decoded = proto::decode(m.frames[0].data(), m.frames[0].size(), "fuzz");
          if (!decoded.has_step_command() || decoded.step_command().num_steps() <= 100000) break;
        } catch (const proto::ProtocolError&) {
          break;
        }
        m = fuzz_message(rng, context, &next, kSideOversize, 0.002);
      }
      send_to(router, role, m);
      ++totals.messages;
      log << m.kind << " " << m.frames.size() << " frame(s): " << hex(m.frames[0], 4096) << "\n";
      sleep_s(rng.uniform(0, 0.02));
    }
    // Let it react, then ask it to stop; a side that is still there after that hangs.
    const auto react = Clock::now();
    while (side.running() && seconds_since(react) < 0.3) {
      if (auto routed = receive(router, 0.02); routed && routed->peer == role && routed->frames.size() == 1) {
        try {
          if (proto::decode(routed->frames[0].data(), routed->frames[0].size(), role).has_error()) ++errors;
        } catch (const proto::ProtocolError&) {
        }
      }
    }
    if (side.running()) {
      protocol::Envelope shutdown;
      shutdown.mutable_shutdown()->set_reason("fuzz over");
      send_to(router, role, envelope_message(shutdown));
    }
    const auto asked = Clock::now();
    auto drained = Clock::now();
    while ((side.running() || seconds_since(drained) < 0.05) && seconds_since(asked) < kSideDeadlineS) {
      if (side.running()) drained = Clock::now();
      if (auto routed = receive(router, 0.02); routed && routed->peer == role && routed->frames.size() == 1) {
        try {
          if (proto::decode(routed->frames[0].data(), routed->frames[0].size(), role).has_error()) ++errors;
        } catch (const proto::ProtocolError&) {
        }
      }
    }
    // Its message, without the note a side prints when it joins over plain tcp.
    std::string err = side.err();
    if (const auto note = err.find(": note: no --keys"); note != std::string::npos) {
      const auto start = err.rfind('\n', note);
      const auto end = err.find('\n', note);
      err.erase(start == std::string::npos ? 0 : start + 1,
                end == std::string::npos ? std::string::npos : end - (start == std::string::npos ? 0 : start + 1) + 1);
    }
    if (side.running()) {
      ++totals.hangs;
      problem = true;
      line += "HANG: still running " + fixed(kSideDeadlineS, 0) + " s after Shutdown";
      side.kill_now();
    } else if (side.term_signal() != 0) {
      ++totals.crashes;
      problem = true;
      line += "CRASH: " + side.how_it_ended() + ": " + err.substr(0, 400);
    } else {
      ++totals.exit_codes[side.exit_code()];
      if (side.exit_code() == 0 || side.exit_code() == 5) {
        ++totals.shut_down;  // 5: a Shutdown with error = true
        line += "exit " + std::to_string(side.exit_code()) + " (obeyed a Shutdown, the fuzzer's or the final one)";
      } else if (err.find_first_not_of(" \n") == std::string::npos) {
        ++totals.unclear;
        problem = true;
        line += "exit " + std::to_string(side.exit_code()) + " WITHOUT a message";
      } else if (side.exit_code() == 4) {
        ++totals.coupler_lost;
        line += "exit 4 (no answer from the coupler): " + err.substr(0, 200);
      } else {
        ++totals.clean_errors;
        line += "exit " + std::to_string(side.exit_code()) + ": " + err.substr(0, 200);
      }
      if (errors > 0) ++totals.errors_reported;
    }
  }
  while (!line.empty() && line.back() == '\n') line.pop_back();
  if (problem) totals.problems.push_back(line + " [seed " + std::to_string(options.seed) + ", " + dir + "]");
  if (problem || options.verbose) std::cout << line << "\n";
  router.close();
  if (!problem && !options.keep) {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
}

}  // namespace

int fuzz_command(std::uint64_t messages, const CommonOptions& options) {
  const std::string root = make_dir("/tmp", "hfmpm-reliability-fuzz");
  std::cout << "hfmpm-reliability fuzz: " << messages << " messages to the coupler, seed " << options.seed
            << ", output under " << root << "\n";
  const std::string scene = root + "/prescribed.scene";
  test::write_file(scene, test::prescribed_scene(0.05, 0.01));
  const auto reference_run = test::run({test::bin("hfmpm"), "run", scene, "--out", root + "/reference", "--quiet"}, 60);
  if (reference_run.exit_code != 0) {
    std::cout << "the run without strangers failed: " << reference_run.err << "\n";
    return 1;
  }
  const test::Csv reference = test::read_csv(root + "/reference/history.csv");

  const auto start = Clock::now();
  CouplerTotals coupler;
  for (std::uint64_t round = 0, sent = 0; sent < messages; ++round) {
    sent += coupler_round(round, messages - sent, options, root, scene, reference, coupler);
  }
  const double coupler_s = seconds_since(start);

  SideTotals side;
  const std::uint64_t trials = std::clamp<std::uint64_t>(messages / 100, 10, 1000);
  {
    zmq::context_t zmq_context;
    for (std::uint64_t i = 0; i < trials; ++i) side_trial(i, options, root, zmq_context, side);
  }
  const double side_s = seconds_since(start) - coupler_s;

  std::cout << "\nsummary (fuzz --messages " << messages << " --seed " << options.seed << ")\n"
            << "phase 1, the coupler (hfmpm coupler --insecure-tcp; " << fixed(coupler_s, 1) << " s):\n"
            << "  messages sent by strangers: " << coupler.messages << " in " << coupler.rounds << " runs ("
            << coupler.side_named
            << " stranger sockets took a side's routing id), raw tcp garbage connections: " << coupler.raw_connections
            << "\n"
            << "  crashes: " << coupler.crashes << ", hangs: " << coupler.hangs << "\n"
            << "  completed runs: " << coupler.completed
            << " (history differs from the run without strangers: " << coupler.history_differs << ")\n"
            << "  runs failed cleanly by a stranger message under a side's name: " << coupler.stranger_failed;
  if (!coupler.failure_kinds.empty()) {
    std::cout << " (";
    bool first = true;
    for (const auto& [kind, n] : coupler.failure_kinds) {
      std::cout << (first ? "" : ", ") << "\"" << kind << "\" " << n;
      first = false;
    }
    std::cout << ")";
  }
  std::cout << "\n"
            << "  other failures: " << coupler.other_failed
            << "; real sides killed by a signal: " << coupler.side_crashes << "\n"
            << "  (with CURVE, the default on tcp, none of these peers gets a message to the coupler)\n"
            << "phase 2, a side (this tool as the coupler; " << fixed(side_s, 1) << " s):\n"
            << "  trials: " << side.trials << ", messages sent: " << side.messages << "\n"
            << "  crashes: " << side.crashes << ", hangs: " << side.hangs << "\n"
            << "  clean failures (exit with a message): " << side.clean_errors
            << ", exits for no answer from the coupler: " << side.coupler_lost
            << ", exit 0 or 5 on a Shutdown: " << side.shut_down << ", nonzero exit without a message: " << side.unclear
            << "\n"
            << "  sides that also told the coupler with an Error message: " << side.errors_reported << "\n"
            << "  exit codes:";
  for (const auto& [code, n] : side.exit_codes) std::cout << " " << code << " x" << n;
  std::cout << "\n  valid exchanges before the fuzz that failed: " << side.setup_failures << "\n"
            << "messages sent in all: " << coupler.messages + side.messages
            << "; crashes: " << coupler.crashes + side.crashes + coupler.side_crashes
            << "; hangs: " << coupler.hangs + side.hangs << "\n";
  const bool ok = coupler.crashes == 0 && coupler.hangs == 0 && coupler.other_failed == 0 &&
                  coupler.history_differs == 0 && coupler.side_crashes == 0 && coupler.problems.empty() &&
                  side.problems.empty();
  for (const auto& p : coupler.problems) std::cout << "problem: " << p << "\n";
  for (const auto& p : side.problems) std::cout << "problem: " << p << "\n";
  std::cout << (ok ? "OK" : "PROBLEMS FOUND") << "\n";
  std::error_code ec;
  if (ok && !options.keep) {
    fs::remove_all(root, ec);
  } else {
    std::cout << "outputs kept in " << root << "\n";
  }
  return ok ? 0 : 1;
}

}  // namespace hfmpm::reliability
