// Growth of cracks not aligned with the grid (issue 18): J, K and the path
// stay right after every growth step. An interior crack at 45 degrees,
// pressurised in an in-situ stress taken as the reference state, grown from
// both tips.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "oblique_growth.hpp"

namespace hfmpm::solid::mpm {
namespace {

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
  // Each tip as each of its growth steps cut it (a step may lengthen the tip
  // segment rather than add a particle).
  std::vector<Vec2> start_part, end_part;
  for (auto g = log.begin(); g != std::next(tenth); ++g)
    (g->tip.at_end ? end_part : start_part).push_back(g->tip.at_end ? g->plane.back() : g->plane.front());
  const double grown = kSteps * c.fracture.growth_cells * h;
  const double start_off = off_line(start_part, centre, dir), end_off = off_line(end_part, centre, dir);
  std::printf(
      "grown by %zu (start) and %zu (end) steps; largest distance from the crack line %.3e m (start), "
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
  int start_grown = 0, end_grown = 0;         // growth steps of each tip
  double start_heading = 0, end_heading = 0;  // deg
  int count_gap = 0;                          // largest difference of the tips' growth counts
  double step_gap = 0;  // m, the largest distance from point symmetry of the tips of the k-th growth steps
  double start_crossing = 0, end_crossing = 0;  // m, x where the start (end) tip's path crosses y = -1.5 (+1.5) m
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
  // The dynamic term (HFMPM_ANISOTROPIC_STATIC=n): the crack of each of the
  // first n checks that grew a tip, re-solved from rest under that check's
  // pressure (held, damped over 12 transits).
  // HFMPM_RESOLVE_DOMAIN=i,o evaluates the re-solves over a J domain of i-o
  // cells instead of the test's 3-7 (path independence).
  const int statics = std::getenv("HFMPM_ANISOTROPIC_STATIC") ? std::atoi(std::getenv("HFMPM_ANISOTROPIC_STATIC")) : 0;
  for (const auto& g : log) {
    if ((g.tip.at_end ? g.end_grown : g.start_grown) > statics) continue;
    SolidConfig rest = c;
    rest.fracture.propagate = false;
    rest.cracks[0].points = g.before;
    if (std::getenv("HFMPM_RESOLVE_DOMAIN")) {
      rest.fracture.inner_cells = std::atof(std::getenv("HFMPM_RESOLVE_DOMAIN"));
      rest.fracture.outer_cells = std::atof(std::strchr(std::getenv("HFMPM_RESOLVE_DOMAIN"), ',') + 1);
    }
    Solver again(rest);
    again.cracks()[0].pressure().assign(g.before.size(), pressure(g.time));
    settle(again, 2 * b, 12);
    for (const auto& tip : again.tips()) {
      if (tip.at_end != g.tip.at_end) continue;
      std::printf(
          "re-solve from rest, %s tip's check %d (p %.4e Pa, J domain %g-%g cells): J %.4e J/m^2 (faces %.4e; "
          "growth run %.4e), J/((K_I^2+K_II^2)/E') %.4f (growth run %.4f), K_I %.4e (growth run %.4e), K_II/K_I "
          "%+.4f (%+.4f)\n",
          tip.at_end ? "end" : "start", tip.at_end ? g.end_grown : g.start_grown, pressure(g.time),
          rest.fracture.inner_cells, rest.fracture.outer_cells, tip.j, tip.j_faces, g.tip.j, j_over_k(tip),
          j_over_k(g.tip), tip.k1, g.tip.k1, tip.k2 / tip.k1, g.tip.k2 / g.tip.k1);
    }
  }
  // HFMPM_PATH_OUT=file writes the path for tools/curved_path.py: every
  // growth decision (the tip, its count, the time and face pressure of the
  // check, the new tip particle, the K's and kink the check measured), then
  // the final crack's particles.
  if (const char* path = std::getenv("HFMPM_PATH_OUT")) {
    std::FILE* f = std::fopen(path, "w");
    if (f == nullptr) ADD_FAILURE() << "cannot write HFMPM_PATH_OUT=" << path;
    if (f != nullptr) {
      std::fprintf(f, "record,tip,step,time_s,pressure_pa,x_m,y_m,k1_pa_sqrt_m,k2_pa_sqrt_m,kink_deg,h_m\n");
      for (const auto& g : log) {
        const Vec2& x = g.tip.at_end ? g.plane.back() : g.plane.front();
        std::fprintf(f, "growth,%s,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", g.tip.at_end ? "end" : "start",
                     g.tip.at_end ? g.end_grown : g.start_grown, g.time, pressure(g.time), x.x(), x.y(), g.tip.k1,
                     g.tip.k2, g.tip.kink * 180 / kPi, h);
      }
      const auto& plane = solid.cracks()[0].plane();
      for (std::size_t i = 0; i < plane.size(); ++i)
        std::fprintf(f, "plane,,%zu,,,%.9g,%.9g,,,,%.9g\n", i, plane[i].x(), plane[i].y(), h);
      std::fclose(f);
    }
  }
  Turned out;
  out.plane = solid.cracks()[0].plane();
  out.start_grown = log.empty() ? 0 : log.back().start_grown;
  out.end_grown = log.empty() ? 0 : log.back().end_grown;
  out.start_heading = heading(out.plane, false, 2 * h);
  out.end_heading = heading(out.plane, true, 2 * h);
  const Vec2 centre(h / 2, 0);
  std::vector<Vec2> start_new, end_new;  // each tip's new particle after each of its steps
  for (const auto& g : log) {
    out.count_gap = std::max(out.count_gap, std::abs(g.start_grown - g.end_grown));
    (g.tip.at_end ? end_new : start_new).push_back(g.tip.at_end ? g.plane.back() : g.plane.front());
  }
  for (std::size_t k = 0; k < std::min(start_new.size(), end_new.size()); ++k)
    out.step_gap = std::max(out.step_gap, (end_new[k] - centre + (start_new[k] - centre)).norm());
  out.start_crossing = x_at_height(out.plane, false, -1.5);
  out.end_crossing = x_at_height(out.plane, true, 1.5);
  std::printf(
      "h = a/%.0f: start tip grew %d steps to (%+.4f, %+.4f), heading %.2f deg, crosses y = -1.5 m at "
      "x = %+.4f m; end tip %d steps to (%+.4f, %+.4f), heading %.2f deg, crosses y = 1.5 m at x = %+.4f m\n",
      kA / h, out.start_grown, out.plane.front().x(), out.plane.front().y(), out.start_heading, out.start_crossing,
      out.end_grown, out.plane.back().x(), out.plane.back().y(), out.end_heading, out.end_crossing);
  std::printf(
      "point symmetry about the centre (%.3f, 0): tips at the end %.4f m from symmetric, the k-th new particles "
      "of the two tips at most %.4f m, crossings %.4f m; growth counts differed by at most %d\n",
      centre.x(), (out.plane.back() - centre + (out.plane.front() - centre)).norm(), out.step_gap,
      std::abs(out.end_crossing - centre.x() + (out.start_crossing - centre.x())), out.count_gap);
  return out;
}

// Stress ratio 3:1 (sigma_xx = -2 MPa, sigma_yy = -6 MPa): the crack turns
// perpendicular to the least compression (sigma_xx), i.e. towards the y axis:
// the end tip's heading to +90 deg, the start tip's to -90 deg. The crack
// first grows when the pressure has just passed the 4 MPa normal stress on
// it (K_II about -5 K_I), so it kinks by about 67 deg to a heading of about
// 112 deg, overshooting the final direction, and turns back over the next
// growth steps. Asserted after 1.2 a of growth (24 quarter-cell steps at
// a/5): both headings (the last 2 cells) within 5 deg of +-90 (issue 18);
// point symmetry about the centre (h / 2, 0): the tips' new particles and the
// points where the paths cross y = +-1.5 m symmetric within one growth step
// (a quarter cell).
// Right after the first kink J's domain form is half (K_I^2 + K_II^2)/E', also
// in a re-solve from rest (it gives the parent crack's J vector on the kink's
// direction; tests/solid/kinked_j_test.cpp), by different amounts at the two
// tips. While J drove growth there, the start tip grew its second and third
// steps before the end tip's second (counts 3 : 1) and ended one step ahead
// (25 : 24). Growth there is now driven by (K_I^2 + K_II^2)/E' (the crack
// bends by more than 30 deg in the domain): the tips grow at the same checks
// (24 : 24). Asserted: the tips of the k-th growth steps point-symmetric
// within a step, and the counts within one step (issue 18).
// HFMPM_OBLIQUE_CELLS=n runs at a/n.
TEST(ObliqueGrowth, AnisotropicStressTurnsPerpendicularToLeastCompression) {
  const int cells = std::getenv("HFMPM_OBLIQUE_CELLS") ? std::atoi(std::getenv("HFMPM_OBLIQUE_CELLS")) : 5;
  const double h = kA / cells;
  const Turned t = turn_in_anisotropic_stress(h, 1.2 * kA);
  EXPECT_NEAR(t.end_heading, 90, 5);
  EXPECT_NEAR(t.start_heading, -90, 5);
  const Vec2 centre(h / 2, 0);
  const double step = 0.25 * h;
  EXPECT_LE(t.count_gap, 1) << "the tips of a point-symmetric crack grew apart";
  EXPECT_LT(t.step_gap, step);
  EXPECT_LT(std::abs(t.end_crossing - centre.x() + (t.start_crossing - centre.x())), step);
}

// The inclined centre crack (45 degrees) under remote tension sigma_yy grows
// on past its first kink. Maximum hoop stress with the handbook K_I = K_II
// kinks it by -53.13 deg (heading -8.13 deg from the x axis at the end tip;
// InclinedCrack.MixedModeAndKinkAngleThenNoSecondKink checks the angle before growth); the
// kinked crack then carries a small K_II that turns it towards the plane
// normal to the load (heading 0 at the end tip, 180 at the start tip), the
// path's asymptote. Plate +-5a (K about 4% above the infinite plate's); the
// tension ramps over 20 transits to 1.3 times the handbook onset load and
// is then held; 24 growth steps (1.2 a) from each tip. Asserted:
// - the growth goes on past the kink, the first heading within 3 deg of
//   -8.13 (as for the kink before growth), the two tips point-symmetric
//   within one growth step;
// - J/((K_I^2+K_II^2)/E') within 5% from the 4th step on, within 10% at
//   the first three; at the end tip's first three checks the crack and the
//   tension of the check are re-solved from rest (damped over 12 transits),
//   and there J/((K_I^2+K_II^2)/E') must be within 7% of 1 and K_I within
//   3% of the growth run's: the excess of J at the two steps after the kink
//   is the motion the growth left (the dynamic term), the static J after
//   the kink a few percent low (docs/verification.md has the figures);
// - issue 18: from the 5th step on, every heading within 3 deg of the
//   maximum-hoop-stress path computed from the K measured at each step (the
//   first heading turned by the sum of the kinks measured since);
// - the principle of local symmetry: after a kink by maximum hoop stress
//   K_II at the new tip is near 0, |K_II|/K_I < 0.05 at every later step
//   (measured <= 0.015; a 5% K_II kinks by 5.7 deg);
// - the path turns towards the plane normal to the load without overshoot:
//   every heading within 3 deg of the band between the first heading and 0
//   and never more than 3 deg below an earlier one, and the last 4 headings
//   (steps 21-24) average within half the first heading of 0.
// Before the fix (the K's after a kink from the chord over 3 cells without
// the auxiliary field's traction on the faces before the kink, docs/
// verification.md) the headings went -8.1, -10.0, -11.7, -13.0, -13.9,
// -14.1, -13.5, -12.2, -9.1, ..., K_II/K_I after the kink was 0.88 and the
// maximum-hoop-stress path from those K's turned 51 deg at the second step.
}  // namespace
}  // namespace hfmpm::solid::mpm
