// Converters between the wire messages and the plain types of exchange.hpp.
// from_proto checks every invariant the protocol states and throws
// ProtocolError naming the crack, the array and the index that break it.
#pragma once

#include "hfmpm/exchange.hpp"
#include "hfmpm/proto/envelope.hpp"
#include "hfmpm/protocol.pb.h"
#include "hfmpm/scene.pb.h"
#include "hfmpm/time_function.hpp"

namespace hfmpm::proto {

void to_proto(const CrackGeometry& crack, protocol::CrackState::Crack* out);
CrackGeometry from_proto(const protocol::CrackState::Crack& crack);

void to_proto(const CrackPressure& crack, protocol::FluidState::Crack* out);
CrackPressure from_proto(const protocol::FluidState::Crack& crack);

void to_proto(const SideDiagnostics& diagnostics, protocol::Diagnostics* out);
SideDiagnostics from_proto(const protocol::Diagnostics& diagnostics);

// Assumes a validated scene (hfmpm::scene::validate).
TimeFunction to_time_function(const scene::TimeFunction& f);

}  // namespace hfmpm::proto
