// Growth of cracks not aligned with the grid (issue 18): J, K and the path
// stay right after every growth step. An interior crack at 45 degrees,
// pressurised in an in-situ stress taken as the reference state, grown from
// both tips.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fracture_setup.hpp"

namespace hfmpm::solid::mpm {
namespace {

constexpr double kA = 1;  // m, half-length of the initial crack

// An interior crack of length 2 kA at `angle` to the x axis with its centre
// at `centre`, in the plate [-b, b]^2 under the in-situ stress (sxx, syy)
// held by the edges, as the reference state; crack particles every half
// cell. It grows by quarter cells when its tips reach K_Ic = k_ic (J domain
// 3-7 cells, settle_transits 2).
SolidConfig oblique_crack(double h, double b, double angle, const Vec2& centre, double sxx, double syy, double k_ic) {
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
double transit_time(double b) { return 2 * b / kRock.p_wave_speed(kRock.density); }

// One growth decision: the tip as evaluated by the check that grew it.
struct Growth {
  TipResult tip;
  int start_grown = 0, end_grown = 0;  // growth steps of each tip so far, this one included
  std::vector<Vec2> plane;             // the crack after the step
};

double j_over_k(const TipResult& tip) { return tip.j * tip.modulus / (tip.k1 * tip.k1 + tip.k2 * tip.k2); }

void print(const Growth& g) {
  const auto& t = g.tip;
  std::printf(
      "  %s tip step %d at (%+.4f, %+.4f): J %.4e J/m^2, J/((K_I^2+K_II^2)/E') %.4f, K_I %.4e, "
      "K_II/K_I %+.4f, kink %+.2f deg\n",
      t.at_end ? "end  " : "start", t.at_end ? g.end_grown : g.start_grown, t.position.x(), t.position.y(), t.j,
      j_over_k(t), t.k1, t.k2 / t.k1, t.kink * 180 / kPi);
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
    const std::size_t before = crack.size();
    const Vec2 first = crack.plane().front(), last = crack.plane().back();
    solid.step(dt);
    if (solid.cracks()[0].size() == before) continue;
    // Which tips grew: the one whose end particle is new.
    for (const auto& tip : solid.last_tips()) {
      const Vec2& now = tip.at_end ? solid.cracks()[0].plane().back() : solid.cracks()[0].plane().front();
      if ((now - (tip.at_end ? last : first)).norm() < 1e-3 * solid.grid().h) continue;
      ++grown[tip.at_end ? 1 : 0];
      log.push_back({tip, grown[0], grown[1], solid.cracks()[0].plane()});
      print(log.back());
    }
  }
  return log;
}

// Largest distance (m) of a crack's particles from the line through
// `origin` along `dir`, and the heading (rad) of the chord from `from` to `to`.
double off_line(const std::vector<Vec2>& points, const Vec2& origin, const Vec2& dir) {
  double worst = 0;
  for (const auto& p : points)
    worst = std::max(worst, std::abs((p - origin).x() * dir.y() - (p - origin).y() * dir.x()));
  return worst;
}

// The interior crack at 45 degrees under an isotropic in-situ stress of 4 MPa
// (as the reference state), its faces loaded by a pressure ramped from 0 (the
// crack starts shut, in contact) to 6.86 MPa over 20 P-wave transits of the
// plate and then held; K_Ic = 3.9 MPa m^0.5 (J_Ic 1,426 J/m^2, as in the
// issue's scene); growth by a quarter cell, settle_transits 2 (quasi-static
// growth, as for hydraulic fractures); J domain 3-7 cells (docs/solid.md:
// oblique cracks). The centre is half a cell off the grid node, so the crack
// line passes through a row of particle centres: each new segment passes
// within a fraction of a millimetre of a particle's centre, where a node
// field of that side holds only the corner of one particle.
// By symmetry (point symmetry of the body, grid, particles and loads about
// the centre; mirror symmetry of the loads about the crack line) both tips
// see the same K, K_II = 0, and the crack grows straight on.
// Asserted, as issue 18 asks:
// - J / ((K_I^2 + K_II^2) / E') in [0.95, 1.05] at every growth step (J and
//   K come from different integrals of the same field; their agreement is
//   the check that the field around the fresh tip is an elastic crack field);
// - |K_II| / K_I < 0.05 at every step (a 5% K_II kinks the tip by 5.7 deg);
// - the two tips' growth counts never differ by more than one step;
// - the grown parts lie within 2 deg of the crack line (the particles stay
//   within tan(2 deg) of their distance from the initial tip).
// - J after 10 steps (settled) within 5% of a static re-solve of the grown
//   crack from rest (measured 0.9994, 0.9984).
// Before the fix (face loads spread by linear weights onto node fields
// holding only the tail of a particle's weight) the particles at the tip of
// the second step moved at 20-40 m/s, growth stopped after 3 steps per tip,
// and at the end J was -2.8e4 / -4.7e4 J/m^2 against K_I = 7.86 / 6.51
// MPa m^0.5 (2.0 / 1.7 K_Ic) at the two tips, K_II/K_I +0.20 / +0.31.
TEST(ObliqueGrowth, IsotropicStressGrowsStraightAndSymmetric) {
  const int cells = std::getenv("HFMPM_OBLIQUE_CELLS") ? std::atoi(std::getenv("HFMPM_OBLIQUE_CELLS")) : 5;
  const double h = kA / cells, b = 5 * kA, s0 = -4e6, k_ic = 3.9e6;
  const double angle = kPi / 4;
  const Vec2 centre(h / 2, 0);
  SolidConfig c = oblique_crack(h, b, angle, centre, s0, s0, k_ic);
  Solver solid(c);
  const double transit = transit_time(b);
  const double p_end = -s0 + 1.3 * k_ic / std::sqrt(kPi * kA);
  auto pressure = [&](double t) { return p_end * std::min(1.0, t / (20 * transit)); };
  constexpr int kSteps = 10;
  // One step more: the checks that grow the tips the 11th time see the
  // settled field of the crack grown 10 times (the re-solve's reference).
  const auto log = grow(
      solid, pressure, [](int s, int e) { return s > kSteps && e > kSteps; }, 60 * transit);
  ASSERT_FALSE(log.empty()) << "the crack never grew";
  for (const auto& tip : solid.last_tips()) {
    std::printf(
        "at the end (t = %.1f transits): %s tip J %.4e J/m^2, K_I %.4e (%.2f K_Ic), K_II/K_I %+.4f, "
        "kinetic energy %.3e J/m\n",
        solid.time() / transit, tip.at_end ? "end" : "start", tip.j, tip.k1, tip.k1 / k_ic, tip.k2 / tip.k1,
        solid.kinetic_energy());
  }
  ASSERT_GT(log.back().start_grown, kSteps);
  ASSERT_GT(log.back().end_grown, kSteps);
  for (const auto& g : log) {
    EXPECT_NEAR(j_over_k(g.tip), 1, 0.05) << (g.tip.at_end ? "end" : "start") << " tip";
    EXPECT_LT(std::abs(g.tip.k2) / g.tip.k1, 0.05);
    EXPECT_LE(std::abs(g.start_grown - g.end_grown), 1) << "the tips of a point-symmetric crack grew apart";
  }
  // The crack after both tips grew kSteps times, and J at the checks that
  // grew them once more (that crack's settled field).
  const auto tenth = std::find_if(log.begin(), log.end(),
                                  [](const Growth& g) { return g.start_grown == kSteps && g.end_grown == kSteps; });
  ASSERT_NE(tenth, log.end());
  const auto& plane = tenth->plane;
  const Vec2 dir(std::cos(angle), std::sin(angle));
  const std::size_t initial = static_cast<std::size_t>(std::lround(4 * kA / h)) + 1;
  const std::size_t start_new = kSteps;
  const std::vector<Vec2> start_part(plane.begin(), plane.begin() + static_cast<std::ptrdiff_t>(start_new));
  const std::vector<Vec2> end_part(plane.begin() + static_cast<std::ptrdiff_t>(start_new + initial), plane.end());
  const double grown = kSteps * c.fracture.growth_cells * h;
  const double start_off = off_line(start_part, centre, dir), end_off = off_line(end_part, centre, dir);
  std::printf(
      "grown by %zu (start) and %zu (end) particles; largest distance from the crack line %.3e m (start), "
      "%.3e m (end), %.2f and %.2f deg over the grown length\n",
      start_part.size(), end_part.size(), start_off, end_off, std::atan(start_off / grown) * 180 / kPi,
      std::atan(end_off / grown) * 180 / kPi);
  EXPECT_LT(start_off, std::tan(2 * kPi / 180) * grown);
  EXPECT_LT(end_off, std::tan(2 * kPi / 180) * grown);

  // A static re-solve of the grown crack: the same body with that crack from
  // the start, the final pressure held, damped to rest over 12 transits. J of
  // the growth run (after its settling wait) must match it within 5%: what
  // the growth run carries over from its history (the faces' closed start,
  // the particles cut by the new segments) must not change the field.
  ASSERT_GE(tenth->tip.j, 0);
  SolidConfig rest = c;
  rest.fracture.propagate = false;
  rest.cracks[0].points = plane;
  Solver again(rest);
  again.cracks()[0].pressure().assign(plane.size(), p_end);
  settle(again, 2 * b, 12);
  for (const auto& tip : again.tips()) {
    const auto settled = std::find_if(log.begin(), log.end(), [&](const Growth& g) {
      return g.tip.at_end == tip.at_end && (tip.at_end ? g.end_grown : g.start_grown) == kSteps + 1;
    });
    ASSERT_NE(settled, log.end());
    std::printf(
        "re-solve from rest, %s tip: J %.4e J/m^2 (growth run %.4e, ratio %.4f), K_I %.4e (growth run %.4e), "
        "K_II/K_I %+.4f\n",
        tip.at_end ? "end" : "start", tip.j, settled->tip.j, settled->tip.j / tip.j, tip.k1, settled->tip.k1,
        tip.k2 / tip.k1);
    EXPECT_NEAR(settled->tip.j / tip.j, 1, 0.05);
  }
}

// Heading (deg, counter-clockwise from x) of the last `span` m of a polyline
// read from its end (at_end) or from its start.
double heading(const std::vector<Vec2>& plane, bool at_end, double span) {
  const Vec2 tip = at_end ? plane.back() : plane.front();
  Vec2 back = tip;
  for (std::size_t i = 1; i < plane.size() && (back - tip).norm() < span; ++i) {
    back = at_end ? plane[plane.size() - 1 - i] : plane[i];
  }
  return std::atan2(tip.y() - back.y(), tip.x() - back.x()) * 180 / kPi;
}

// x (m) where the polyline first crosses the height y, from the end (or the start).
double x_at_height(const std::vector<Vec2>& plane, bool from_end, double y) {
  const std::size_t n = plane.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Vec2& a = plane[from_end ? n - 1 - i : i];
    const Vec2& b = plane[from_end ? n - 2 - i : i + 1];
    if ((a.y() - y) * (b.y() - y) <= 0 && a.y() != b.y())
      return a.x() + (y - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
  }
  return std::nan("");
}

struct Turned {
  std::vector<Vec2> plane;
  std::size_t start_initial = 0, end_initial = 0;  // indices of the initial tips in plane
  double start_heading = 0, end_heading = 0;       // deg
};

// The 45-degree crack in sigma_xx = -2 MPa, sigma_yy = -6 MPa, pressurised
// until both tips have grown `length` m (quarter-cell steps, settled).
Turned turn_in_anisotropic_stress(double h, double length) {
  const double b = 5 * kA, k_ic = 3.9e6;
  SolidConfig c = oblique_crack(h, b, kPi / 4, Vec2(h / 2, 0), -2e6, -6e6, k_ic);
  Solver solid(c);
  const double transit = transit_time(b);
  const double p_end = 4e6 + 1.3 * k_ic / std::sqrt(kPi * kA);
  auto pressure = [&](double t) { return p_end * std::min(1.0, t / (20 * transit)); };
  const int steps = static_cast<int>(std::ceil(length / (c.fracture.growth_cells * h)));
  const auto log = grow(
      solid, pressure, [&](int s, int e) { return s >= steps && e >= steps; }, 80 * transit);
  Turned out;
  out.plane = solid.cracks()[0].plane();
  out.start_initial = static_cast<std::size_t>(log.empty() ? 0 : log.back().start_grown);
  out.end_initial = out.start_initial + static_cast<std::size_t>(std::lround(4 * kA / h));
  out.start_heading = heading(out.plane, false, 2 * h);
  out.end_heading = heading(out.plane, true, 2 * h);
  std::printf(
      "h = a/%.0f: start tip grew %zu steps to (%+.4f, %+.4f), heading %.2f deg, crosses y = -1.5 m at "
      "x = %+.4f m; end tip %zu steps to (%+.4f, %+.4f), heading %.2f deg, crosses y = 1.5 m at x = %+.4f m\n",
      kA / h, out.start_initial, out.plane.front().x(), out.plane.front().y(), out.start_heading,
      x_at_height(out.plane, false, -1.5), out.plane.size() - 1 - out.end_initial, out.plane.back().x(),
      out.plane.back().y(), out.end_heading, x_at_height(out.plane, true, 1.5));
  return out;
}

// Stress ratio 3:1 (sigma_xx = -2 MPa, sigma_yy = -6 MPa): the crack turns
// perpendicular to the least compression (sigma_xx), i.e. towards the y axis:
// the end tip's heading to +90 deg, the start tip's to -90 deg. The crack is
// shut when it first grows (the pressure is still below the 4 MPa normal
// stress on it), so it kinks by the pure mode II angle, 70.5 deg, to a
// heading of 115.5 deg, overshooting the final direction, and turns back over
// the next growth steps as the pressure opens it. Asserted after 1.2 a of
// growth (24 quarter-cell steps at a/5): both headings (the last 2 cells)
// within 5 deg of +-90 (issue 18), and the two tips point-symmetric within
// one growth step (a quarter cell; issue 18; measured: 1.5e-3 m, 0.008 h). HFMPM_OBLIQUE_CELLS=n runs at a/n.
TEST(ObliqueGrowth, AnisotropicStressTurnsPerpendicularToLeastCompression) {
  const int cells = std::getenv("HFMPM_OBLIQUE_CELLS") ? std::atoi(std::getenv("HFMPM_OBLIQUE_CELLS")) : 5;
  const double h = kA / cells;
  const Turned t = turn_in_anisotropic_stress(h, 1.2 * kA);
  EXPECT_NEAR(t.end_heading, 90, 5);
  EXPECT_NEAR(t.start_heading, -90, 5);
  // Point symmetry about the crack's centre (h / 2, 0).
  const Vec2 centre(h / 2, 0);
  EXPECT_LT((t.plane.back() - centre + (t.plane.front() - centre)).norm(), 0.25 * h);
}

// The inclined centre crack (45 degrees) under remote tension sigma_yy grows
// on past its first kink. Maximum hoop stress with the handbook K_I = K_II
// kinks it by -53.13 deg (heading -8.13 deg from the x axis at the end tip;
// InclinedCrack.MixedModeAndKinkAngleThenNoSecondKink checks the angle before growth); the
// kinked crack then carries a small K_II that turns it towards the plane
// normal to the load (heading 0 at the end tip, 180 at the start tip), the
// path's asymptote. Plate +-5a (K about 4% above the infinite plate's); the
// tension ramps over 20 transits to 1.3 times the handbook onset load and
// is then held. Asserted: at least 12 growth steps from each tip (the growth
// goes on past the kink), the first heading within 3 deg of -8.13 (as for the
// kink before growth), J/((K_I^2+K_II^2)/E') within 8% at every step (the
// tolerance of K on an oblique crack before growth: a kink inside the J
// domain is the same kind of geometry error; measured 0.966-1.056), the two
// tips point-symmetric within one growth step. NOT asserted
// (open): the path after the kink. Measured at a/5: the headings fall from
// -8.1 to -14.1 deg over the first 6 steps and come back to +0.5 at step 12;
// the maximum-hoop-stress path turns monotonically from -8.1 towards 0. The
// K's after a kink come from a domain (3-7 cells) that mostly sees the
// crack before the kink, measured in a frame (the chord over 3 cells) that
// the new branch turns.
TEST(ObliqueGrowth, InclinedCrackUnderTensionGrowsPastTheKink) {
  const double h = kA / 5, b = 5 * kA, k_ic = 1e6;
  SolidConfig c = oblique_crack(h, b, kPi / 4, Vec2(h / 2, 0), 0, 0, k_ic);
  const double sigma_c = k_ic / (std::sqrt(kPi * kA) / std::sqrt(2.0));  // |K| = sigma sqrt(pi a) / sqrt(2)
  const double transit = transit_time(b);
  const auto sigma = TimeFunction::table({0, 20 * transit}, {0, 1.3 * sigma_c});
  c.tractions = {{Edge::Top, sigma, TimeFunction::constant(0)}, {Edge::Bottom, sigma, TimeFunction::constant(0)}};
  Solver solid(c);
  const int kSteps = std::getenv("HFMPM_TENSION_STEPS") ? std::atoi(std::getenv("HFMPM_TENSION_STEPS")) : 12;
  const auto log = grow(
      solid, [](double) { return 0.0; }, [&](int s, int e) { return s >= kSteps && e >= kSteps; }, 80 * transit);
  ASSERT_FALSE(log.empty()) << "the crack never grew";
  EXPECT_GE(log.back().start_grown, kSteps);
  EXPECT_GE(log.back().end_grown, kSteps);
  const auto& plane = solid.cracks()[0].plane();
  const std::size_t initial = static_cast<std::size_t>(std::lround(4 * kA / h)) + 1;
  const std::size_t start_new = static_cast<std::size_t>(log.back().start_grown);
  // Headings of the grown segments, from each initial tip outwards (the
  // start tip's mapped by 180 deg onto the end tip's by symmetry).
  auto segment_heading = [&](std::size_t from, std::size_t to, bool flip) {
    const Vec2 d = plane[to] - plane[from];
    double a = std::atan2(d.y(), d.x()) * 180 / kPi;
    if (flip) a = a > 0 ? a - 180 : a + 180;
    return a;
  };
  const double first_exact = 45 - 53.13;
  for (const bool at_end : {false, true}) {
    std::vector<double> headings;
    if (at_end) {
      for (std::size_t k = start_new + initial - 1; k + 1 < plane.size(); ++k)
        headings.push_back(segment_heading(k, k + 1, false));
    } else {
      for (std::size_t k = start_new; k > 0; --k) headings.push_back(segment_heading(k, k - 1, true));
    }
    std::printf("%s tip headings (deg, mapped onto the end tip's):", at_end ? "end" : "start");
    for (const double a : headings) std::printf(" %.2f", a);
    std::printf("\n");
    ASSERT_GE(headings.size(), static_cast<std::size_t>(kSteps));
    EXPECT_NEAR(headings.front(), first_exact, 3);
  }
  for (const auto& g : log) EXPECT_NEAR(j_over_k(g.tip), 1, 0.08) << (g.tip.at_end ? "end" : "start") << " tip";
  const Vec2 centre(h / 2, 0);
  EXPECT_LT((plane.back() - centre + (plane.front() - centre)).norm(), c.fracture.growth_cells * h);
}

}  // namespace
}  // namespace hfmpm::solid::mpm
