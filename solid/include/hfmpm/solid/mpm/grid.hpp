// Background grid: uniform square cells of size h over [origin, origin + (nx, ny) h].
// Nodal fields are dense arrays; only the nodes particles touched in a step
// ("active" nodes) are visited and reset.
#pragma once

#include <cstdint>
#include <vector>

#include "hfmpm/exchange.hpp"

namespace hfmpm::solid::mpm {

struct Grid {
  Vec2 origin = Vec2::Zero();  // m
  double h = 1;                // m, cell size
  int nx = 1, ny = 1;          // cells per direction

  int nodes_x() const { return nx + 1; }
  int nodes_y() const { return ny + 1; }
  std::size_t node_count() const { return static_cast<std::size_t>(nodes_x()) * static_cast<std::size_t>(nodes_y()); }
  int node(int i, int j) const { return i + j * nodes_x(); }
  Vec2 position(int n) const { return origin + h * Vec2(n % nodes_x(), n / nodes_x()); }
  bool inside(int i, int j) const { return i >= 0 && j >= 0 && i <= nx && j <= ny; }
};

// Per-node fields of one velocity field. Index by node number.
struct NodalFields {
  std::vector<double> mass;         // kg/m
  std::vector<Vec2> momentum;       // kg/(m s)
  std::vector<Vec2> force;          // N/m
  std::vector<Vec2> displaced;      // kg/m * m: sum of S m u (cracks only; / mass = nodal displacement)
  std::vector<std::uint8_t> fixed;  // bit 0: v_x = 0, bit 1: v_y = 0 (constraints; set once)

  void resize(std::size_t n) {
    mass.assign(n, 0.0);
    momentum.assign(n, Vec2::Zero());
    force.assign(n, Vec2::Zero());
    displaced.assign(n, Vec2::Zero());
    fixed.assign(n, 0);
  }
};

}  // namespace hfmpm::solid::mpm
