// Sneddon's pressurised centre crack (and K_I = F p sqrt(pi a) from J) (length 2a, faces loaded by p) in a box
// of half-width b = 5a, modelled as a half body with a symmetry plane through
// the crack centre (x = 0), explicit CRAMP crack from x = 0 to the tip x = a.
// Reference (Sneddon 1946; Tada, Paris and Irwin, The Stress Analysis of
// Cracks Handbook): w(x) = 4 p / E' sqrt(a^2 - x^2), E' = E / (1 - nu^2),
// scaled by the finite-width factor of a centre crack in a strip of width 2b
// with free edges, F = (1 - 0.025 al^2 + 0.06 al^4) sqrt(sec(pi al / 2)),
// al = a / b (Tada's fit, 0.1%): F = 1.0245 at b = 5a.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {
namespace {

constexpr double kA = 1.0, kB = 5.0, kP = 1e6;
const Material kRock{"rock", 1e10, 0.25, 2500};

double finite_width_factor(double a, double b) {
  const double al = a / b;
  return (1 - 0.025 * al * al + 0.06 * std::pow(al, 4)) * std::sqrt(1 / std::cos(std::numbers::pi * al / 2));
}

struct SneddonResult {
  double l2_error = 0;       // relative L2 error of the opening profile
  double mouth_error = 0;    // relative error of the opening at x = 0
  double k_error = 0;        // relative error of K_I (interaction integral)
  double k2_ratio = 0;       // |K_II| / K_I
  double j_faces_share = 0;  // face-load part of J / J
  std::size_t particles = 0;
  std::uint64_t steps = 0;
};

// sigma0: an in-situ biaxial stress (Pa, compression negative) held by
// tractions on the outer edges; the faces then carry p - sigma0, so that the
// net load, and the reference opening, stay those of p.
// near_box > 0: one particle per cell (per direction) in the body, two within
// x < near_box a, |y| < near_box a / 2 (a later region, so it wins there).
// rock: the material (default kRock). widths: if given, the face openings
// at 8, 10 and 12 transits (for the drift test).
SneddonResult run_sneddon(int cells_per_a, int threads, double sigma0 = 0, bool in_situ_reference = false,
                          double near_box = 0, const Material& rock = kRock,
                          std::vector<std::vector<double>>* widths = nullptr) {
  const double h = kA / cells_per_a;
  SolidConfig c;
  c.grid.origin = Vec2(0, -kB - 2 * h);
  c.grid.h = h;
  c.grid.nx = static_cast<int>(std::lround(kB / h)) + 2;
  c.grid.ny = static_cast<int>(std::lround(2 * kB / h)) + 4;
  c.materials = {rock};
  Region r;
  r.lo = Vec2(0, -kB);
  r.hi = Vec2(kB, kB);
  r.initial_stress = Voigt(sigma0, sigma0, 0, 2 * 0.25 * sigma0);  // zz = nu (xx + yy), plane strain
  c.regions = {r};
  if (near_box > 0) {
    Region near = r;
    near.lo = Vec2(0, -near_box * kA / 2);
    near.hi = Vec2(near_box * kA, near_box * kA / 2);
    near.particles_per_cell = 2;
    c.regions[0].particles_per_cell = 1;
    c.regions.push_back(near);
  }
  c.in_situ_reference = in_situ_reference;
  if (sigma0 != 0) {
    for (Edge e : {Edge::Right, Edge::Top, Edge::Bottom}) {
      Traction t;
      t.edge = e;
      t.normal = TimeFunction::constant(sigma0);
      c.tractions.push_back(t);
    }
  }
  c.constraints = {{Constraint::Kind::PlaneX, 0.0}};
  CrackSpec crack;
  const int segments = 2 * cells_per_a;  // crack particles every half cell
  for (int k = 0; k <= segments; ++k) crack.points.emplace_back(kA * k / segments, 0.0);
  crack.start_is_tip = false;  // the crack centre, on the symmetry plane
  crack.end_is_tip = true;
  c.cracks = {crack};
  // Damping near critical for the lowest modes of the box.
  const double c_p = rock.p_wave_speed(rock.density);
  c.damping.grid_alpha = 2 * std::numbers::pi * c_p / (4 * kB);
  c.threads = threads;
  Solver solid(c);
  solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), kP - sigma0));
  const double dt = solid.stable_dt();
  const double transit = 2 * kB / c_p;
  for (int transits : {8, 10, 12}) {
    while (solid.time() < transits * transit) solid.step(dt);
    if (widths) {
      widths->emplace_back();
      for (std::size_t k = 0; k < solid.cracks()[0].size(); ++k) widths->back().push_back(solid.cracks()[0].width(k));
    }
  }

  const double e_prime = rock.plane_strain_modulus();
  const double factor = finite_width_factor(kA, kB);
  const auto& cr = solid.cracks()[0];
  double num = 0, den = 0;
  for (std::size_t k = 0; k < cr.size(); ++k) {
    const double x = kA * static_cast<double>(k) / segments;
    const double exact = factor * 4 * kP / e_prime * std::sqrt(std::max(0.0, kA * kA - x * x));
    num += std::pow(cr.width(k) - exact, 2);
    den += exact * exact;
  }
  SneddonResult result;
  result.l2_error = std::sqrt(num / den);
  const double mouth = factor * 4 * kP * kA / e_prime;
  result.mouth_error = (cr.width(0) - mouth) / mouth;
  const auto tips = solid.tips();
  const double k_exact = factor * kP * std::sqrt(std::numbers::pi * kA);
  result.k_error = (tips.at(0).k1 - k_exact) / k_exact;
  result.k2_ratio = std::abs(tips.at(0).k2) / tips.at(0).k1;
  result.j_faces_share = tips.at(0).j_faces / tips.at(0).j;
  result.particles = solid.particles().size();
  result.steps = solid.steps();
  return result;
}

