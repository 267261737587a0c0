// Conformance checks of a side's life: Hello, the start-up exchange, heartbeats,
// Reject and protocol versions, Shutdown (idle, blocked on data, in the
// handshake) and what a side does when the coupler goes silent.
#include <cmath>
#include <cstdio>

#include "checks.hpp"
#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::conformance {
namespace {

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

protocol::Envelope shutdown_message(bool error, const std::string& reason) {
  protocol::Envelope envelope;
  envelope.mutable_shutdown()->set_error(error);
  envelope.mutable_shutdown()->set_reason(reason);
  return envelope;
}

protocol::Envelope reject_message() {
  protocol::Envelope envelope;
  envelope.mutable_reject()->set_reason("the conformance check rejects this side on purpose");
  envelope.mutable_reject()->set_coupler_protocol_version(proto::kProtocolVersion);
  return envelope;
}

// Starts a command and waits until the side has sent its frame and is blocked waiting for ours.
void block_on_data_plane(Session& s) {
  const auto k = s.exchange_interval();
  const auto times = s.send_command(k);
  if (!s.peer_sends_first(s.step() + k)) s.expect_frame(s.step() + k, times.back());
}

std::string expect_rejected_exit(Session& s) {
  const auto start = Clock::now();
  s.send_control(reject_message());
  if (!s.wait_exit(kErrorTimeout)) fail("still running " + seconds_text(kErrorTimeout) + " after Reject");
  const auto status = s.exit_status();
  if (!status) fail("after Reject the program " + *s.ended() + "; it must exit with a non-zero status");
  if (*status == 0) fail("after Reject the program exited with status 0; a rejected side exits non-zero");
  return *s.ended() + " " + seconds_text(s.seconds_to_exit(start)) + " after Reject";
}

std::string check_hello(Context& context) {
  Session s(context);
  const auto hello = s.expect_hello();
  std::string capabilities;
  for (const auto& c : hello.capabilities()) capabilities += (capabilities.empty() ? "" : ",") + c;
  return hello.implementation() + " " + hello.implementation_version() + ", protocol " +
         std::to_string(hello.protocol_version()) + ", routing id '" + s.side() + "', capabilities [" + capabilities +
         "]";
}

std::string check_startup(Context& context) {
  Session s(context);
  s.start(true);
  return "Welcome -> " + std::string(s.role() == protocol::SOLID ? "Listening " + s.data_endpoint() + " -> " : "") +
         "step-0 exchange -> Ready(stable_dt " + fmt(s.ready().stable_dt()) + " s)";
}

std::string check_heartbeat(Context& context) {
  const double interval = 0.2, timeout = 2.0, window = 1.6;
  Session s(context, {{"coupling.heartbeat_interval_s=0.2", "coupling.heartbeat_timeout_s=2"}, {}});
  s.start();
  const auto from = Clock::now();
  while (since(from) < window) {
    if (auto message = s.poll_control(window - since(from))) {
      fail("the idle side sent " + describe(*message) + " after Ready with no StepCommand");
    }
  }
  // The side knows the interval from Welcome: beating starts then, not after a long setup.
  if (s.beats().empty() || s.beats().front().at - s.welcome_sent_at() > std::chrono::duration<double>(interval + 0.5)) {
    fail("no heartbeat within " + seconds_text(interval + 0.5) + " of the Welcome (heartbeat_interval_s " +
         fmt(interval) + " s); a side beats from when it has the scene, also while it sets up");
  }
  const double first = std::chrono::duration<double>(s.beats().front().at - s.welcome_sent_at()).count();
  std::vector<Beat> beats;
  for (const auto& beat : s.beats()) {
    if (beat.from != s.side() + ".hb") {
      fail("a Heartbeat from routing id '" + beat.from + "'; sides send heartbeats from '" + s.side() + ".hb'");
    }
    if (beat.at >= from) beats.push_back(beat);
  }
  if (beats.size() < 4) {
    fail(std::to_string(beats.size()) + " heartbeats in " + seconds_text(window) + " with heartbeat_interval_s = " +
         fmt(interval) + " s; about " + std::to_string(static_cast<int>(window / interval)) + " were due");
  }
  double max_gap = 0;
  for (std::size_t i = 1; i < beats.size(); ++i) {
    const auto& a = beats[i - 1].heartbeat;
    const auto& b = beats[i].heartbeat;
    if (b.sequence() != a.sequence() + 1) {
      fail("heartbeat sequence " + std::to_string(a.sequence()) + " followed by " + std::to_string(b.sequence()) +
           "; it counts up by one");
    }
    max_gap = std::max(max_gap, std::chrono::duration<double>(beats[i].at - beats[i - 1].at).count());
  }
  for (const auto& beat : beats) {
    if (beat.heartbeat.step() != 0 || beat.heartbeat.waiting_for_peer()) {
      fail("an idle side at step 0 sent a heartbeat with step " + std::to_string(beat.heartbeat.step()) +
           " and waiting_for_peer " + (beat.heartbeat.waiting_for_peer() ? "true" : "false"));
    }
  }
  const double mean =
      std::chrono::duration<double>(beats.back().at - beats.front().at).count() / static_cast<double>(beats.size() - 1);
  if (mean < 0.5 * interval || mean > 1.5 * interval) {
    fail("heartbeats every " + seconds_text(mean) + " on average; the scene's interval is " + fmt(interval) + " s");
  }
  if (max_gap > 0.5 * timeout) {
    fail("a gap of " + seconds_text(max_gap) + " between heartbeats; heartbeat_timeout_s is " + fmt(timeout) + " s");
  }
  std::string note = first <= 0 ? "beating before Welcome" : "first beat " + seconds_text(first) + " after Welcome";
  note += "; " + std::to_string(beats.size()) + " beats from '" + s.side() + ".hb' in " + seconds_text(window);
  note += ", mean interval " + seconds_text(mean) + " (scene " + fmt(interval) + " s)";
  note += ", max gap " + seconds_text(max_gap);
  return note;
}

std::string check_heartbeat_waiting(Context& context) {
  Session s(context, {{"coupling.heartbeat_interval_s=0.2", "coupling.heartbeat_timeout_s=2"}, {}});
  s.start();
  block_on_data_plane(s);
  const std::uint64_t step =
      s.peer_sends_first(s.step() + s.exchange_interval()) ? s.step() : s.step() + s.exchange_interval();
  const auto from = Clock::now();
  while (since(from) < 2.0) {
    if (auto message = s.poll_control(0.05)) {
      fail("the side sent " + describe(*message) + " while it waited for the peer's DataFrame");
    }
    for (const auto& beat : s.beats()) {
      if (beat.at < from || !beat.heartbeat.waiting_for_peer()) continue;
      if (beat.heartbeat.step() != step) {
        fail("while blocked after step " + std::to_string(step) + " the side's heartbeat says step " +
             std::to_string(beat.heartbeat.step()) + "; Heartbeat.step is the last completed step");
      }
      return "heartbeat with waiting_for_peer = true, step " + std::to_string(step) + ", " + seconds_text(since(from)) +
             " after the side blocked";
    }
  }
  fail("no heartbeat with waiting_for_peer = true within 2 s while the side was blocked on the data plane");
}

std::string check_reject(Context& context) {
  Session s(context);
  s.expect_hello();
  return expect_rejected_exit(s);
}

std::string check_protocol_version(Context& context) {
  Session s(context, {{}, {"--protocol-version", "99"}});
  s.expect_hello(99);
  return "Hello carried protocol_version 99; " + expect_rejected_exit(s);
}

std::string check_shutdown_handshake(Context& context) {
  Session s(context);
  s.expect_hello();
  const auto start = Clock::now();
  s.send_control(shutdown_message(false, "conformance: Shutdown instead of Welcome"));
  return expect_clean_exit(s, start, kShutdownTimeout, "Shutdown{error: false} in the handshake");
}

// Shutdown while the side waits for the step-0 frame of the start-up exchange.
std::string check_shutdown_startup(Context& context) {
  Session s(context);
  s.expect_hello();
  s.send_welcome();
  if (s.role() == protocol::SOLID) {
    s.connect_to_listening();
    s.expect_frame(0, 0.0);
  }
  const auto start = Clock::now();
  s.send_control(shutdown_message(false, "conformance: stop during the start-up exchange"));
  return expect_clean_exit(s, start, kShutdownTimeout, "Shutdown{error: false} during the step-0 exchange");
}

std::string check_shutdown_idle(Context& context) {
  Session s(context);
  s.start();
  s.run_command(s.exchange_interval());
  const auto start = Clock::now();
  s.send_control(shutdown_message(false, "conformance: end of run"));
  return expect_clean_exit(s, start, kShutdownTimeout, "Shutdown{error: false} between commands");
}

std::string check_shutdown_waiting(Context& context) {
  Session s(context);
  s.start();
  block_on_data_plane(s);
  const auto start = Clock::now();
  s.send_control(shutdown_message(false, "conformance: stop while blocked on the data plane"));
  return expect_clean_exit(s, start, kShutdownTimeout, "Shutdown{error: false} while blocked on the data plane");
}

std::string check_shutdown_error(Context& context) {
  Session s(context);
  s.start();
  const auto start = Clock::now();
  s.send_control(shutdown_message(true, "conformance: the other side failed"));
  if (!s.wait_exit(kShutdownTimeout)) fail("still running " + seconds_text(kShutdownTimeout) + " after Shutdown");
  if (!s.exit_status()) fail("after Shutdown{error: true} the program " + *s.ended() + "; it must exit, not crash");
  // protocol.proto, Shutdown: "exits (status 0 if !error)": a run stopped for an error does not end with 0.
  if (*s.exit_status() == 0) {
    fail(
        "after Shutdown{error: true} the program exited with status 0; status 0 is for Shutdown{error: false} "
        "only, so that whoever started the side sees that the run failed");
  }
  return *s.ended() + " " + seconds_text(s.seconds_to_exit(start)) + " after Shutdown{error: true}";
}

std::string silence(Context& context, bool blocked) {
  const double timeout = 1.0, margin = 1.5;
  Session s(context, {{"coupling.heartbeat_interval_s=0.2", "coupling.heartbeat_timeout_s=1"}, {}});
  s.start();
  if (blocked) block_on_data_plane(s);
  s.set_heartbeats(false);
  const auto last = s.last_sent();
  if (!s.wait_exit(timeout + margin)) {
    fail("still running " + seconds_text(since(last)) +
         " after the coupler went silent; heartbeat_timeout_s = " + fmt(timeout) + " s");
  }
  const double after = s.seconds_to_exit(last);
  const auto status = s.exit_status();
  if (!status) fail("the program " + *s.ended() + " when the coupler went silent; it must exit, not crash");
  if (*status == 0) fail("the program exited with status 0 when it lost the coupler; it must exit non-zero");
  if (after < 0.9 * timeout) {
    fail("the program gave up " + seconds_text(after) +
         " after the coupler's last message, before "
         "heartbeat_timeout_s = " +
         fmt(timeout) + " s");
  }
  return *s.ended() + " " + seconds_text(after) + " after the coupler's last message (heartbeat_timeout_s " +
         fmt(timeout) + " s)";
}

}  // namespace

