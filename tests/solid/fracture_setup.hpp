// Set-ups shared by the fracture tests: handbook factors, damping, and an
// edge-cracked strip under remote tension.
#pragma once

#include <cmath>
#include <numbers>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {

inline constexpr double kPi = std::numbers::pi;
inline const Material kRock{"rock", 1e10, 0.25, 2500};

// Single edge crack in a strip under remote tension (Tada, Paris and Irwin,
// The Stress Analysis of Cracks Handbook, 3rd ed., 2.10; ~0.5% for all a/W):
//   F = sqrt(2 / (pi al) tan(pi al / 2)) (0.752 + 2.02 al + 0.37 (1 - sin(pi al / 2))^3) / cos(pi al / 2)
// K_I = F sigma sqrt(pi a). F(0.3) = 1.6551.
inline double tada_edge_factor(double al) {
  const double b = kPi * al / 2;
  return std::sqrt(std::tan(b) / b) * (0.752 + 2.02 * al + 0.37 * std::pow(1 - std::sin(b), 3)) / std::cos(b);
}

// Near-critical grid damping for the lowest mode of a body of size `length`.
inline double critical_alpha(double length) { return 2 * kPi * kRock.p_wave_speed(kRock.density) / (4 * length); }

// Steps until `transits` P-wave transits of `length` have passed.
inline void settle(Solver& solid, double length, double transits) {
  const double dt = solid.stable_dt();
  const double end = solid.time() + transits * length / kRock.p_wave_speed(kRock.density);
  while (solid.time() < end) solid.step(dt);
}

// The plate [-b, b]^2 of kRock (grid two cells wider on each side) with a
// straight interior crack of length 2a at `angle` to the x axis centred at
// `centre`, both ends tips, crack particles every half cell; critically
// damped for the plate's lowest mode. Loads and stresses are the caller's.
inline SolidConfig plate_with_centre_crack(double h, double b, double a, double angle, const Vec2& centre) {
  SolidConfig c;
  c.grid.origin = Vec2(-b - 2 * h, -b - 2 * h);
  c.grid.h = h;
  c.grid.nx = c.grid.ny = static_cast<int>(std::lround(2 * b / h)) + 4;
  c.materials = {kRock};
  Region r;
  r.lo = Vec2(-b, -b);
  r.hi = Vec2(b, b);
  c.regions = {r};
  CrackSpec crack;
  const int segments = static_cast<int>(std::lround(4 * a / h));
  const Vec2 dir(std::cos(angle), std::sin(angle));
  for (int k = 0; k <= segments; ++k) crack.points.push_back(centre + (-a + 2 * a * k / segments) * dir);
  crack.start_is_tip = true;
  crack.end_is_tip = true;
  c.cracks = {crack};
  c.damping.grid_alpha = critical_alpha(2 * b);
  return c;
}

// Strip [0, W] x [-H, H] with an edge crack from (0, 0) to (a, 0) along a grid
// line, pulled by sigma(t) on the top and bottom edges.
inline SolidConfig edge_crack(double w, double a, double half_height, int cells_across, TimeFunction sigma) {
  const double h = w / cells_across;
  SolidConfig c;
  c.grid.origin = Vec2(-2 * h, -half_height - 2 * h);
  c.grid.h = h;
  c.grid.nx = cells_across + 4;
  c.grid.ny = static_cast<int>(std::lround(2 * half_height / h)) + 4;
  c.materials = {kRock};
  Region r;
  r.lo = Vec2(0, -half_height);
  r.hi = Vec2(w, half_height);
  c.regions = {r};
  c.tractions = {{Edge::Top, sigma, TimeFunction::constant(0)}, {Edge::Bottom, sigma, TimeFunction::constant(0)}};
  CrackSpec crack;
  const int segments = static_cast<int>(std::lround(2 * a / h));  // every half cell
  for (int k = 0; k <= segments; ++k) crack.points.emplace_back(a * k / segments, 0.0);
  crack.start_is_tip = false;  // the mouth, on the left edge
  c.cracks = {crack};
  c.damping.grid_alpha = critical_alpha(2 * half_height);
  c.threads = 2;
  return c;
}

}  // namespace hfmpm::solid::mpm
