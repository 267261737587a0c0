// Conformance checks of a side's answer to bad input: a wrong StepCommand,
// garbage or multi-frame messages, an unexpected message, and bad DataFrames
// (wrong step, wrong payload, garbage, NaN). Each runs in its own launch; the
// side must send Error{who: its role, what: "protocol"} and exit non-zero.
#include <cmath>
#include <functional>
#include <limits>

#include "checks.hpp"
#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::conformance {
namespace {

// Bytes no protobuf parser accepts: a field tag with the invalid wire type 7.
const std::string kGarbage = "\xff\xff\xff\xff\x0f not an hfmpm envelope";

std::string first_line(const std::string& text, std::size_t max = 110) {
  const std::string line = text.substr(0, text.find('\n'));
  return line.size() > max ? line.substr(0, max) + "..." : line;
}

// After `what` the side must send Error (protocol) as its next control message and exit non-zero.
std::string expect_protocol_error(Session& s, const std::string& what) {
  const auto start = Clock::now();
  const auto message = s.poll_control(kErrorTimeout);
  if (!message) fail("no Error after " + what + s.waited(kErrorTimeout));
  if (!message->has_error()) fail("after " + what + " the side sent " + describe(*message) + " where Error was due");
  const auto& error = message->error();
  if (error.who() != s.role()) {
    fail("Error.who is " + protocol::Role_Name(error.who()) + "; the " + s.side() + " side says " +
         protocol::Role_Name(s.role()));
  }
  if (error.what() != "protocol") {
    fail("Error.what is \"" + error.what() + "\" after " + what + "; \"protocol\" is due");
  }
  if (error.message().empty()) fail("Error.message is empty; it tells a person what happened");
  if (!s.wait_exit(kErrorTimeout)) fail("the side sent Error but still ran " + seconds_text(kErrorTimeout) + " later");
  const auto status = s.exit_status();
  if (!status) fail("the program " + *s.ended() + " after its Error; it must exit with a non-zero status");
  if (*status == 0) {
    fail("the program exited with status 0 after sending Error; a side that sends Error exits non-zero");
  }
  return "Error(protocol) \"" + first_line(error.message()) + "\"; " + *s.ended() + " after " +
         seconds_text(s.seconds_to_exit(start));
}

protocol::Envelope step_command(const Session& s, std::uint64_t first_step, std::uint32_t num_steps, double dt) {
  protocol::Envelope envelope;
  auto* command = envelope.mutable_step_command();
  command->set_first_step(first_step);
  command->set_num_steps(num_steps);
  command->set_t(s.t());
  command->set_dt(dt);
  return envelope;
}

std::string check_first_step(Context& context) {
  Session s(context);
  s.start();
  s.run_command(s.exchange_interval());
  s.send_control(step_command(s, s.step() + 3, s.exchange_interval(), s.dt()));
  return expect_protocol_error(s, "a StepCommand whose first_step is 3 ahead of the side");
}

std::string check_dt(Context& context) {
  Session s(context);
  s.start();
  s.send_control(step_command(s, s.step(), s.exchange_interval(), 0.0));
  return expect_protocol_error(s, "a StepCommand with dt = 0");
}

std::string check_num_steps(Context& context) {
  Session s(context, {{"coupling.exchange_interval=5"}, {}});
  s.start();
  s.send_control(step_command(s, s.step(), 3, s.dt()));
  return expect_protocol_error(s, "a StepCommand of 3 steps with exchange_interval 5");
}

std::string check_garbage_control(Context& context) {
  Session s(context);
  s.start();
  s.send_control_frames({kGarbage});
  return expect_protocol_error(s, "garbage bytes on the control socket");
}

std::string check_multiframe_control(Context& context) {
  Session s(context);
  s.start();
  const std::string command = proto::encode(step_command(s, s.step(), s.exchange_interval(), s.dt()));
  s.send_control_frames({command, command});
  return expect_protocol_error(s, "a two-frame message on the control socket");
}

std::string check_unexpected(Context& context) {
  Session s(context);
  s.start();
  protocol::Envelope envelope;
  envelope.mutable_listening()->set_data_endpoint("ipc:///nowhere");
  s.send_control(envelope);
  return expect_protocol_error(s, "a Listening message (side -> coupler only) where a StepCommand was due");
}

// Starts a command, takes the side's frame (unless ours goes first) and sends `bad` instead of ours.
using Spoil = std::function<void(protocol::DataFrame& ours, const protocol::DataFrame* theirs)>;
std::string bad_exchange(Session& s, const Spoil& spoil, const std::string& what) {
  const auto k = s.exchange_interval();
  const auto times = s.send_command(k);
  const std::uint64_t step = s.step() + k;
  std::optional<protocol::DataFrame> theirs;
  if (!s.peer_sends_first(step)) theirs = s.expect_frame(step, times.back());
  auto ours = s.peer().make(step, times.back());
  spoil(ours, theirs ? &*theirs : nullptr);
  s.send_frame(ours);
  return expect_protocol_error(s, what);
}

std::string check_data_step(Context& context) {
  Session s(context);
  s.start();
  return bad_exchange(
      s, [](protocol::DataFrame& ours, const protocol::DataFrame*) { ours.set_step(ours.step() + 1); },
      "a DataFrame for the step after the one due");
}

std::string check_data_payload(Context& context) {
  Session s(context);
  s.start();
  const bool solid = s.role() == protocol::SOLID;
  return bad_exchange(
      s,
      [solid](protocol::DataFrame& ours, const protocol::DataFrame* theirs) {
        const auto step = ours.step();
        const double t = ours.t();
        if (theirs) {
          ours = *theirs;  // the side's own kind of payload, echoed back
        } else if (solid) {
          ours.mutable_crack()->add_cracks();
        } else {
          ours.mutable_fluid()->add_cracks();
        }
        ours.set_step(step);
        ours.set_t(t);
      },
      std::string("a DataFrame carrying a ") + (solid ? "CrackState to the solid" : "FluidState to the fluid"));
}

std::string check_data_garbage(Context& context) {
  Session s(context);
  s.start();
  const auto k = s.exchange_interval();
  const auto times = s.send_command(k);
  if (!s.peer_sends_first(s.step() + k)) s.expect_frame(s.step() + k, times.back());
  s.send_data_bytes(kGarbage);
  return expect_protocol_error(s, "garbage bytes on the data plane");
}

std::string check_data_not_frame(Context& context) {
  Session s(context);
  s.start();
  const auto k = s.exchange_interval();
  const auto times = s.send_command(k);
  if (!s.peer_sends_first(s.step() + k)) s.expect_frame(s.step() + k, times.back());
  protocol::Envelope envelope;
  envelope.mutable_heartbeat()->set_role(s.role() == protocol::SOLID ? protocol::FLUID : protocol::SOLID);
  s.send_data_bytes(proto::encode(envelope));
  return expect_protocol_error(s, "a Heartbeat (not a DataFrame) on the data plane");
}

std::string check_nan(Context& context) {
  Session s(context);
  s.start();
  const bool solid = s.role() == protocol::SOLID;
  return bad_exchange(
      s,
      [](protocol::DataFrame& ours, const protocol::DataFrame*) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        if (ours.has_fluid()) ours.mutable_fluid()->mutable_cracks(0)->set_pressure(1, nan);
        if (ours.has_crack()) ours.mutable_crack()->mutable_cracks(0)->set_width(1, nan);
      },
      solid ? "a FluidState with pressure[1] = NaN" : "a CrackState with width[1] = NaN");
}

}  // namespace

