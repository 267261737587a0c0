// Fracture mechanics of the MPM solid against handbook solutions: K from the
// interaction integral for an edge crack and an inclined crack, the kink
// angle by maximum hoop stress, path independence of J, mirror symmetry of a
// mode-I problem, and the interaction integral's auxiliary fields.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <stdexcept>

#include "fracture_setup.hpp"

namespace hfmpm::solid::mpm {
namespace {

// One settled state of an edge crack, a/W = 0.3, half-height 1.5 W, under
// remote tension, checked three ways (one test: each check needs the same
// 12 damped transits at h = W/40, about a minute of CPU).
//
// K_I (interaction integral) against Tada (the strip is long: at half-height
// >= W the factor is within 1% of the infinite strip). Measured: -3.5%
// (h = W/20), -1.7% (W/40) (sqrt(E' J): -3.6%, -1.7%): first order, as the
// near-tip field is resolved by a few cells; held to 3% at W/40.
//
// Path independence: J over domains 1-3, 2-5 and 3-7 cells from the tip
// agree. The domains see different parts of the field, so this tests the area
// integral's equilibrium assumption; measured spread < 1%; held to 2%.
//
// Mirror symmetry of a mode-I problem about the crack line: the particles
// come in mirror pairs (the crack lies on a grid line), and u_x must be even
// and u_y odd in y. Measured asymmetry: round-off (1.5e-13 of the largest
// displacement); held to 1e-9. (Before the side tests treated a tip sitting
// on a node with a tolerance, round-off motions of the tip flipped that node
// between one and two fields, and the asymmetry was 4e-3.)
TEST(EdgeCrack, KMatchesTadaJIsPathIndependentAndModeIStaysSymmetric) {
  constexpr double kW = 1, kA = 0.3, kH = 1.5 * kW, kSigma = 1e6;
  const double k_exact = tada_edge_factor(kA / kW) * kSigma * std::sqrt(kPi * kA);
  double previous = 1;
  for (int cells : {20, 40}) {
    const auto config = edge_crack(kW, kA, kH, cells, TimeFunction::constant(kSigma));
    Solver solid(config);
    settle(solid, 2 * kH, 12);
    const auto tips = solid.tips();
    ASSERT_EQ(tips.size(), 1u);
    const double error = (tips[0].k1 - k_exact) / k_exact;
    std::printf(
        "edge crack a/W = 0.3, h = W/%d: K_I %.4e Pa m^0.5, Tada %.4e, error %+.4f, "
        "|K_II|/K_I %.1e, face work %.3f of J\n",
        cells, tips[0].k1, k_exact, error, std::abs(tips[0].k2) / tips[0].k1, tips[0].j_faces / tips[0].j);
    EXPECT_LT(std::abs(error), cells >= 40 ? 0.03 : 0.05);
    EXPECT_LT(std::abs(tips[0].k2), 1e-6 * tips[0].k1) << "mode I problem with a mode II part";
    EXPECT_LE(std::abs(error), previous + 0.005) << "K does not improve with refinement";
    previous = std::abs(error);
    if (cells < 40) continue;

    std::vector<double> js;
    for (auto [inner, outer] : {std::pair{1.0, 3.0}, std::pair{2.0, 5.0}, std::pair{3.0, 7.0}}) {
      auto c = config;
      c.fracture.inner_cells = inner;
      c.fracture.outer_cells = outer;
      // Same state, other domain: copy the solver's state into a solver with other settings.
      Solver probe(c);
      probe.particles() = solid.particles();
      probe.cracks() = solid.cracks();
      js.push_back(probe.tips().at(0).j);
      std::printf("J over cells %.0f-%.0f: %.6e J/m^2\n", inner, outer, js.back());
    }
    const auto [lo, hi] = std::minmax_element(js.begin(), js.end());
    EXPECT_LT((*hi - *lo) / *hi, 0.02) << "J depends on the domain";

    const auto& p = solid.particles();
    // Pair particles by their initial positions x - u.
    auto key = [&](std::size_t i, double sign) {
      const Vec2 x0 = p.x[i] - p.displacement[i];
      const double quarter = solid.grid().h / 4;  // particles sit at odd multiples of h/4 from grid lines
      return std::pair{std::lround(x0.x() / quarter), std::lround(sign * x0.y() / quarter)};
    };
    std::map<std::pair<long, long>, std::size_t> index;
    for (std::size_t i = 0; i < p.size(); ++i) index[key(i, 1)] = i;
    double worst = 0, largest = 0;
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const auto it = index.find(key(i, -1));
      ASSERT_NE(it, index.end());
      const Vec2& u = p.displacement[i];
      const Vec2& m = p.displacement[it->second];
      const double asym = std::max(std::abs(u.x() - m.x()), std::abs(u.y() + m.y()));
      worst = std::max(worst, asym);
      largest = std::max(largest, u.norm());
      ++pairs;
    }
    std::printf("mirror asymmetry over %zu pairs: %.3e of the largest displacement %.3e m\n", pairs, worst / largest,
                largest);
    EXPECT_LT(worst, 1e-9 * largest) << "mode I problem not mirror-symmetric";
  }
}

}  // namespace
}  // namespace hfmpm::solid::mpm

