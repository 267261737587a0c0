// Messages for the fuzzer: valid Envelopes of every kind (built with the
// project's generated classes and codec), byte mutations of them, raw bytes.
#pragma once

#include <string>

#include "common.hpp"
#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::reliability {

// What goes into a Welcome and a StepCommand.
struct MessageContext {
  scene::Scene coupled_scene;  // the prescribed scene (solid and fluid)
  scene::Scene dry_scene;      // the same without the fluid block
  std::string data_endpoint;   // a data endpoint nobody binds
  std::string output_dir;
  std::uint64_t step = 0;  // the receiver's step and time, for a StepCommand that follows on
  double t = 0;
};

// One Envelope of a random kind with plausible (sometimes extreme) fields.
protocol::Envelope random_envelope(Rng& rng, const MessageContext& context);

// The bytes with 1 to 4 random edits: bit flips, bytes set to interesting
// values, insertions, deletions, truncation, a repeated range, an appended field.
std::string mutate(std::string bytes, Rng& rng);

// A valid StepCommand that follows on from context.step and context.t.
protocol::Envelope next_command(Rng& rng, const MessageContext& context);

}  // namespace hfmpm::reliability
