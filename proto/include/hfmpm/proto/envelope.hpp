// Encoding and decoding of the one top-level message, with errors that say
// what arrived and from whom. Nothing read from a socket is trusted.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hfmpm/protocol.pb.h"

namespace hfmpm::proto {

inline constexpr std::uint32_t kProtocolVersion = protocol::CURRENT;
inline constexpr std::uint32_t kSceneSchemaVersion = protocol::SCENE_SCHEMA_CURRENT;
// The program's version: in Hello, and in every checkpoint (a checkpoint of another version is refused).
inline constexpr const char* kProgramVersion = "0.1.0";

// 16 hex digits: FNV-1a (64 bits) of the scene's deterministic binary serialization. Two scenes
// with the same hash are the same scene for a restart (docs/reliability.md, "Checkpoint and restart").
std::string scene_hash(const scene::Scene& scene);

// A message that breaks the protocol: malformed, unexpected, or inconsistent.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::string encode(const protocol::Envelope& envelope);

// Parses one frame; throws ProtocolError naming `from` if the bytes are not an
// Envelope with a body, or carry fields this version does not know.
protocol::Envelope decode(const void* data, std::size_t size, std::string_view from);

// A double or float set in a message that is NaN or infinite: its path
// from the message ("diagnostics.inlet_pressure", "cracks[0].x_m[1]") and value.
struct NonFinite {
  std::string path;
  double value = 0;
};
// Every one in `message`, nested and repeated fields included, in field
// order. By reflection, so a field added later is covered without code here
// (the scene's rule "every number is finite", the coupler's check of what a
// side reports).
std::vector<NonFinite> non_finite_numbers(const google::protobuf::Message& message);

// "hello", "step_command", ... or "empty" for an envelope without a body.
std::string_view body_name(const protocol::Envelope& envelope);
std::string_view role_name(protocol::Role role);

}  // namespace hfmpm::proto
