// Internal to the implicit interface step (implicit.cpp, implicit_substep.cpp):
// the failures a (sub)step throws, the colouring of the difference Jacobian,
// and two small helpers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "hfmpm/fluid/mpm/shape.hpp"

namespace hfmpm::fluid::mpm::implicit_detail {

struct Squeezed {
  std::ptrdiff_t particle;
};

// A (sub)step whose interface solve failed: not committed; step_implicit
// retries the step in more fluid substeps.
struct StepFailed {
  std::string message;
  bool misfit = false;  // Newton's method ended above the bound (not: a particle turned inside out)
};

// Elements perturbed together when the Jacobian is built by differences: a
// pressure reaches the residuals of elements at most jacobian_reach(band)
// away (a particle spans up to ~2 elements; its ends move with the nodes
// around it; the faces open under the pressure projected to the nodes it
// touches, and the solid's response carries an opening to nodes up to its
// compliance band away). Measured on the 30-degree inclined well (one
// element perturbed at a time, entries above 1e-3 of the column's largest):
// band 4 reaches 4-6 elements, band 5 5-6, band 6 (grown quarter-cell
// segments across the grid) 6-8. Elements closer than that perturbed
// together alias their columns: with the reach fixed at 5 the band-6
// Jacobian was wrong, Newton's method stalled at 30 iterations a step and a
// step outlasted the step timeout.
constexpr std::size_t kReach = 5;  // without a compliance band (the explicit schemes)
inline std::size_t jacobian_reach(std::size_t band) { return std::max(kReach, band + 2); }

// The element pieces of a domain [a, b]: fn(element, fraction of the length).
template <class Fn>
void for_pieces(const std::vector<double>& arc, double a, double b, Fn&& fn) {
  const std::size_t elements = arc.size() - 1;
  const double l = b - a;
  if (!(l > 0)) return;
  const std::size_t first = hat_at(arc, a).node, last = hat_at(arc, b).node;
  for (std::size_t e = first; e <= last && e < elements; ++e) {
    const double lo = e == 0 ? a : std::max(a, arc[e]);
    const double hi = e + 1 == elements ? b : std::min(b, arc[e + 1]);
    if (hi > lo) fn(e, (hi - lo) / l);
  }
}

inline double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace hfmpm::fluid::mpm::implicit_detail
