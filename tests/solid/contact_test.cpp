// Crack contact (CRAMP frictionless contact, Nairn 2003): a block cut right
// across by a closed crack (both ends mouths, so the halves are separate).
// - Compression (top traction -p, roller base): the load must cross the crack.
//   At rest sigma_yy = -p in both halves (within 1% of p) and the faces do not
//   interpenetrate (overlap below 1% of the block's elastic shortening p H / M).
// - Tension (top traction +p): the faces separate freely: the lower half stays
//   unstressed (|sigma_yy| < 1% of p) while the crack opens.
// - In-situ compression (initial stress -p in the block, held by the top
//   traction): the body is in equilibrium from the first step, so nothing may
//   move (a crack closed under confinement before any fluid arrives). Faces
//   that touch with zero opening (to round-off) are in contact; a test
//   "opening < 0" lets them overlap first and then chatter (measured here: a
//   kinetic energy 2.7% of the stored energy within 3 steps; in a confined
//   KGD box, spurious crack growth with no fluid at all).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {
namespace {

const Material kRock{"rock", 1e9, 0.25, 2500};
constexpr double kP = 1e6, kH = 0.05;

SolidConfig cut_block(double top_traction) {
  SolidConfig c;
  c.grid.origin = Vec2(-2 * kH, 0);
  c.grid.h = kH;
  c.grid.nx = 24;
  c.grid.ny = 30;  // room above for the upper half to move away
  c.materials = {kRock};
  Region r;
  r.lo = Vec2(0, 0);
  r.hi = Vec2(1, 1);
  c.regions = {r};
  c.constraints = {{Constraint::Kind::PlaneY, 0.0}, {Constraint::Kind::PlaneX, 0.0}};
  c.tractions = {{Edge::Top, TimeFunction::constant(top_traction)}};
  CrackSpec crack;
  for (int k = 0; k <= 40; ++k) crack.points.emplace_back(k / 40.0, 0.5);
  crack.start_is_tip = crack.end_is_tip = false;
  c.cracks = {crack};
  c.damping.grid_alpha = std::numbers::pi * kRock.p_wave_speed(kRock.density) / 2;
  return c;
}

// Mean sigma_yy of the particles above (upper = true) or below the crack.
double mean_syy(const Solver& s, bool upper) {
  double sum = 0, volume = 0;
  const auto& p = s.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if ((p.x[i].y() > 0.5) != upper) continue;
    sum += p.stress[i][1] * p.volume[i];
    volume += p.volume[i];
  }
  return sum / volume;
}

TEST(Contact, ClosedCrackCarriesCompressionWithoutInterpenetration) {
  Solver s(cut_block(-kP));
  const double dt = s.stable_dt();
  for (int i = 0; i < 3000; ++i) s.step(dt);
  EXPECT_NEAR(mean_syy(s, true), -kP, 0.01 * kP);
  EXPECT_NEAR(mean_syy(s, false), -kP, 0.01 * kP);
  const double shortening = kP * 1.0 / kRock.p_modulus();
  const auto& crack = s.cracks()[0];
  double overlap = 0;
  for (std::size_t k = 0; k < crack.size(); ++k) {
    overlap = std::max(overlap, -(crack.surface(1)[k] - crack.surface(-1)[k]).dot(crack.normal(k)));
  }
  EXPECT_LT(overlap, 0.01 * shortening) << "faces overlap by " << overlap << " m";
  EXPECT_GT(s.contacts(), 0u);
}

TEST(Contact, ClosedCrackUnderInSituStressStaysAtRest) {
  SolidConfig c = cut_block(-kP);
  c.regions[0].initial_stress = Voigt(0, -kP, 0, -0.25 * kP);  // sigma_zz = nu sigma_yy (plane strain)
  c.damping.grid_alpha = 0;
  Solver s(c);
  const double dt = s.stable_dt();
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    s.step(dt);
    worst = std::max(worst, s.kinetic_energy());
  }
  // Stored energy p^2 / (2 M) per unit volume times the block's 1 m^2: 2e2 J/m.
  const double stored = kP * kP / (2 * kRock.p_modulus());
  std::printf("closed crack under in-situ stress: max kinetic energy %.3e J/m (stored %.3e J/m)\n", worst, stored);
  EXPECT_LT(worst, 1e-12 * stored);  // round-off: the state is exactly in equilibrium
  EXPECT_NEAR(mean_syy(s, true), -kP, 1e-9 * kP);
  EXPECT_NEAR(mean_syy(s, false), -kP, 1e-9 * kP);
}

TEST(Contact, FacesSeparateFreelyUnderTension) {
  Solver s(cut_block(kP));
  const double dt = s.stable_dt();
  for (int i = 0; i < 600; ++i) s.step(dt);
  EXPECT_LT(std::abs(mean_syy(s, false)), 0.01 * kP);
  const auto& crack = s.cracks()[0];
  const double w1 = crack.width(20);
  for (int i = 0; i < 100; ++i) s.step(dt);
  EXPECT_GT(w1, 0);
  EXPECT_GT(crack.width(20), w1);  // still opening
}

}  // namespace
}  // namespace hfmpm::solid::mpm
