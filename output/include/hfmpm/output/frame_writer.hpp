// hfmpm::output::FrameWriter: writes simulation frames (2D point sets with per-point data) to one HDF5
// file plus an XDMF 2 sidecar (<name>.xmf beside <name>.h5) that ParaView opens directly (docs/architecture.md, "Output
// files").
//
// HDF5 layout (all datasets little-endian, contiguous):
//   /                                 string attributes: "title" and whatever attribute() set
//   /frames                           attribute frame_count (uint64): frames completed by end_frame()
//   /frames/NNNNNN                    one group per frame, NNNNNN = 0-based frame index, 6+ digits;
//                                     attributes time_s (float64) and step (uint64)
//   /frames/NNNNNN/<set>/positions    float64 N x 2 (x, y)
//   /frames/NNNNNN/<set>/<scalar>     float64 N
//   /frames/NNNNNN/<set>/<integer>    int32   N
//   /frames/NNNNNN/<set>/<vector>     float64 N x 3 (x, y, 0): ParaView wants 3 components for a Vector
//   /frames/NNNNNN/<set>/<tensor>     float64 N x 4 (xx, yy, xy, zz); string attribute components = "xx yy xy zz"
// A set with N = 0 still gets its group and zero-sized datasets.
//
// XDMF layout: one top-level <Grid GridType="Collection" CollectionType="Temporal"> per point-set name, whose
// children are Polyvertex Uniform grids named after the set (one per frame, each with its own <Time Value=.../>).
// Open it in ParaView with the "XDMF Reader" (the XDMF 2 one): it gives a multiblock with one block per set,
// named after the set and at the same index at every time, each block holding the grid of the current time;
// the reader panel lists the sets so they can be switched off. (A temporal collection of per-frame spatial
// collections would renumber the blocks whenever a set is missing from a frame.)
// - A set with N = 0 in a frame is left out of that frame's XDMF (its HDF5 datasets still exist): empty
//   DataItems are not reliably accepted by the XDMF readers. At that time the set's block is simply empty.
// - There is no XDMF file until a frame has a set with points: ParaView's XDMF reader crashes on a Domain
//   without grids. An XDMF left beside the HDF5 file by an earlier run is deleted when the writer starts.
// - Geometry is GeometryType="XY" on the N x 2 positions.
// - Scalars and integers are Scalar attributes, vectors Vector attributes (N x 3).
// - A tensor <name> is shown as four Scalar attributes <name>_xx, <name>_yy, <name>_xy, <name>_zz, each a
//   HyperSlab of the one N x 4 dataset. Not Tensor6: the XDMF 2 reader expands Tensor6 as xx xy xz yy yz zz
//   while VTK's own symmetric order is xx yy zz xy yz xz, so a Tensor6 would be misread by one or the other.
// - Times are written with the shortest decimal form that reads back as the same double.
// - DataItems refer to the HDF5 file by its base name, so the pair can be moved together.
// - ParaView 5.11's Xdmf3ReaderS/T read the sets, times, positions, scalars, integers and vectors too, but skip
//   HyperSlab DataItems (so no tensor components, with a warning "Skipping unrecognized array type") and make no
//   vertex cells from a Polyvertex topology without connectivity; prefer the "XDMF Reader".
//
// Durability: the data of a frame is kept in memory until end_frame(), which writes it, flushes the HDF5 file
// and then replaces the XDMF whole (temporary file + rename). So after every end_frame() both files (the XDMF
// once it exists) are complete and readable, and a run that dies between end_frame() calls loses only the frame
// in progress. (A death inside end_frame() itself may leave the HDF5 file damaged: HDF5 1.10 has no journal.)
// If end_frame() throws std::runtime_error, that frame is dropped and its group number is not reused.
// The writer disables HDF5 file locking on its own handle so that a viewer can open the file while the run goes
// on. (Within the writing process, opening the same file again through HDF5 with default settings fails while
// the writer is alive: HDF5 refuses a second open with a different locking setting.)
//
// Usage order, per frame: begin_frame, then for each set points() before that set's attributes, then end_frame.
// Names (sets, attributes, root attribute keys) are [A-Za-z0-9_]+; an attribute may not be called "positions".
// Misuse throws std::invalid_argument (bad names, sizes, values) or std::logic_error (call order, duplicates);
// such a throw leaves the writer as it was. HDF5 and file-system failures throw std::runtime_error naming the
// path and the operation.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::output {

class FrameWriter {
 public:
  // Creates (truncates) h5_path; the XDMF is <h5_path with extension .xmf> (see above for when it appears).
  // title is stored as the root attribute "title" and as an <Information Name="title"> in the XDMF.
  FrameWriter(const std::string& h5_path, const std::string& title);
  // Restarts (docs/reliability.md, "Checkpoint and restart"): save() writes what the writer
  // knows of the frames written so far (their number, times and XDMF entries); the resuming
  // constructor opens the existing h5_path for writing, removes the frame groups written after
  // that state was saved (by a run killed after its checkpoint), sets frame_count back and
  // rewrites the XDMF, so that the continued run's file holds the frames an uninterrupted run
  // would have. Throws std::runtime_error if the file is missing or unreadable. Call save()
  // between frames only.
  void save(StateWriter& out) const;
  FrameWriter(const std::string& h5_path, const StateReader& saved);
  // Closes the file. A frame begun but not ended is discarded from the XDMF and from frame_count.
  ~FrameWriter();
  FrameWriter(FrameWriter&&) noexcept;
  FrameWriter& operator=(FrameWriter&&) noexcept;
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Starts a frame. time_s must be finite and greater than the previous frame's time.
  void begin_frame(double time_s, std::uint64_t step);
  // Declares a point set of this frame (particles, crack particles, fluid particles, ...), once per frame.
  void points(const std::string& set, const std::vector<Vec2>& positions);
  // Per-point data of a set declared in this frame; sizes must equal the set's point count.
  void scalar(const std::string& set, const std::string& name, const std::vector<double>& values);
  void integer(const std::string& set, const std::string& name, const std::vector<std::int32_t>& values);
  void vector(const std::string& set, const std::string& name, const std::vector<Vec2>& values);
  // Symmetric in-plane tensor with the out-of-plane normal component (plane strain): (xx, yy, xy, zz).
  void tensor(const std::string& set, const std::string& name, const std::vector<Eigen::Vector4d>& xx_yy_xy_zz);
  // Writes the frame, flushes the HDF5 file and rewrites the XDMF.
  void end_frame();

  // Frame-independent metadata: a string attribute on the HDF5 root group (e.g. scene, units "SI", version),
  // also listed in the XDMF as <Information>. Written and flushed at once; setting a key again replaces it.
  void attribute(const std::string& key, const std::string& value);

  const std::string& h5_path() const;
  const std::string& xdmf_path() const;
  std::size_t frames_written() const;  // frames completed by end_frame()
  bool in_frame() const;               // between begin_frame() and end_frame()

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hfmpm::output