std::vector<Check> error_checks() {
  return {
      {"error_first_step", "StepCommand with the wrong first_step -> Error(protocol), exit non-zero", check_first_step},
      {"error_dt", "StepCommand with dt = 0 -> Error(protocol), exit non-zero", check_dt},
      {"error_num_steps", "num_steps not a multiple of exchange_interval -> Error(protocol), exit non-zero",
       check_num_steps},
      {"error_garbage_control", "garbage bytes on the control socket -> Error(protocol), exit non-zero",
       check_garbage_control},
      {"error_multiframe_control", "a two-frame control message -> Error(protocol), exit non-zero",
       check_multiframe_control},
      {"error_unexpected", "a message the coupler never sends (Listening) -> Error(protocol), exit non-zero",
       check_unexpected},
      {"error_data_step", "DataFrame with the wrong step -> Error(protocol), exit non-zero", check_data_step},
      {"error_data_payload", "DataFrame with the wrong payload type -> Error(protocol), exit non-zero",
       check_data_payload},
      {"error_data_garbage", "garbage bytes on the data plane -> Error(protocol), exit non-zero", check_data_garbage},
      {"error_data_not_frame", "an Envelope other than DataFrame on the data plane -> Error(protocol), exit",
       check_data_not_frame},
      {"error_nan", "NaN in the peer's frame (width for a fluid, pressure for a solid) -> Error(protocol), exit",
       check_nan},
  };
}

}  // namespace hfmpm::conformance
