// J and the growth energy right after a large kink (issue 18), at rest: the
// 45-degree crack of the oblique tests with a quarter-cell kink of 67 deg at
// both tips (the 3:1 case's first kink), against the same crack without the
// kink (its parent) and Cotterell and Rice's first-order kink solution.
//
// What is measured (docs/verification.md, "J after a large kink"): the
// domain-form J of the kinked crack is the parent's J vector projected on
// the new direction, cos(a) J1 + sin(a) J2 with J1 = (K_I^2 + K_II^2) / E'
// and J2 = -2 K_I K_II / E' of the parent (the projection of Hellen and
// Blackburn, which is not the kinked tip's energy release rate), because
// the face term that turns it into the kinked tip's G is concentrated
// within about the kink's length of its corner, a quarter cell, where the
// discretized fields know nothing of it. The interaction integral's K's
// are the kinked tip's. Growth is therefore driven by (K_I^2 + K_II^2) / E'
// where the crack bends by more than 30 deg within the domain
// (growth_energy, kIrwinBend).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "oblique_growth.hpp"

namespace hfmpm::solid::mpm {
namespace {

constexpr double kKink = 67 * kPi / 180;  // rad, counter-clockwise at the end tip (point-symmetric at the start)

// Cells, the kink's length (HFMPM_KINK_CELLS, default a quarter cell, the
// growth step of the oblique tests).
double kink_cells() { return std::getenv("HFMPM_KINK_CELLS") ? std::atof(std::getenv("HFMPM_KINK_CELLS")) : 0.25; }

// The oblique tests' crack, with a kink of kKink and kink_cells() at each
// tip (or without it: the parent).
std::vector<Vec2> crack_points(double h, bool kinked) {
  const Vec2 centre(h / 2, 0);
  const int segments = static_cast<int>(std::lround(4 * kA / h));
  const Vec2 dir(std::cos(kPi / 4), std::sin(kPi / 4));
  const Vec2 ahead(std::cos(kPi / 4 + kKink), std::sin(kPi / 4 + kKink));
  std::vector<Vec2> pts;
  // The kink in segments of at most half a cell (as growth makes them).
  const int pieces = std::max(1, static_cast<int>(std::ceil(kink_cells() / 0.5 - 1e-9)));
  if (kinked) {
    for (int k = pieces; k > 0; --k) pts.push_back(centre - kA * dir - kink_cells() * h * k / pieces * ahead);
  }
  for (int k = 0; k <= segments; ++k) pts.push_back(centre + (-kA + 2 * kA * k / segments) * dir);
  if (kinked) {
    for (int k = 1; k <= pieces; ++k) pts.push_back(centre + kA * dir + kink_cells() * h * k / pieces * ahead);
  }
  return pts;
}

enum class Load { kAnisotropic, kRemoteTension, kInSituTension };

// The crack at rest under one of the loads: the 3:1 in-situ stress (sigma_xx
// = -2, sigma_yy = -6 MPa, the reference state) with the face pressure of
// the 3:1 case's first growth (4.39 MPa); a remote sigma_xx = 2 MPa, faces
// free; the same tension as the in-situ (reference) stress, faces free (by
// superposition the same problem). Damped over 12 transits.
std::vector<TipResult> at_rest(bool kinked, Load load) {
  const double h = kA / 5, b = 5 * kA;
  const bool anisotropic = load == Load::kAnisotropic;
  SolidConfig c = oblique_crack(h, b, kPi / 4, Vec2(h / 2, 0), anisotropic ? -2e6 : 0, anisotropic ? -6e6 : 0, 3.9e6);
  if (load == Load::kInSituTension) c = oblique_crack(h, b, kPi / 4, Vec2(h / 2, 0), 2e6, 0, 3.9e6);
  if (load == Load::kRemoteTension) {
    const auto held = TimeFunction::constant(2e6);
    c.tractions = {{Edge::Left, held, TimeFunction::constant(0)}, {Edge::Right, held, TimeFunction::constant(0)}};
  }
  c.fracture.propagate = false;
  c.cracks[0].points = crack_points(h, kinked);
  Solver s(c);
  s.cracks()[0].pressure().assign(c.cracks[0].points.size(), anisotropic ? 4.39e6 : 0.0);
  settle(s, 2 * b, 12);
  return s.tips();
}

// J/m^2: the energy release rate of a kink by kKink from a tip with the
// parent's K's, to first order in the kink's length (Cotterell and Rice 1980,
// Int. J. Fract. 16: the kinked tip's K's are the parent's hoop and shear
// stress intensities in the kink's direction).
double kinked_g(const TipResult& parent) {
  const double a = kKink, k1 = parent.k1, k2 = parent.k2;
  const double c11 = (3 * std::cos(a / 2) + std::cos(3 * a / 2)) / 4;
  const double c12 = -3 * (std::sin(a / 2) + std::sin(3 * a / 2)) / 4;
  const double c21 = (std::sin(a / 2) + std::sin(3 * a / 2)) / 4;
  const double c22 = (std::cos(a / 2) + 3 * std::cos(3 * a / 2)) / 4;
  const double kk1 = c11 * k1 + c12 * k2, kk2 = c21 * k1 + c22 * k2;
  return (kk1 * kk1 + kk2 * kk2) / parent.modulus;
}

// J/m^2: the parent's J vector on the kink's direction (Hellen and Blackburn).
double projected_j(const TipResult& parent) {
  const double j1 = (parent.k1 * parent.k1 + parent.k2 * parent.k2) / parent.modulus;
  const double j2 = -2 * parent.k1 * parent.k2 / parent.modulus;
  return std::cos(kKink) * j1 + std::sin(kKink) * j2;
}

struct Measured {
  double growth[2] = {0, 0};  // growth_energy / kinked_g, start and end tip
  double energy[2] = {0, 0};  // J/m^2, growth_energy
  double j_projected[2] = {0, 0};
};

Measured measure(Load load, const char* name) {
  const auto parents = at_rest(false, load);
  const auto kinked = at_rest(true, load);
  Measured m;
  for (const auto& tip : kinked) {
    const TipResult* parent = nullptr;
    for (const auto& p : parents)
      if (p.at_end == tip.at_end) parent = &p;
    EXPECT_NE(parent, nullptr);
    if (parent == nullptr) continue;
    const int i = tip.at_end ? 1 : 0;
    m.energy[i] = growth_energy(tip);
    m.growth[i] = m.energy[i] / kinked_g(*parent);
    m.j_projected[i] = tip.j / projected_j(*parent);
    std::printf(
        "%s, %s tip: parent K_I %.4e, K_II %.4e Pa m^0.5 (J/((K_I^2+K_II^2)/E') %.4f); kinked (bend %.2f deg): "
        "J %.4e J/m^2 (faces %+.4e), K_I %.4e, K_II %.4e, J/((K_I^2+K_II^2)/E') %.4f; first-order kink G %.4e, "
        "growth energy %.4e (%.4f of it), J / parent's J vector on the kink %.4f\n",
        name, tip.at_end ? "end" : "start", parent->k1, parent->k2, j_over_k(*parent), tip.bend * 180 / kPi, tip.j,
        tip.j_faces, tip.k1, tip.k2, j_over_k(tip), kinked_g(*parent), growth_energy(tip), m.growth[i],
        m.j_projected[i]);
    EXPECT_NEAR(tip.bend, kKink, 0.5 * kPi / 180);  // the faces move
    EXPECT_TRUE(tip.one_material);
  }
  return m;
}

// The 3:1 case's first kink, at rest. Asserted:
// - the growth energy within 10% of the first-order kink solution from the
//   parent's K's (measured 1.04; the parent's own J/K is 1.03 at this cell
//   size, and the first-order solution is a few percent off the exact one
//   at 67 deg). Before the growth energy came from the K's here it was J:
//   0.51 of it, and the two tips of the growing crack waited for J to reach
//   J_Ic at different checks;
// - the cause: J itself within 10% of the parent's J vector on the kink's
//   direction (measured 1.06), half the kinked tip's G;
// - the two tips' growth energies within 1% (point symmetry).
TEST(KinkedJ, AfterTheAnisotropicCasesKinkGrowthEnergyIsTheKinkedTips) {
  const Measured m = measure(Load::kAnisotropic, "3:1 in situ, p 4.39 MPa");
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(m.growth[i], 1, 0.10) << (i ? "end" : "start") << " tip";
    EXPECT_NEAR(m.j_projected[i], 1, 0.10) << (i ? "end" : "start") << " tip";
  }
  EXPECT_NEAR(m.growth[0] / m.growth[1], 1, 0.01);
}

// The same kink under a tension sigma_xx = 2 MPa held at the edges (faces
// free), and the same as the in-situ stress with the faces loaded by its
// traction: superposition says the growth energies are equal. Asserted
// within 5% of each other (measured 3.0-3.9%; the parents' J differ by
// 4%) and 10% of the first-order kink solution from each parent's K's
// (measured 1.01-1.09; J is 0.85-0.86 of (K_I^2 + K_II^2) / E' there, the
// projection's 0.875 at this K_II/K_I).
TEST(KinkedJ, RemoteTensionAndTheSameTensionAsInSituStressGiveTheSameGrowthEnergy) {
  const Measured remote = measure(Load::kRemoteTension, "remote sigma_xx 2 MPa");
  const Measured in_situ = measure(Load::kInSituTension, "in-situ sigma_xx 2 MPa");
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(remote.growth[i], 1, 0.10);
    EXPECT_NEAR(in_situ.growth[i], 1, 0.10);
    EXPECT_NEAR(remote.energy[i] / in_situ.energy[i], 1, 0.05);
    EXPECT_NEAR(remote.j_projected[i], 1, 0.10);
    EXPECT_NEAR(in_situ.j_projected[i], 1, 0.10);
  }
}

}  // namespace
}  // namespace hfmpm::solid::mpm
