// A side's frame file over a run that may be checkpointed and restarted: the
// file is created at setup (unless a restart will continue it), its state goes
// into each checkpoint, and a restart continues it from there (frames a killed
// run wrote after the checkpoint are dropped; FrameWriter's resuming
// constructor).
#pragma once

#include <optional>
#include <string>

#include "hfmpm/output/frame_writer.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::output {

class SideFrames {
 public:
  // Before setup(): the run restarts from a checkpoint, so setup() leaves the file alone.
  void will_restart() { restarting_ = true; }
  // path: the frame file, or empty for none (output.hdf5 off); title: its title attribute.
  void setup(std::string path, std::string title);
  // The writer, created at the first call after a restart whose checkpoint had
  // no file; nullptr without a frame file.
  FrameWriter* writer();
  void save(StateWriter& out) const;
  void resume(const StateReader& in);

 private:
  std::string path_, title_;
  bool restarting_ = false;
  std::optional<FrameWriter> writer_;
};

}  // namespace hfmpm::output
