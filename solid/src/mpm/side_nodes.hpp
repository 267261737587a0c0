// The nodes a crack surface point reads and loads, for the crack parts of the
// step (solver_cracks.cpp) and the crack surfaces (crack_surfaces.cpp).
// Internal to the solid library.
#pragma once

#include <cmath>
#include <cstddef>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm::detail {

// The 4 nodes of the cell holding x and their linear weights.
struct CellWeights {
  int i = 0, j = 0;
  double w[2][2] = {{0, 0}, {0, 0}};  // [a][b] for node (i + a, j + b)
};

inline CellWeights cell_weights(const Grid& g, const Vec2& x) {
  CellWeights c;
  const Vec2 rel = (x - g.origin) / g.h;
  c.i = static_cast<int>(std::floor(rel.x()));
  c.j = static_cast<int>(std::floor(rel.y()));
  const double fx = rel.x() - c.i, fy = rel.y() - c.j;
  c.w[0][0] = (1 - fx) * (1 - fy);
  c.w[1][0] = fx * (1 - fy);
  c.w[0][1] = (1 - fx) * fy;
  c.w[1][1] = fx * fy;
  return c;
}

// For side `side` (+1 above, -1 below) of crack particle k: the nodes around
// the surface point, the field that side uses at each, and linear weights
// over the nodes where that field has mass (renormalized).
template <class Visit>
inline void for_side_nodes(const Solver& solver, const Grid& g, const NodalFields* fields[2], const Crack& crack,
                           std::size_t k, int side, double min_mass, Visit&& visit) {
  const Vec2 n = crack.normal(k);
  const Vec2 test = crack.plane()[k] + side * 1e-6 * g.h * n;  // a point just off the plane on that side
  // The cell of the surface point nudged to its own side: a closed surface on
  // a grid line would otherwise take the cell above for both sides.
  const auto cell = cell_weights(g, crack.surface(side)[k] + side * 1e-6 * g.h * n);
  int node[4], field[4];
  double weight[4], total = 0;
  int count = 0;
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      if (!g.inside(cell.i + a, cell.j + b)) continue;
      const int nd = g.node(cell.i + a, cell.j + b);
      const int f = solver.field_of(test, g.position(nd));
      const double w = cell.w[a][b];
      if (w <= 0 || fields[f]->mass[static_cast<std::size_t>(nd)] <= min_mass) continue;
      node[count] = nd;
      field[count] = f;
      weight[count] = w;
      total += w;
      ++count;
    }
  }
  for (int c = 0; c < count; ++c) visit(node[c], field[c], weight[c] / total);
}

}  // namespace hfmpm::solid::mpm::detail
