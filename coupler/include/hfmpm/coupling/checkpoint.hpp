// Checkpoints, the coupler's part (docs/reliability.md, "Checkpoint and restart"): where they
// live, the coupler's own state file that marks one complete, finding the last complete one
// in a run directory, and the checks before a restart.
//
// <run dir>/checkpoints/step-NNNNNNNNNNNN/  solid.h5, fluid.h5 (each written by its side,
// temporary name then rename) and coupler.pb (checkpoint.proto's CouplerState, written by the
// coupler the same way, only after both sides reported theirs written). Format 2: every file
// carries checksums (coupler.pb its field `checksum`, last; the sides' files one per dataset) and
// a restart passes over a damaged checkpoint to the complete one before it (docs/reliability.md,
// "Damaged checkpoints").
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hfmpm/checkpoint.pb.h"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

inline constexpr std::uint32_t kCouplerCheckpointFormat = 2;

// A checkpoint that cannot be used for this restart; the text names why.
class RestartError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RestartPoint {
  std::string run_dir;    // as given
  std::string directory;  // relative to run_dir: "checkpoints/step-000000000120"
  checkpoint::CouplerState state;
  // Complete checkpoints after this one that were passed over as damaged: "checkpoints/step-N: why".
  std::vector<std::string> damaged;
};

// "checkpoints/step-000000000120"
std::string checkpoint_directory(std::uint64_t step);

// Checks a side's checkpoint file (hfmpm/output/checkpoint_file.hpp, verify_checkpoint: this
// library does not read HDF5); throws, naming the file and the dataset, if it is damaged.
using SideFileCheck = std::function<void(const std::string& path)>;

// The intact complete checkpoint with the highest step in run_dir. Complete: its coupler.pb exists
// (a directory without it was cut short and is skipped). Intact: coupler.pb matches its checksum,
// and each expected side's file in the directory, if it is there (a side started by hand may keep
// its file elsewhere, and then checks it itself), passes `check_side_file` (if given). A damaged
// checkpoint is passed over for the one before, and named in RestartPoint::damaged. Throws
// RestartError if there is no complete checkpoint, if every one is damaged (naming each and why),
// or if the one found was written by another checkpoint format, program, protocol or
// scene-schema version.
RestartPoint find_restart(const std::string& run_dir, const SideFileCheck& check_side_file = {});

// The bytes of a coupler.pb: `state` without its checksum, then its field `checksum` (34,
// fixed64) holding FNV-1a (64 bits) of those bytes.
std::string coupler_checkpoint_bytes(checkpoint::CouplerState state);

// Throws RestartError unless `scene` is the checkpoint's scene (the same proto::scene_hash).
void check_restart_scene(const RestartPoint& point, const scene::Scene& scene);

// Writes <run_dir>/<directory>/coupler.pb atomically (temporary file, fsync, rename), then
// removes the checkpoints before the previous complete one (two complete ones are kept).
void write_coupler_checkpoint(const std::string& run_dir, const std::string& directory,
                              const checkpoint::CouplerState& state);

// Keeps the header of history.csv and its rows up to and including `step`; the rows a killed
// run wrote after its last checkpoint go (the restart writes them again), and so does a row that
// repeats the step of the row before it (before this was fixed, a run stopped by a signal right
// after an output row wrote that step twice; the first is the uninterrupted run's). Returns the
// step of the last row kept, or nothing if none is.
std::optional<std::uint64_t> truncate_history(const std::string& path, std::uint64_t step);

}  // namespace hfmpm::coupling