namespace hfmpm::solid::mpm {
namespace {

constexpr double kA = 1, kB = 10, kSigma = 1e6;

// The centre crack of length 2 kA at 45 degrees in the plate [-kB, kB]^2 pulled by
// kSigma on its top and bottom edges; crack particles every half cell.
SolidConfig inclined_crack(double h) {
  SolidConfig c = plate_with_centre_crack(h, kB, kA, kPi / 4, Vec2::Zero());
  const auto sigma = TimeFunction::constant(kSigma);
  c.tractions = {{Edge::Top, sigma, TimeFunction::constant(0)}, {Edge::Bottom, sigma, TimeFunction::constant(0)}};
  c.threads = 2;
  return c;
}

// Centre crack of length 2a at beta = 45 degrees to the x axis in a square
// plate [-10a, 10a]^2 under remote tension sigma_yy. Reference: the infinite
// plate (Tada, Paris and Irwin, The Stress Analysis of Cracks Handbook, 1.4;
// exact): K_I = sigma sqrt(pi a) cos^2(beta), K_II = sigma sqrt(pi a)
// sin(beta) cos(beta) (sin^2 and sin cos of the angle to the load axis), here
// both sigma sqrt(pi a) / 2; by maximum hoop stress the crack kinks by
// -53.13 degrees (Erdogan and Sih 1963). The plate's finite size raises K by
// about 1% at b = 10a (3.7% at b = 5a, measured on the crack normal to the load).
// K_I and K_II from the interaction integral, measured at h = a/5 (a/8):
//   domain 3-7 cells: K_I -0.7% (-0.7%), K_II +0.1% (+0.3%), kink -53.25 (-53.29) deg;
//   domain 2-5 cells (the default): K_I +6.1% (+4.1%), K_II +6.8% (-0.7%), kink -53.22 (-52.41).
// The default domain is too close to the tip for an oblique crack: the
// particles within two cells of a crack crossing the cells at 45 degrees
// carry stress errors of 10-50% (against Westergaard), and J itself is +14%
// (sqrt(J E') +6.9%) over it, path-dependent (+8.7%, +6.9%, +3.4% over 1-3,
// 2-5, 3-7 cells), not converging with h at a fixed domain in cells (a/16:
// K_I +6.9%), and shifting the crack by a fraction of a cell moves K by +-5%.
// (The split is not the problem: K_II / K_I from M is 1.006 at a/5, and
// within 0.95-1.07 over crack shifts and h = a/5, a/8 on either domain.)
// So the 5% of the issue is held on the 3-7 domain of the same state, the
// default domain to 8%, and the kink on both to 3 degrees.
//
// After a kink the crack should go on in the kinked direction, not turn
// again: the state of this test (the kinked segment just added, still closed, so the
// field is the unkinked crack's) must give about the same absolute growth
// direction as before the kink. The tip frame is the last segment; the crack
// before the kink lies off its x1 axis, and the interaction integral's face
// terms there (the auxiliary field's traction) are what keep the second kink
// small: without them the same field gave a second kink of about the first
// (-53 degrees again: -106 from the crack), and fluid-driven cracks beside an
// interface spiralled. Asserted: within 10 degrees of the first direction
// (the field is not that of the kinked crack, and the new tip is half a cell
// from the singularity the domain sees; measured 6.74 deg).
// HFMPM_INCLINED_CELLS=n runs at h = a/n.
TEST(InclinedCrack, MixedModeAndKinkAngleThenNoSecondKink) {
  const int cells = std::getenv("HFMPM_INCLINED_CELLS") ? std::atoi(std::getenv("HFMPM_INCLINED_CELLS")) : 5;
  const double h = kA / cells;
  SolidConfig c = inclined_crack(h);
  Solver solid(c);
  settle(solid, 2 * kB, 12);
  const double k_exact = kSigma * std::sqrt(kPi * kA) / 2;
  const double kink_exact = 2 * std::atan((1 - 3.0) / 4);  // -53.13 degrees
  // The same state with the 3-7 cell domain.
  auto wide = c;
  wide.fracture.inner_cells = 3;
  wide.fracture.outer_cells = 7;
  Solver probe(wide);
  probe.particles() = solid.particles();
  probe.cracks() = solid.cracks();
  for (const bool wide_domain : {true, false}) {
    const auto tips = wide_domain ? probe.tips() : solid.tips();
    ASSERT_EQ(tips.size(), 2u);
    for (const auto& tip : tips) {
      std::printf(
          "inclined crack h = a/%d, domain %s, %s tip: K_I %.4e (error %+.4f), K_II %.4e (error %+.4f), "
          "kink %.2f deg (exact %.2f)\n",
          cells, wide_domain ? "3-7" : "2-5", tip.at_end ? "end" : "start", tip.k1, tip.k1 / k_exact - 1, tip.k2,
          tip.k2 / k_exact - 1, tip.kink * 180 / kPi, kink_exact * 180 / kPi);
      const double tolerance = wide_domain ? 0.05 : 0.08;
      EXPECT_NEAR(tip.k1 / k_exact, 1, tolerance);
      EXPECT_NEAR(tip.k2 / k_exact, 1, tolerance);
      EXPECT_NEAR(tip.kink * 180 / kPi, kink_exact * 180 / kPi, 3);
    }
  }

  // Then, on the same state and the 3-7 domain: the kink added, the next
  // heading.
  auto end_tip = [&] {
    for (const auto& tip : probe.tips()) {
      if (tip.at_end) return tip;
    }
    throw std::runtime_error("no end tip");
  };
  auto heading = [](const TipResult& tip) {  // absolute growth direction, radians
    return std::atan2(tip.direction.y(), tip.direction.x()) + tip.kink;
  };
  const TipResult first = end_tip();
  const double first_heading = heading(first);
  probe.cracks()[0].append(first.position + 0.5 * h * Vec2(std::cos(first_heading), std::sin(first_heading)));
  const TipResult second = end_tip();
  const double second_heading = heading(second);
  std::printf(
      "kink %.2f deg from the crack (heading %.2f deg); after it, the next heading %.2f deg (kink %.2f deg "
      "from the tip frame at %.2f deg)\n",
      first.kink * 180 / kPi, first_heading * 180 / kPi, second_heading * 180 / kPi, second.kink * 180 / kPi,
      std::atan2(second.direction.y(), second.direction.x()) * 180 / kPi);
  EXPECT_NEAR(second_heading * 180 / kPi, first_heading * 180 / kPi, 10);
}

}  // namespace
}  // namespace hfmpm::solid::mpm