// CI size: h = a/5 and a/10. The error falls at first order (the square-root
// tip is resolved by a few cells): measured 9.7%, 4.8% and (HFMPM_SNEDDON_CELLS=20)
// 2.7%, so a/10 is held to 6%. The mouth opening is held to 3%: measured -1.4%,
// +0.9%, +2.8%; it tends to the opening of the finite box, whose free top and
// bottom (at +-5a) the strip factor F does not include.
TEST(Sneddon, OpeningProfileMatchesAndConverges) {
  const int finest = std::getenv("HFMPM_SNEDDON_CELLS") ? std::atoi(std::getenv("HFMPM_SNEDDON_CELLS")) : 10;
  double previous = 1;
  for (int cells = 5; cells <= finest; cells *= 2) {
    const auto r = run_sneddon(cells, 2);
    std::printf(
        "sneddon h = a/%d: %zu particles, %llu steps, opening L2 error %.4f, mouth error %+.4f, "
        "K_I error %+.4f (|K_II|/K_I %.1e, face work %.2f of J)\n",
        cells, r.particles, static_cast<unsigned long long>(r.steps), r.l2_error, r.mouth_error, r.k_error, r.k2_ratio,
        r.j_faces_share);
    EXPECT_LT(r.l2_error, 0.8 * previous) << "no convergence at h = a/" << cells;
    if (cells > 5) {
      // Observed order log2(e(2h) / e(h)): first order (the square-root tip
      // spans a few cells; measured 1.01 for a/5 -> a/10, 0.83 for a/10 ->
      // a/20); held above 0.75.
      const double order = std::log2(previous / r.l2_error);
      std::printf("sneddon: observed order %.2f at h = a/%d\n", order, cells);
      EXPECT_GT(order, 0.75);
    }
    if (cells >= 10) {
      EXPECT_LT(r.l2_error, 0.06);
      EXPECT_LT(std::abs(r.mouth_error), 0.03);
      // K_I from the interaction integral (face-pressure work included)
      // against F p sqrt(pi a): measured +1.8% (a/5) and +2.4% (a/10); the
      // issue's 3%.
      EXPECT_LT(std::abs(r.k_error), 0.03);
    }
    previous = r.l2_error;
  }
}

