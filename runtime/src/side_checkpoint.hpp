// A side's checkpoints (docs/reliability.md, "Checkpoint and restart"): where
// the file goes, the stamp that ties it to the run, and writing it with the
// time and size logged. The side runtime calls these when a StepCommand asks
// for a checkpoint and when a Welcome restarts the run.
#pragma once

#include <cstdint>
#include <string>

#include "hfmpm/runtime/side_runtime.hpp"

namespace hfmpm::coupling {

// <output_dir>/<directory>/<role>.h5, the directory created; throws
// proto::ProtocolError unless `directory` is a relative path inside output_dir.
std::string checkpoint_path(const std::string& output_dir, const std::string& directory, const std::string& role);

// What identifies a checkpoint: the side, its program, protocol and schema
// versions, the scene's hash, the step and the time.
CheckpointStamp checkpoint_stamp(const SideOptions& options, const std::string& role, const scene::Scene& scene,
                                 std::uint64_t step, double t);

// model.save_checkpoint(path, stamp), logged on stderr with its time and size;
// returns the seconds it took.
double write_side_checkpoint(SideModel& model, const std::string& path, const CheckpointStamp& stamp,
                             const std::string& role);

}  // namespace hfmpm::coupling
