// `hfmpm-reliability fuzz`, phase 2, a side: this tool plays the coupler (a ROUTER socket), starts
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
#include "fuzz.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "messages.hpp"

namespace hfmpm::reliability {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

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

}  // namespace hfmpm::reliability
