#include "hfmpm/output/side_frames.hpp"

#include <utility>

namespace hfmpm::output {

void SideFrames::setup(std::string path, std::string title) {
  path_ = std::move(path);
  title_ = std::move(title);
  if (!restarting_) writer();  // a restart continues the file instead (resume)
}

FrameWriter* SideFrames::writer() {
  if (!writer_ && !path_.empty()) {
    writer_.emplace(path_, title_);
    writer_->attribute("units", "SI; 2D quantities per unit thickness");
  }
  return writer_ ? &*writer_ : nullptr;
}

void SideFrames::save(StateWriter& out) const {
  out.put("side.frames", writer_ ? 1 : 0);
  if (!writer_) return;
  PrefixedWriter frames(out, "frames.");
  writer_->save(frames);
}

void SideFrames::resume(const StateReader& in) {
  int frames = 0;
  in.get("side.frames", frames);
  if (frames == 0 || path_.empty()) return;
  writer_.reset();
  writer_.emplace(path_, PrefixedReader(in, "frames."));
}

}  // namespace hfmpm::output