namespace hfmpm::solid::mpm {
namespace {

// Williams' near-tip displacement in plane strain (tip frame: crack along
// x1 < 0), written with the half angles from x1, x2 so that it takes complex
// arguments: the complex step then gives its gradient to round-off.
template <class T>
std::array<T, 2> williams_displacement(T x1, T x2, double k1, double k2, double mu, double kappa) {
  using std::sqrt;
  const T r = sqrt(x1 * x1 + x2 * x2);
  const T c = sqrt((r + x1) / (2.0 * r));                                     // cos(theta / 2)
  const T s = (std::real(x2) < 0 ? -1.0 : 1.0) * sqrt((r - x1) / (2.0 * r));  // sin(theta / 2)
  const T g = sqrt(r / (2 * kPi)) / (2 * mu);
  return {g * (k1 * c * (kappa - 1 + 2.0 * s * s) + k2 * s * (kappa + 1 + 2.0 * c * c)),
          g * (k1 * s * (kappa + 1 - 2.0 * c * c) - k2 * c * (kappa - 1 - 2.0 * s * s))};
}

// du_i/dx_j by the complex step (exact to round-off).
Eigen::Matrix2d williams_gradient(const Vec2& x, double k1, double k2, double mu, double kappa) {
  constexpr double kStep = 1e-30;
  Eigen::Matrix2d g;
  for (int j = 0; j < 2; ++j) {
    const std::complex<double> x1(x.x(), j == 0 ? kStep : 0), x2(x.y(), j == 1 ? kStep : 0);
    const auto u = williams_displacement(x1, x2, k1, k2, mu, kappa);
    for (int i = 0; i < 2; ++i) g(i, j) = u[static_cast<std::size_t>(i)].imag() / kStep;
  }
  return g;
}

// Williams' near-tip stress (s11, s22, s12), the textbook form.
std::array<double, 3> williams_stress(const Vec2& x, double k1, double k2) {
  const double r = x.norm(), t = std::atan2(x.y(), x.x()), f = 1 / std::sqrt(2 * kPi * r);
  const double c = std::cos(t / 2), s = std::sin(t / 2), c3 = std::cos(1.5 * t), s3 = std::sin(1.5 * t);
  return {f * (k1 * c * (1 - s * s3) - k2 * s * (2 + c * c3)), f * (k1 * c * (1 + s * s3) + k2 * s * c * c3),
          f * (k1 * s * c * c3 + k2 * c * (1 - s * s3))};
}

// The auxiliary fields' stress is C : sym(grad u) of their displacement
// (their strain and u_i,1 are derived from the displacement): checked at
// points all round the tip to 1e-10 of the stress.
TEST(InteractionIntegral, WilliamsStressMatchesDisplacementGradient) {
  const double mu = kRock.shear_modulus(), lambda = kRock.lame_lambda(), kappa = 3 - 4 * kRock.poisson_ratio;
  for (const double r : {1e-3, 0.2, 3.0}) {
    for (const double theta : {-3.1, -2.0, -0.6, 0.1, 1.3, 2.5, 3.13}) {
      for (const auto& [k1, k2] : {std::pair{1.0, 0.0}, std::pair{0.0, 1.0}, std::pair{0.7, -1.9}}) {
        const Vec2 x(r * std::cos(theta), r * std::sin(theta));
        const Eigen::Matrix2d g = williams_gradient(x, k1, k2, mu, kappa);
        const double tr = g(0, 0) + g(1, 1);
        const std::array<double, 3> from_u{lambda * tr + 2 * mu * g(0, 0), lambda * tr + 2 * mu * g(1, 1),
                                           mu * (g(0, 1) + g(1, 0))};
        const auto exact = williams_stress(x, k1, k2);
        const double scale = std::max({std::abs(exact[0]), std::abs(exact[1]), std::abs(exact[2])});
        for (std::size_t i = 0; i < 3; ++i) {
          EXPECT_NEAR(from_u[i] / scale, exact[i] / scale, 1e-10)
              << "r " << r << " theta " << theta << " component " << i;
        }
      }
    }
  }
}

// The solver's interaction integral on a prescribed Williams field: every
// particle of an edge-cracked strip gets grad u of K_I, K_II fields about
// the tip (x = 0.3, h = W/20, no loads, so no face work). With the field
// f = K_I f_I + K_II f_II, M^(I) = B(f, f_I) and J = B(f, f) / 2 for the
// same discrete bilinear form B if the solver's auxiliary stress and u_i,1 are
// those of f_I and f_II, so K_I K_I' + K_II K_II' = E' J holds to round-off
// (primes: the returned values) whatever the quadrature error. The returned K
// match the prescribed ones to the quadrature error of the domain integral
// (measured -0.11%; held to 0.5%), and the kink follows maximum hoop stress
// with K_I clamped at 0 (a closed crack under shear kinks by -70.53 degrees).
TEST(InteractionIntegral, RecoversPrescribedWilliamsField) {
  Solver solid(edge_crack(1, 0.3, 1.5, 20, TimeFunction::constant(0)));
  const Vec2 tip_position(0.3, 0);
  const double mu = kRock.shear_modulus(), kappa = 3 - 4 * kRock.poisson_ratio;
  const double e_prime = kRock.plane_strain_modulus(), k0 = 1e6;
  for (const auto& [k1, k2] :
       {std::pair{k0, 0.0}, std::pair{0.0, k0}, std::pair{k0, -0.5 * k0}, std::pair{-0.4 * k0, k0}}) {
    auto& p = solid.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.grad_u[i] = williams_gradient(p.x[i] - tip_position, k1, k2, mu, kappa);
    }
    const auto tips = solid.tips();
    ASSERT_EQ(tips.size(), 1u);
    const auto& tip = tips[0];
    ASSERT_NEAR((tip.position - tip_position).norm(), 0, 1e-12);
    const double k1_kink = std::max(0.0, k1);
    const double kink = k2 == 0 ? 0 : 2 * std::atan((k1_kink - std::sqrt(k1_kink * k1_kink + 8 * k2 * k2)) / (4 * k2));
    std::printf(
        "prescribed K_I %+.2e, K_II %+.2e: returned K_I %+.6e, K_II %+.6e, (K_I K_I' + K_II K_II') / E' J - 1 "
        "= %.1e, kink %.3f deg (exact %.3f)\n",
        k1, k2, tip.k1, tip.k2, (k1 * tip.k1 + k2 * tip.k2) / (e_prime * tip.j) - 1, tip.kink * 180 / kPi,
        kink * 180 / kPi);
    EXPECT_NEAR((k1 * tip.k1 + k2 * tip.k2) / (e_prime * tip.j), 1, 1e-10);
    EXPECT_NEAR(tip.k1 / k0, k1 / k0, 0.005);
    EXPECT_NEAR(tip.k2 / k0, k2 / k0, 0.005);
    EXPECT_NEAR(tip.kink * 180 / kPi, kink * 180 / kPi, 0.5);
  }
}

}  // namespace
}  // namespace hfmpm::solid::mpm
