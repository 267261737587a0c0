// What the growth tests of oblique cracks share (oblique_growth_test.cpp:
// straight and turning growth of a 45-degree crack; kinked_growth_test.cpp:
// growth past a kink, and its checkpoint): the crack, its plate and loads,
// and a stepping loop that logs every growth decision.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "fracture_setup.hpp"

namespace hfmpm::solid::mpm {

inline constexpr double kA = 1;  // m, half-length of the initial crack

// An interior crack of length 2 kA at `angle` to the x axis with its centre
// at `centre`, in the plate [-b, b]^2 under the in-situ stress (sxx, syy)
// held by the edges, as the reference state; crack particles every half
// cell. It grows by quarter cells when its tips reach K_Ic = k_ic (J domain
// 3-7 cells, settle_transits 2).
inline SolidConfig oblique_crack(double h, double b, double angle, const Vec2& centre, double sxx, double syy,
                                 double k_ic) {
  SolidConfig c = plate_with_centre_crack(h, b, kA, angle, centre);
  c.regions[0].initial_stress = Voigt(sxx, syy, 0, kRock.poisson_ratio * (sxx + syy));
  c.in_situ_reference = true;
  auto held = [](Edge e, double s) { return Traction{e, TimeFunction::constant(s), TimeFunction::constant(0)}; };
  c.tractions = {held(Edge::Left, sxx), held(Edge::Right, sxx), held(Edge::Bottom, syy), held(Edge::Top, syy)};
  c.threads = 1;
  c.fracture.inner_cells = 3;
  c.fracture.outer_cells = 7;
  c.fracture.propagate = true;
  c.fracture.growth_cells = 0.25;
  c.fracture.settle_transits = 2;
  c.materials[0].toughness = k_ic * k_ic / kRock.plane_strain_modulus();
  return c;
}

// s, one P-wave transit of the plate [-b, b]^2.
inline double transit_time(double b) { return 2 * b / kRock.p_wave_speed(kRock.density); }

// One growth decision: the tip as evaluated by the check that grew it.
struct Growth {
  TipResult tip;
  int start_grown = 0, end_grown = 0;  // growth steps of each tip so far, this one included
  std::vector<Vec2> plane;             // the crack after the step
  std::vector<Vec2> before;            // the crack the check evaluated (before the step)
  double time = 0;                     // s, of the check
};

inline double j_over_k(const TipResult& tip) { return tip.j * tip.modulus / (tip.k1 * tip.k1 + tip.k2 * tip.k2); }

inline void print(const Growth& g) {
  const auto& t = g.tip;
  std::printf(
      "  %s tip step %d at (%+.4f, %+.4f), t = %.5f s: J %.4e J/m^2 (faces %+.4e), J/((K_I^2+K_II^2)/E') %.4f, "
      "K_I %.4e, K_II/K_I %+.4f, kink %+.2f deg\n",
      t.at_end ? "end  " : "start", t.at_end ? g.end_grown : g.start_grown, t.position.x(), t.position.y(), g.time, t.j,
      t.j_faces, j_over_k(t), t.k1, t.k2 / t.k1, t.kink * 180 / kPi);
}

// Steps `solid` with the face pressure pressure(t) until `done` says so or
// `end` s, logging every growth step.
template <class Pressure, class Done>
std::vector<Growth> grow(Solver& solid, Pressure pressure, Done done, double end) {
  std::vector<Growth> log;
  int grown[2] = {0, 0};
  const double dt = solid.stable_dt();
  while (solid.time() < end && !done(grown[0], grown[1])) {
    auto& crack = solid.cracks()[0];
    crack.pressure().assign(crack.size(), pressure(solid.time()));
    const Vec2 first = crack.plane().front(), last = crack.plane().back();
    const std::vector<Vec2> shape = crack.plane();
    solid.step(dt);
    // Which tips grew: the one whose end particle is new, or moved a growth
    // step (a short tip segment lengthened; docs/solid.md, "Crack particles
    // at least half a cell apart").
    for (const auto& tip : solid.last_tips()) {
      const Vec2& now = tip.at_end ? solid.cracks()[0].plane().back() : solid.cracks()[0].plane().front();
      if ((now - (tip.at_end ? last : first)).norm() < 0.02 * solid.grid().h) continue;  // steps are >= h / 16
      ++grown[tip.at_end ? 1 : 0];
      log.push_back({tip, grown[0], grown[1], solid.cracks()[0].plane(), shape, solid.time()});
      print(log.back());
    }
  }
  return log;
}

// Largest distance (m) of a crack's particles from the line through
// `origin` along `dir`, and the heading (rad) of the chord from `from` to `to`.
inline double off_line(const std::vector<Vec2>& points, const Vec2& origin, const Vec2& dir) {
  double worst = 0;
  for (const auto& p : points)
    worst = std::max(worst, std::abs((p - origin).x() * dir.y() - (p - origin).y() * dir.x()));
  return worst;
}

// Heading (deg, counter-clockwise from x) of the last `span` m of a polyline
// read from its end (at_end) or from its start.
inline double heading(const std::vector<Vec2>& plane, bool at_end, double span) {
  const Vec2 tip = at_end ? plane.back() : plane.front();
  Vec2 back = tip;
  for (std::size_t i = 1; i < plane.size() && (back - tip).norm() < span; ++i) {
    back = at_end ? plane[plane.size() - 1 - i] : plane[i];
  }
  return std::atan2(tip.y() - back.y(), tip.x() - back.x()) * 180 / kPi;
}

}  // namespace hfmpm::solid::mpm
