// Coulomb friction on closed crack faces: a closed crack inclined in a plate
// under biaxial compression (the in-situ stress as the reference state, held
// by the edges' tractions). The crack's plane at beta = 30 degrees to x under
// sigma_xx = -3 MPa, sigma_yy = -1 MPa carries the normal stress
// sigma_n = -1.5 MPa and the shear tau = 0.866 MPa. The faces stay shut; where
// |tau| > mu |sigma_n| they slide under the excess shear, so the crack is a
// mode-II crack loaded by tau_eff = |tau| - mu |sigma_n| (a uniform shear
// on an open crack's faces, by superposition; Tada, Paris and Irwin, The
// Stress Analysis of Cracks Handbook, 1.4):
//   K_II = tau_eff sqrt(pi a), K_I = 0,
//   slip at the centre 4 (1 - nu^2) tau_eff a / E;
// where |tau| <= mu |sigma_n| they stick: K_II = 0 and no slip.
// Checked at mu = 0 (0.866 MPa), 0.3 (0.416 MPa) and 0.6 (stuck), h = a/5
// (HFMPM_FRICTION_CELLS=n for a/n):
// - frictionless: K_II +2.8%, within the 5% the inclined crack is
//   verified to on this J domain (fracture_test.cpp);
// - stuck (mu 0.6): no slip (1e-13 m against 3.7e-4 m frictionless) and
//   |K_II| 9.5% of the frictionless one: the faces' contact carries
//   95% of the in-situ load that presses them together; the tip cells,
//   where the two sides share one field, carry the rest as a body would;
// - sliding (mu 0.3): the nodal Coulomb law (Nairn's) carries 0.86 mu of
//   the contact's normal load as friction, not mu: the nodes
//   near the tips, with little slip, stick below their limit. The slip
//   against the frictionless slip at the same resolution (which cancels the
//   surfaces' reading, +15% of the closed form) is 0.577 against Coulomb's
//   0.480 (+20%): the crack slides as under mu = 0.24. Asserted as measured:
//   that ratio within 25% of Coulomb's, the friction carried between 0.8 and
//   1 mu of the normal load.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fracture_setup.hpp"

