#include "side_checks.hpp"

#include <algorithm>
#include <cmath>

namespace hfmpm::coupling {

void check_step_command(const protocol::StepCommand& command, std::uint64_t step, double t, std::uint32_t interval) {
  if (command.first_step() != step) {
    throw proto::ProtocolError("StepCommand starts at step " + std::to_string(command.first_step()) +
                               " but this side is at step " + std::to_string(step));
  }
  if (!(std::isfinite(command.dt()) && command.dt() > 0)) {
    throw proto::ProtocolError("StepCommand dt = " + std::to_string(command.dt()) + " s; dt must be finite and > 0");
  }
  if (command.num_steps() == 0 || command.num_steps() % interval != 0) {
    throw proto::ProtocolError("StepCommand num_steps = " + std::to_string(command.num_steps()) +
                               "; it must be >= 1 and a multiple of the exchange interval " + std::to_string(interval));
  }
  if (std::abs(command.t() - t) > 1e-9 * std::max(1.0, std::abs(t))) {
    throw proto::ProtocolError("StepCommand t = " + std::to_string(command.t()) +
                               " s but this side is at t = " + std::to_string(t) + " s");
  }
}

void check_data_frame(const protocol::Envelope& envelope, protocol::Role role, std::uint64_t expected) {
  const std::string peer = role == protocol::SOLID ? "fluid" : "solid";
  const std::string from = "the " + peer + " side";
  if (!envelope.has_data()) {
    throw proto::ProtocolError("unexpected " + std::string(proto::body_name(envelope)) + " message from " + from +
                               " on the data plane; only DataFrame is allowed there");
  }
  const auto& frame = envelope.data();
  const bool right_payload = role == protocol::SOLID ? frame.has_fluid() : frame.has_crack();
  if (!right_payload) {
    throw proto::ProtocolError("DataFrame from " + from + " carries " +
                               (frame.has_crack()   ? "a CrackState"
                                : frame.has_fluid() ? "a FluidState"
                                                    : "nothing") +
                               "; a " + peer + " side sends " +
                               (role == protocol::SOLID ? "FluidState" : "CrackState"));
  }
  if (frame.step() != expected) {
    throw proto::ProtocolError("DataFrame from " + from + " is for step " + std::to_string(frame.step()) +
                               " but step " + std::to_string(expected) + " was due");
  }
}

}  // namespace hfmpm::coupling