// The same crack in an in-situ stress ten times the net pressure (sigma0 =
// -10 p held by the outer edges' tractions, faces at 11 p), with the in-situ
// stress as the reference state (SolidConfig::in_situ_reference): the
// particles carry only the change of stress, the edges -sigma0 n on top of
// their tractions and the faces p n + sigma0 n. By superposition the crack
// must open as the plain case: the same profile to 0.5% (L2) and the same
// mouth opening and K_I. Superposition holds at any resolution, so this runs at
// h = a/5 (an eighth of a/10's cost); the a/5 error bounds are those of the
// convergence test's a/5 run (L2 9.7%, so held to 11%; mouth and K_I 3%).
// Measured at a/5: L2 9.69% in both, mouth -1.38% in both, K_I +1.82% in both
// (at a/10, before: 4.82% in both, also with the in-situ stress kept in the
// particles).
// Issue 19's near-tip drift: a soft material (p/E = 0.05, five hundred
// times sneddon.scene's) with the crack on a node row, as here. The issue saw
// the face point next to the tip open without bound through the run (to five
// times its exact opening). Not reproduced since the face-load sliver limit
// of issue 18 (docs/solid.md): at p/E = 1e-3 (a/20), 1e-2 and 5e-2 (a/10) the
// openings are steady to 4 digits from 4 transits on (by hand with
// scenarios/sneddon.scene). Held here: between 8 and 12 transits no face
// point's opening moves by more than 0.5% of the largest opening, none
// exceeds 1.2 x the exact largest opening, and the profile's L2 error falls
// under refinement. Measured: drift 3.0e-7 (a/5) and 1.9e-5 (a/10) of the
// largest opening; widest 1.024 and 1.074 of it; L2 error 7.9% and 6.6% (at
// this p/E the small-strain reference itself is off by a few percent).
TEST(Sneddon, SoftMaterialOnANodeRowHasNoNearTipDrift) {
  const Material soft{"soft", 2e7, 0.25, 2500};
  const double largest = finite_width_factor(kA, kB) * 4 * kP * kA / soft.plane_strain_modulus();
  double previous = 1;
  for (int cells : {5, 10}) {
    std::vector<std::vector<double>> widths;
    const auto r = run_sneddon(cells, 2, 0, false, 0, soft, &widths);
    ASSERT_EQ(widths.size(), 3u);
    double drift = 0, widest = 0;
    for (std::size_t k = 0; k < widths[0].size(); ++k) {
      drift = std::max({drift, std::abs(widths[2][k] - widths[0][k]), std::abs(widths[1][k] - widths[0][k])});
      for (const auto& w : widths) widest = std::max(widest, w[k]);
    }
    std::printf(
        "sneddon p/E = 0.05, h = a/%d: opening L2 error %.4f, largest drift over 8-12 transits %.2e of the "
        "mouth opening, widest %.4f of it\n",
        cells, r.l2_error, drift / largest, widest / largest);
    EXPECT_LT(drift, 5e-3 * largest) << "a face point drifts at h = a/" << cells;
    EXPECT_LT(widest, 1.2 * largest) << "h = a/" << cells;
    EXPECT_LT(r.l2_error, previous) << "h = a/" << cells;
    previous = r.l2_error;
  }
}

TEST(Sneddon, InSituStressAsReferenceOpensAsTheNetPressure) {
  const double sigma0 = -10 * kP;
  const auto plain = run_sneddon(5, 2);
  const auto reference = run_sneddon(5, 2, sigma0, true);
  std::printf(
      "sneddon a/5: L2 error %.4f (no in-situ stress), %.4f (in-situ stress -10 p as reference); "
      "mouth %+.4f, %+.4f; K_I %+.4f, %+.4f\n",
      plain.l2_error, reference.l2_error, plain.mouth_error, reference.mouth_error, plain.k_error, reference.k_error);
  EXPECT_LT(reference.l2_error, 0.11);
  EXPECT_LT(std::abs(reference.mouth_error), 0.03);
  EXPECT_LT(std::abs(reference.l2_error - plain.l2_error), 0.005);
  EXPECT_LT(std::abs(reference.k_error), 0.03);
}

// A coarse far field (SolidConfig regions with their own particles_per_cell):
// one particle per cell in the body and four (2 x 2) only within 2a x 2a
// (x < 2a, |y| < a) around the crack. The far field carries small, smooth
// strains that one uGIMP particle per cell integrates well, so the opening
// and K_I stay those of the fine body: the profile within 0.5% (L2 difference
// of the errors) and K_I within 1%, with under half the particles. Run at
// h = a/5 (the crack's cells are the ones that matter and a/5 already resolves
// the far field's strains): measured 5,000 against 1,550 particles, L2 error
// 9.69% against 9.61%, mouth -1.38% against -1.11%, K_I +1.82% against +2.02%
// (at a/10, before: 20,000 against 6,200; 4.82% both; +0.85/+0.94%; +2.36/+2.43%;
// the coarse far field's departures are larger at a/5 but well inside the bounds).
// The crack's own cells
// keep four particles each.
TEST(Sneddon, CoarseFarFieldOpensAsTheFineBody) {
  const auto fine = run_sneddon(5, 2);
  const auto coarse = run_sneddon(5, 2, 0, false, 2.0);
  std::printf(
      "sneddon a/5: %zu particles (fine), %zu (coarse far field); L2 error %.4f, %.4f; mouth %+.4f, %+.4f; "
      "K_I %+.4f, %+.4f\n",
      fine.particles, coarse.particles, fine.l2_error, coarse.l2_error, fine.mouth_error, coarse.mouth_error,
      fine.k_error, coarse.k_error);
  EXPECT_LT(coarse.particles, fine.particles / 2);
  EXPECT_LT(coarse.l2_error, 0.11);
  EXPECT_LT(std::abs(coarse.l2_error - fine.l2_error), 0.005);
  EXPECT_LT(std::abs(coarse.mouth_error - fine.mouth_error), 0.005);
  EXPECT_LT(std::abs(coarse.k_error - fine.k_error), 0.01);
}

}  // namespace
}  // namespace hfmpm::solid::mpm
