// Private to the side runtime: the rules a side applies to what it is sent
// (side_checks.cpp), and the --fault test hook's action (fault.cpp).
#pragma once

#include <cstdint>
#include <string>

#include "hfmpm/proto/envelope.hpp"
#include "hfmpm/runtime/side_runtime.hpp"
#include "hfmpm/runtime/transport.hpp"

namespace hfmpm::coupling {

// A StepCommand against the side's own step and time; `interval`: the
// exchange interval num_steps must be a multiple of (1 without a peer).
// Throws proto::ProtocolError naming the broken rule.
void check_step_command(const protocol::StepCommand& command, std::uint64_t step, double t, std::uint32_t interval);

// A message on the data plane: a DataFrame with the peer's payload (a
// FluidState for a solid, a CrackState for a fluid) for step `expected`.
void check_data_frame(const protocol::Envelope& envelope, protocol::Role role, std::uint64_t expected);

// The --fault hook at `step`: exits, aborts, hangs, stops itself or sends
// garbage on the given links; returns true for Kind::NaN (poison the next
// frame). Does nothing unless `fault` is due at `step`.
bool act_on_fault(const Fault& fault, std::uint64_t step, const std::string& role, Link& control, Link* data);

}  // namespace hfmpm::coupling
