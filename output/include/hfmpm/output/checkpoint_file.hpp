// One side's checkpoint: its full state (StateWriter / StateReader arrays) in one HDF5 file,
// stamped with what it belongs to (docs/reliability.md, "Checkpoint and restart").
//
// HDF5 layout: one dataset per state array at the root, named as the physics named it
// ("solid.particles.x"), float64 or uint64, one-dimensional; root string attributes
// with the stamp (format, role, implementation, program version, protocol and scene
// schema versions, scene hash, step, time as 17 significant digits and as its bits).
//
// Checksums (format 2; docs/reliability.md, "Damaged checkpoints"): every dataset carries the
// string attribute checksum_fnv1a64, 16 hex digits of FNV-1a (64 bits, hfmpm/checksum.hpp) over
// its name and its type ("f64", "u64" or "u8"), each followed by a zero byte, and the bytes the file
// holds for its elements (little-endian; one-dimensional, of one of those types); the root attribute `datasets`
// counts them, and the root attribute checksum_fnv1a64 covers the stamp ("key=value\n" for each
// root attribute above and `datasets`, in that order). A file of format 1 has none and is refused.
//
// write_checkpoint writes <path>.tmp, flushes and closes it, fsyncs it and renames it to
// <path>: a checkpoint file either exists whole or not at all, also after kill -9.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

#include "hfmpm/state_archive.hpp"

namespace hfmpm::output {

inline constexpr std::uint32_t kCheckpointFormat = 2;

// A checkpoint file whose bytes are not those written: a dataset or the stamp that does not match
// its checksum, a dataset without one, a count that differs, or a file HDF5 cannot read. The text
// names the file and the dataset (or attribute).
class DamagedCheckpoint : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void write_checkpoint(const std::string& path, const CheckpointStamp& stamp,
                      const std::function<void(StateWriter&)>& fill);

// Reads every dataset of the file at path and checks it, and the stamp, against its checksum.
// Throws DamagedCheckpoint naming the file and the first dataset (in name order) or attribute that
// does not match, and std::runtime_error for a file of another format (naming both formats).
void verify_checkpoint(const std::string& path);

// Opens path, checks its format, then every checksum (verify_checkpoint), then its stamp against
// `expected` (every field; t bit for bit), and hands the state to `read`. A stamp that differs
// throws std::runtime_error naming the field, both values and the file.
void read_checkpoint(const std::string& path, const CheckpointStamp& expected,
                     const std::function<void(const StateReader&)>& read);

}  // namespace hfmpm::output