std::string seconds_text(double seconds) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f s", seconds);
  return text;
}

std::string expect_clean_exit(Session& s, Clock::time_point start, double timeout_s, const std::string& after) {
  if (!s.wait_exit(timeout_s)) fail("still running " + seconds_text(timeout_s) + " after " + after);
  const auto status = s.exit_status();
  if (!status || *status != 0) fail("after " + after + " the program " + *s.ended() + "; status 0 is due");
  if (!s.errors().empty()) {
    fail("the side sent Error (" + s.errors().front().what() + "): " + s.errors().front().message() + " after " +
         after);
  }
  return *s.ended() + " " + seconds_text(s.seconds_to_exit(start)) + " after " + after;
}

std::vector<Check> lifecycle_checks() {
  return {
      {"hello", "first message Hello: role, protocol_version 1, implementation and version; routing id = role",
       check_hello},
      {"startup", "Welcome -> (solid: Listening) -> step-0 exchange in order -> Ready with stable_dt > 0",
       check_startup},
      {"heartbeat", "heartbeats from '<role>.hb' from Welcome on at the scene's interval, sequence +1, step 0",
       check_heartbeat},
      {"heartbeat_waiting", "blocked on the data plane: heartbeat with waiting_for_peer and the last step",
       check_heartbeat_waiting},
      {"reject", "Reject in answer to Hello -> exit non-zero within 3 s", check_reject},
      {"protocol_version", "--protocol-version 99 -> Hello carries 99; Reject -> exit non-zero",
       check_protocol_version},
      {"shutdown_handshake", "Shutdown instead of Welcome -> exit 0 within 2 s", check_shutdown_handshake},
      {"shutdown_startup", "Shutdown while waiting for the step-0 frame -> exit 0 within 2 s", check_shutdown_startup},
      {"shutdown_idle", "Shutdown{error: false} between commands -> exit 0 within 2 s", check_shutdown_idle},
      {"shutdown_waiting", "Shutdown while blocked on the data plane -> exit 0 within 2 s", check_shutdown_waiting},
      {"shutdown_error", "Shutdown{error: true} -> exit non-zero within 2 s", check_shutdown_error},
      {"coupler_silence", "coupler silent (timeout 1 s) while idle -> exit non-zero within timeout + 1.5 s",
       [](Context& c) { return silence(c, false); }},
      {"coupler_silence_waiting", "coupler silent while blocked on the data plane -> exit non-zero in time",
       [](Context& c) { return silence(c, true); }},
  };
}

}  // namespace hfmpm::conformance
