// Checkpoints, the coupler's part (docs/reliability.md, "Checkpoint and restart"): where they
// live, the coupler's own state file that marks one complete, finding the last complete one
// in a run directory, and the checks before a restart.
//
// <run dir>/checkpoints/step-NNNNNNNNNNNN/  solid.h5, fluid.h5 (each written by its side,
// temporary name then rename) and coupler.pb (checkpoint.proto's CouplerState, written by the
// coupler the same way, only after both sides reported theirs written).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "hfmpm/checkpoint.pb.h"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

inline constexpr std::uint32_t kCouplerCheckpointFormat = 1;

// A checkpoint that cannot be used for this restart; the text names why.
class RestartError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RestartPoint {
  std::string run_dir;    // as given
  std::string directory;  // relative to run_dir: "checkpoints/step-000000000120"
  checkpoint::CouplerState state;
};

// "checkpoints/step-000000000120"
std::string checkpoint_directory(std::uint64_t step);

// The complete checkpoint with the highest step in run_dir (its coupler.pb exists and parses;
// a directory without it was cut short and is skipped). Throws RestartError if there is none,
// or if it was written by another program, protocol or scene-schema version.
RestartPoint find_restart(const std::string& run_dir);

// Throws RestartError unless `scene` is the checkpoint's scene (the same proto::scene_hash).
void check_restart_scene(const RestartPoint& point, const scene::Scene& scene);

// Writes <run_dir>/<directory>/coupler.pb atomically (temporary file, fsync, rename), then
// removes the checkpoints before the previous complete one (two complete ones are kept).
void write_coupler_checkpoint(const std::string& run_dir, const std::string& directory,
                              const checkpoint::CouplerState& state);

// Keeps the header of history.csv and its rows up to and including `step`; the rows a killed
// run wrote after its last checkpoint go (the restart writes them again).
void truncate_history(const std::string& path, std::uint64_t step);

}  // namespace hfmpm::coupling