namespace hfmpm::solid::mpm {
namespace {

constexpr double kA = 1, kB = 10, kBeta = kPi / 6;
constexpr double kSxx = -3e6, kSyy = -1e6;

struct Slide {
  double k1 = 0, k2 = 0;                   // Pa m^0.5, worst of the two tips by |K_II|, as measured
  double slip = 0;                         // m, at the centre, |(above - below) . t|
  double normal_load = 0, shear_load = 0;  // N/m, the contact's tractions summed along the crack
};

Slide closed_crack_under_compression(double mu) {
  const int cells = std::getenv("HFMPM_FRICTION_CELLS") ? std::atoi(std::getenv("HFMPM_FRICTION_CELLS")) : 5;
  const double h = kA / cells;
  SolidConfig c = plate_with_centre_crack(h, kB, kA, kBeta, Vec2::Zero());
  const double nu = kRock.poisson_ratio;
  c.regions[0].initial_stress = Voigt(kSxx, kSyy, 0, nu * (kSxx + kSyy));
  c.in_situ_reference = true;
  c.tractions = {{Edge::Left, TimeFunction::constant(kSxx)},
                 {Edge::Right, TimeFunction::constant(kSxx)},
                 {Edge::Bottom, TimeFunction::constant(kSyy)},
                 {Edge::Top, TimeFunction::constant(kSyy)}};
  c.cracks[0].friction = mu;
  c.fracture.inner_cells = 3;
  c.fracture.outer_cells = 7;
  c.threads = 2;
  Solver solid(c);
  settle(solid, 2 * kB, 12);
  Slide out;
  for (const auto& tip : solid.tips()) {
    if (std::abs(tip.k2) >= std::abs(out.k2)) {
      out.k2 = tip.k2;
      out.k1 = tip.k1;
    }
  }
  const auto& crack = solid.cracks()[0];
  const std::size_t mid = crack.size() / 2;
  const Vec2 t(std::cos(kBeta), std::sin(kBeta));
  out.slip = std::abs((crack.surface(1)[mid] - crack.surface(-1)[mid]).dot(t));
  // The friction the contact carried, against mu x the normal load it carried.
  for (std::size_t k = 0; k < crack.size(); ++k) {
    const Vec2 nk = crack.normal(k);
    const Vec2 traction_k = crack.contact_traction()[k];
    out.normal_load += traction_k.dot(nk) * crack.tributary_length(k);
    out.shear_load += std::abs(traction_k.dot(Vec2(nk.y(), -nk.x()))) * crack.tributary_length(k);
  }
  return out;
}

TEST(Friction, ClosedInclinedCrackSlidesUnderTheExcessShear) {
  const Vec2 n(-std::sin(kBeta), std::cos(kBeta)), t(std::cos(kBeta), std::sin(kBeta));
  const Voigt s0(kSxx, kSyy, 0, 0);
  const Vec2 traction_on_plane = traction(s0, n);
  const double sigma_n = traction_on_plane.dot(n), tau = std::abs(traction_on_plane.dot(t));
  ASSERT_NEAR(sigma_n, -1.5e6, 1);
  ASSERT_NEAR(tau, (kSyy - kSxx) * std::sin(kBeta) * std::cos(kBeta), 1);  // 0.866 MPa
  const double modulus = kRock.youngs_modulus / (1 - kRock.poisson_ratio * kRock.poisson_ratio);
  const char* only = std::getenv("HFMPM_FRICTION_MU");  // mu = 0 always runs: the others are measured against it
  Slide frictionless;
  for (const double mu : {0.0, 0.3, 0.6}) {
    if (only && mu != 0 && std::abs(std::atof(only) - mu) > 1e-9) continue;
    const double effective = std::max(0.0, tau - mu * std::abs(sigma_n));
    const double k2_exact = effective * std::sqrt(kPi * kA);
    const double slip_exact = 4 * effective * kA / modulus;
    const Slide got = closed_crack_under_compression(mu);
    std::printf(
        "mu %.1f: tau_eff %.4g Pa; K_II %.4e (exact %.4e), K_I %.3e; centre slip %.4e m (exact %.4e); the "
        "contact's friction %.3f of its normal load\n",
        mu, effective, std::abs(got.k2), k2_exact, got.k1, got.slip, slip_exact,
        got.normal_load > 0 ? got.shear_load / got.normal_load : 0.0);
    if (mu == 0) {
      frictionless = got;
      EXPECT_NEAR(std::abs(got.k2) / k2_exact, 1, 0.05);
      EXPECT_LT(got.shear_load, 1e-4 * got.normal_load);  // no friction (round-off)
      continue;
    }
    ASSERT_GT(frictionless.slip, 0) << "run mu = 0 first";
    if (effective > 0) {
      const double coulomb = effective / tau;  // the slip's ratio to the frictionless one
      EXPECT_NEAR(got.slip / frictionless.slip / coulomb, 1, 0.25) << "mu " << mu;
      EXPECT_GT(got.shear_load, 0.8 * mu * got.normal_load) << "mu " << mu;
      EXPECT_LE(got.shear_load, mu * got.normal_load * (1 + 1e-9)) << "mu " << mu;
    } else {
      EXPECT_LT(got.slip, 1e-6 * frictionless.slip) << "a stuck crack slid";
      EXPECT_LT(std::abs(got.k2), 0.15 * std::abs(frictionless.k2)) << "a stuck crack slid";
    }
    // Closed: no opening mode (a negative K_I is the faces' residual overlap).
    EXPECT_LT(got.k1, 0.05 * std::abs(frictionless.k2)) << "mu " << mu;
  }
}

}  // namespace
}  // namespace hfmpm::solid::mpm
