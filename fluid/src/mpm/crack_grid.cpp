#include "hfmpm/fluid/mpm/crack_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "hfmpm/fluid/mpm/shape.hpp"

namespace hfmpm::fluid::mpm {
namespace {

[[noreturn]] void reject(std::uint32_t crack, const std::string& what) {
  std::ostringstream out;
  out << "fluid: crack " << crack << ": " << what;
  throw std::invalid_argument(out.str());
}

}  // namespace

void CrackGrid::set(const CrackGeometry& crack, double pre_opening, double pre_opening_length, double virtual_opening) {
  const std::size_t n = crack.ids.size();
  const std::uint32_t id = crack.crack_id;
  if (!ids_.empty() && id != crack_id_) {
    reject(id, "this fluid solver runs on crack " + std::to_string(crack_id_) + "; one solver per crack");
  }
  if (n < 2) reject(id, "needs at least 2 crack particles to carry fluid, got " + std::to_string(n));
  if (crack.position.size() != n || crack.width.size() != n) {
    reject(id, "ids, positions and widths must have the same size (" + std::to_string(n) + ", " +
                   std::to_string(crack.position.size()) + ", " + std::to_string(crack.width.size()) + ")");
  }
  std::size_t appended = n;
  try {
    appended = check_crack_update(id, ids_, crack.ids);  // the first crack: every id is new
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("fluid: ") + e.what());
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(crack.width[i] >= 0) || !std::isfinite(crack.width[i])) {
      std::ostringstream out;
      out << "crack particle " << i << " (id " << crack.ids[i] << ") has width " << crack.width[i]
          << " m; widths must be finite and >= 0";
      reject(id, out.str());
    }
  }
  std::vector<double> arc = arc_length(crack.position);
  double min_spacing = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < n; ++i) {
    const double h = arc[i] - arc[i - 1];
    if (!(h > 0) || !std::isfinite(h)) {
      std::ostringstream out;
      out << "crack particles " << i - 1 << " and " << i << " (ids " << crack.ids[i - 1] << ", " << crack.ids[i]
          << ") are " << h << " m apart; the fluid grid needs distinct, finite positions";
      reject(id, out.str());
    }
    min_spacing = std::min(min_spacing, h);
  }
  // Each node's extra width (the virtual opening, and the pre-opening for a
  // node within pre_opening_length of the mouth) is fixed when the node first
  // appears: the crack plane stretches as it opens, and a test of the arc
  // length at every exchange took the pre-opening from a node that the
  // stretching had carried 4e-9 m past pre_opening_length (the tip node of
  // a pre-opened notch), halving the room of the fluid in its element in one
  // step: a 10 GPa pressure and a burst of the solid's kinetic energy
  // (docs/verification.md, "Layered medium").
  const std::size_t kept = n - appended;
  extra_.resize(kept);
  for (std::size_t i = kept; i < n; ++i)
    extra_.push_back(virtual_opening + (i == 0 || arc[i] <= pre_opening_length ? pre_opening : 0.0));
  appended_ = appended;
  crack_id_ = id;
  ids_ = crack.ids;
  position_ = crack.position;
  arc_ = std::move(arc);
  crack_width_ = crack.width;
  width_.resize(n);
  for (std::size_t i = 0; i < n; ++i) width_[i] = crack.width[i] + extra_[i];
  min_spacing_ = min_spacing;
}

void CrackGrid::move(const std::vector<Vec2>& position, const std::vector<double>& crack_width) {
  const std::size_t n = ids_.size();
  if (position.size() != n || crack_width.size() != n) {
    reject(crack_id_, "move: positions and widths must have one entry per node (" + std::to_string(n) + ")");
  }
  std::vector<double> arc = arc_length(position);
  double min_spacing = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < n; ++i) {
    const double h = arc[i] - arc[i - 1];
    if (!(h > 0) || !std::isfinite(h))
      reject(crack_id_, "move: nodes " + std::to_string(i - 1) + " and " + std::to_string(i) + " would coincide");
    min_spacing = std::min(min_spacing, h);
  }
  for (std::size_t i = 0; i < n; ++i) width_[i] = crack_width[i] + extra_[i];
  crack_width_ = crack_width;
  position_ = position;
  arc_ = std::move(arc);
  min_spacing_ = min_spacing;
}

double CrackGrid::width_integral(double a, double b) const { return integrate(arc_, width_, a, b); }

double CrackGrid::interpolate(double s, std::span<const double> values) const {
  return mpm::interpolate(arc_, values, s);
}

Vec2 CrackGrid::point_at(double s) const {
  const HatPoint h = hat_at(arc_, s);
  return h.n0 * position_[h.node] + h.n1 * position_[h.node + 1];
}

}  // namespace hfmpm::fluid::mpm
