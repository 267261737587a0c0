// One side's checkpoint: its full state (StateWriter / StateReader arrays) in one HDF5 file,
// stamped with what it belongs to (docs/reliability.md, "Checkpoint and restart").
//
// HDF5 layout: one dataset per state array at the root, named as the physics named it
// ("solid.particles.x"), float64 or uint64, one-dimensional; root string attributes
// with the stamp (format, role, implementation, program version, protocol and scene
// schema versions, scene hash, step, time as 17 significant digits and as its bits).
//
// write_checkpoint writes <path>.tmp, flushes and closes it, fsyncs it and renames it to
// <path>: a checkpoint file either exists whole or not at all, also after kill -9.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "hfmpm/state_archive.hpp"

namespace hfmpm::output {

inline constexpr std::uint32_t kCheckpointFormat = 1;

void write_checkpoint(const std::string& path, const CheckpointStamp& stamp,
                      const std::function<void(StateWriter&)>& fill);

// Opens path, checks its stamp against `expected` (every field; t bit for bit) and hands the
// state to `read`. A mismatch throws std::runtime_error naming the field, both values and the file.
void read_checkpoint(const std::string& path, const CheckpointStamp& expected,
                     const std::function<void(const StateReader&)>& read);

}  // namespace hfmpm::output
