// The fluid's grid: the crack particles of one crack, ordered from the mouth
// (node 0) to the tip, with the 1D coordinate s = arc length along the crack
// polyline (docs/fluid.md). The solid publishes it after every step, so the grid
// moves and stretches with the solid; fictitious forces from curvature and
// stretching are ignored. Fluid particles keep their arc length when the grid
// moves (they are not convected with the crack particles).
//
// When the crack grows, crack particles are appended at the tip with new ids;
// existing ids must keep their order (they are the nodes' identities).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::fluid::mpm {

class CrackGrid {
 public:
  // Take the crack's geometry. The first call fixes the crack id; later calls
  // must carry the previous ids as a prefix (growth appends at the end).
  // Throws std::invalid_argument, naming the crack and the offending entry, on
  // fewer than 2 crack particles, arrays of different sizes, a non-finite or
  // negative width, coincident crack particles, a different crack id, or ids
  // that were reordered or removed.
  // Nodes with arc length <= pre_opening_length (m; always node 0) when they
  // first appear are pre_opening (m) wider for the fluid than the crack, for
  // as long as they exist (the crack's stretching does not move a node out
  // of it): a virtual opening
  // that lets fluid enter a closed mouth. It is added (not a floor) so that
  // the fluid's width always follows the crack's: under a floor the fluid
  // sits in a rigid virtual channel until the crack opens past it, its
  // pressure rises with no relief, and the coupled faces chatter.
  // Every node is virtual_opening (m) wider still.
  void set(const CrackGeometry& crack, double pre_opening, double pre_opening_length, double virtual_opening = 0);

  // Move the nodes within a step (the implicit step's fluid substeps): new
  // positions and crack widths for the same nodes; each node keeps its
  // virtual and pre-opening. The positions must keep the nodes distinct
  // (std::invalid_argument otherwise).
  void move(const std::vector<Vec2>& position, const std::vector<double>& crack_width);

  bool empty() const { return ids_.empty(); }
  std::size_t size() const { return ids_.size(); }
  std::uint32_t crack_id() const { return crack_id_; }
  std::size_t appended() const { return appended_; }  // nodes appended by the last set()
  const std::vector<std::uint64_t>& ids() const { return ids_; }
  const std::vector<Vec2>& position() const { return position_; }          // m
  const std::vector<double>& arc() const { return arc_; }                  // m, s_i
  const std::vector<double>& width() const { return width_; }              // m, effective (with the pre-opening)
  const std::vector<double>& crack_width() const { return crack_width_; }  // m, as published by the solid
  double length() const { return arc_.back(); }                            // m, mouth to tip along the crack
  double min_spacing() const { return min_spacing_; }                      // m, smallest node spacing

  // m, effective width at s (linear between nodes; the end values outside).
  double width_at(double s) const { return interpolate(s, width_); }
  // m^2, integral of the effective width over [a, b]; exact for the linear profile.
  double width_integral(double a, double b) const;
  // m, 2D point of arc length s on the crack polyline (clamped to its ends).
  Vec2 point_at(double s) const;
  // Linear interpolation of any nodal field at s.
  double interpolate(double s, std::span<const double> values) const;

  // Checkpoints: every member, bit for bit (fluid/src/mpm/checkpoint.cpp).
  void save(StateWriter& out) const;
  void load(const StateReader& in);

 private:
  std::uint32_t crack_id_ = 0;
  std::vector<std::uint64_t> ids_;
  std::vector<Vec2> position_;
  std::vector<double> arc_, width_, crack_width_;
  std::vector<double> extra_;  // m, each node's virtual and pre-opening, fixed when it first appears
  double min_spacing_ = 0;
  std::size_t appended_ = 0;
};

}  // namespace hfmpm::fluid::mpm
