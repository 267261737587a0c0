// Unit tests of the fluid's pieces.
// - Tait EOS p = c K (exp((1 - J)/c) - 1): p(1) = 0, dp/dJ(1) = -K (central
//   difference, truncation error ~ K h^2 / (6 c^2) relative), monotone, the
//   inverse J(p), no tension.
// - CPDI in 1D (Sadeghirad et al. 2011): on random non-uniform grids the
//   weights sum to one, the gradients to zero, and the weights reproduce
//   linear fields (sum Nbar_i s_i = s_p, sum Gbar_i s_i = 1) for particles
//   from a fraction of an element to many elements long; the weights equal a
//   brute-force quadrature of the hats; the clamp beyond the ends.
// - The crack grid: ids may only be appended; bad geometry is rejected.
// - The solver's input checks: config ranges, reordered ids, a closed mouth
//   without a pre-opening.
// - The stiffness -dp/dw the fluid reports (for the solid's implicit face
//   pressure) against a finite difference of the nodal pressures; the lag
//   pressure beyond the front (zero, or the front's).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/crack_grid.hpp"
#include "hfmpm/fluid/mpm/eos.hpp"
#include "hfmpm/fluid/mpm/rheology.hpp"
#include "hfmpm/fluid/mpm/shape.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {
namespace {

TEST(Tait, ZeroPressureAndBulkModulusAtTheReferenceState) {
  const TaitEos eos{2.2e9, 0.0894};
  EXPECT_EQ(eos.pressure(1.0), 0.0);
  const double h = 1e-5;
  const double slope = (eos.pressure(1 + h) - eos.pressure(1 - h)) / (2 * h);
  std::printf("Tait: dp/dJ(1) by central difference = %.9e Pa (-K = %.9e)\n", slope, -eos.bulk_modulus);
  EXPECT_NEAR(slope / -eos.bulk_modulus, 1.0, 1e-8);  // truncation h^2 / (6 c^2) ~ 2e-9
  EXPECT_DOUBLE_EQ(eos.slope(1.0), -eos.bulk_modulus);
}

TEST(Tait, MonotoneInvertibleAndWithoutTension) {
  const TaitEos eos{2.2e9, 0.0894};
  double previous = eos.pressure(0.3);
  for (double J = 0.31; J < 1.5; J += 0.01) {
    const double p = eos.pressure(J);
    EXPECT_LT(p, previous) << "J = " << J;
    previous = p;
    EXPECT_GE(eos.pressure_no_tension(J), 0.0);
    EXPECT_NEAR(eos.volume_ratio(p), J, 1e-12);
  }
  EXPECT_EQ(eos.pressure_no_tension(1.2), 0.0);
  EXPECT_EQ(eos.pressure_no_tension(0.99), eos.pressure(0.99));
  EXPECT_NEAR(eos.sound_speed(1.0, 1000), std::sqrt(2.2e9 / 1000), 1e-9);
}

TEST(Newtonian, ParallelPlateDrag) {
  const Newtonian water(1e-3);
  const std::vector<double> w{1e-3, 2e-4}, v{0.1, -3};
  std::vector<double> k(2);
  water.drag(w, v, k);
  EXPECT_DOUBLE_EQ(k[0], 12e-3 / 1e-6);  // 12 mu / w^2
  EXPECT_DOUBLE_EQ(k[1], 12e-3 / 4e-8);
  EXPECT_THROW(Newtonian(-1), std::invalid_argument);
}

std::vector<double> random_grid(std::mt19937& rng, int cells) {
  std::uniform_real_distribution<double> spacing(0.05, 2.0);
  std::vector<double> s{0.0};
  for (int i = 0; i < cells; ++i) s.push_back(s.back() + spacing(rng));
  return s;
}

TEST(Cpdi, PartitionOfUnityZeroGradientSumAndLinearReproduction) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int spanning = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const auto nodes = random_grid(rng, 12);
    const double L = nodes.back();
    // Lengths from 1e-4 of the crack to all of it (log-uniform): up to 12 elements.
    const double l = L * std::pow(10.0, -4 * unit(rng));
    const double a = (L - l) * unit(rng), b = a + l;
    std::vector<double> w, g;
    const CpdiRange r = cpdi_weights(nodes, a, b, w, &g);
    ASSERT_EQ(w.size(), r.count);
    if (r.count > 3) ++spanning;
    double sum = 0, gsum = 0, moment = 0, gmoment = 0;
    for (std::size_t k = 0; k < r.count; ++k) {
      const double x = nodes[r.first + k] - 0.5 * (a + b);  // relative to the centre: no cancellation
      ASSERT_GE(w[k], -1e-15);
      sum += w[k];
      gsum += g[k];
      moment += w[k] * x;
      gmoment += g[k] * x;
    }
    ASSERT_NEAR(sum, 1.0, 1e-13) << "a = " << a << " b = " << b;
    ASSERT_NEAR(gsum * l, 0.0, 1e-13);
    ASSERT_NEAR(moment, 0.0, 1e-12 * L);  // sum Nbar_i s_i = s_p
    ASSERT_NEAR(gmoment, 1.0, 1e-11);     // sum Gbar_i s_i = 1
  }
  EXPECT_GT(spanning, 3000);  // many particles spanning several elements were tested
}

TEST(Cpdi, WeightsAreTheMeanOfTheHatsOverTheDomain) {
  std::mt19937 rng(5);
  const auto nodes = random_grid(rng, 8);
  // A long particle over several elements, partly beyond the tip (clamped).
  const double a = 0.3 * nodes[1], b = nodes.back() + 0.7;
  std::vector<double> w;
  const CpdiRange r = cpdi_weights(nodes, a, b, w);
  const int q = 400000;  // midpoint rule: error ~ (l/q)^2 at the hats' kinks
  std::vector<double> brute(nodes.size(), 0.0);
  for (int k = 0; k < q; ++k) {
    const HatPoint h = hat_at(nodes, a + (k + 0.5) * (b - a) / q);
    brute[h.node] += h.n0 / q;
    brute[h.node + 1] += h.n1 / q;
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double mine = i >= r.first && i < r.first + r.count ? w[i - r.first] : 0.0;
    EXPECT_NEAR(mine, brute[i], 1e-9) << "node " << i;
  }
  // The 0.7 m beyond the tip sits on the tip node: its weight exceeds 0.7 / l.
  EXPECT_GT(w.back(), 0.7 / (b - a));
}

TEST(Cpdi, ClampedBeyondTheEnds) {
  const std::vector<double> nodes{0.0, 1.0, 3.0};
  std::vector<double> w, g;
  // Wholly beyond the tip: everything on the tip node, no gradient.
  auto r = cpdi_weights(nodes, 3.5, 4.0, w, &g);
  ASSERT_EQ(r.first, 2u);
  ASSERT_EQ(r.count, 1u);
  EXPECT_DOUBLE_EQ(w[0], 1.0);
  EXPECT_DOUBLE_EQ(g[0], 0.0);
  // Half inside the last element [1, 3], half beyond: [2, 4].
  w.clear();
  g.clear();
  r = cpdi_weights(nodes, 2.0, 4.0, w, &g);
  ASSERT_EQ(r.first, 1u);
  // integral of N_1 over [2, 3] = 0.25, of N_2 = 0.75 + 1 (beyond), over l = 2
  EXPECT_DOUBLE_EQ(w[0], 0.125);
  EXPECT_DOUBLE_EQ(w[1], 0.875);
  EXPECT_DOUBLE_EQ(g[0], (0.0 - 0.5) / 2);  // (N_1(4) - N_1(2)) / l
  EXPECT_DOUBLE_EQ(g[1], (1.0 - 0.5) / 2);
  // A domain ending on a node does not touch the next hat.
  w.clear();
  r = cpdi_weights(nodes, 0.25, 1.0, w);
  EXPECT_EQ(r.first, 0u);
  EXPECT_EQ(r.count, 2u);
}

TEST(Cpdi, IntegralOfALinearFieldIsExact) {
  const std::vector<double> nodes{0.0, 0.5, 2.0, 2.1}, values{1.0, 3.0, -1.0, 4.0};
  // Over [0.25, 2.05]: trapezoids on [0.25, 0.5], [0.5, 2], [2, 2.05].
  const double expected = 0.25 * (2.0 + 3.0) / 2 + 1.5 * (3.0 - 1.0) / 2 + 0.05 * (-1.0 + 1.5) / 2;
  EXPECT_NEAR(integrate(nodes, values, 0.25, 2.05), expected, 1e-15);
  // Constant extension outside: 1 m before the mouth at values[0], 1 m beyond the tip at values[3].
  EXPECT_NEAR(integrate(nodes, values, -1.0, 0.0), 1.0, 1e-15);
  EXPECT_NEAR(integrate(nodes, values, 2.1, 3.1), 4.0, 1e-15);
  EXPECT_NEAR(interpolate(nodes, values, 1.25), 1.0, 1e-15);
}

TEST(CrackGrid, AppendsNodesAndRejectsReorderedOrMissingIds) {
  CrackGrid grid;
  auto crack = test::channel(1.0, 4, 1e-3);
  grid.set(crack, 0, 0);
  EXPECT_EQ(grid.size(), 5u);
  EXPECT_DOUBLE_EQ(grid.length(), 1.0);
  // Growth: two ids appended at the tip.
  auto grown = test::straight_crack({0, 0.25, 0.5, 0.75, 1.0, 1.1, 1.2}, std::vector<double>(7, 1e-3));
  grid.set(grown, 0, 0);
  EXPECT_EQ(grid.size(), 7u);
  EXPECT_EQ(grid.appended(), 2u);
  EXPECT_EQ(grid.ids()[6], 106u);
  // Reordered ids.
  auto swapped = grown;
  std::swap(swapped.ids[2], swapped.ids[3]);
  EXPECT_THROW(grid.set(swapped, 0, 0), std::invalid_argument);
  // A crack particle disappeared.
  auto shorter = test::channel(1.0, 4, 1e-3);
  try {
    grid.set(shorter, 0, 0);
    FAIL() << "a crack that lost crack particles was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("may not disappear"), std::string::npos) << e.what();
  }
  // Another crack id on the same solver.
  auto other = grown;
  other.crack_id = 3;
  EXPECT_THROW(grid.set(other, 0, 0), std::invalid_argument);
  // The grid is unchanged by the rejected calls.
  EXPECT_EQ(grid.size(), 7u);
}

TEST(CrackGrid, RejectsBadGeometryAndAppliesThePreOpening) {
  CrackGrid grid;
  EXPECT_THROW(grid.set(test::straight_crack({0.0}, {1e-3}), 0, 0), std::invalid_argument);
  EXPECT_THROW(grid.set(test::straight_crack({0.0, 0.5, 0.5}, {1e-3, 1e-3, 0}), 0, 0), std::invalid_argument);
  EXPECT_THROW(grid.set(test::straight_crack({0.0, 0.5, 1.0}, {1e-3, -1e-6, 0}), 0, 0), std::invalid_argument);
  // A 1e-4 m pre-opening over the first 0.3 m is added to nodes 0 and 1 (to
  // an open node too: the fluid's width always follows the crack's).
  grid.set(test::straight_crack({0.0, 0.25, 0.5, 0.75}, {0, 2e-4, 0, 0}), 1e-4, 0.3);
  EXPECT_DOUBLE_EQ(grid.width()[0], 1e-4);
  EXPECT_DOUBLE_EQ(grid.width()[1], 3e-4);
  EXPECT_DOUBLE_EQ(grid.width()[2], 0.0);
  EXPECT_DOUBLE_EQ(grid.crack_width()[0], 0.0);
  EXPECT_DOUBLE_EQ(grid.width_integral(0, 0.25), 0.25 * 2e-4);
  // A node keeps its pre-opening when the crack's stretching carries it past
  // pre_opening_length, and a node that first appears beyond it never has
  // one: the extra width is the node's own, fixed when it appears (decided
  // anew at every exchange, the tip node of layered-ci's pre-opened notch
  // lost it to a stretch of 4e-9 m, and the fluid in its element was
  // squeezed to 10 GPa in one step).
  CrackGrid stretched;
  stretched.set(test::straight_crack({0.0, 0.25, 0.5, 0.75}, {0, 2e-4, 0, 0}), 1e-4, 0.5);
  EXPECT_DOUBLE_EQ(stretched.width()[2], 1e-4);
  stretched.set(test::straight_crack({0.0, 0.25, 0.5 + 1e-9, 0.75 + 1e-9}, {0, 2e-4, 0, 0}), 1e-4, 0.5);
  EXPECT_DOUBLE_EQ(stretched.width()[2], 1e-4);
  EXPECT_DOUBLE_EQ(stretched.width()[3], 0.0);
  auto longer = test::straight_crack({0.0, 0.25, 0.5, 0.75, 0.9}, {0, 2e-4, 0, 0, 0});
  stretched.set(longer, 1e-4, 1.0);  // appended, and the length (here changed) is read for it alone
  EXPECT_DOUBLE_EQ(stretched.width()[3], 0.0);
  EXPECT_DOUBLE_EQ(stretched.width()[4], 1e-4);
  CrackGrid shrinking;  // and a node carried back inside the length does not gain one
  shrinking.set(test::straight_crack({0.0, 0.25, 0.5, 0.75}, {0, 0, 0, 0}), 1e-4, 0.6);
  shrinking.set(test::straight_crack({0.0, 0.2, 0.4, 0.55}, {0, 0, 0, 0}), 1e-4, 0.6);
  EXPECT_DOUBLE_EQ(shrinking.width()[3], 0.0);
  // A virtual opening is added everywhere, on top of the pre-opening.
  CrackGrid film;
  film.set(test::straight_crack({0.0, 0.25, 0.5, 0.75}, {0, 2e-4, 0, 0}), 1e-4, 0.3, 1e-5);
  EXPECT_DOUBLE_EQ(film.width()[0], 1.1e-4);
  EXPECT_DOUBLE_EQ(film.width()[1], 3.1e-4);
  EXPECT_DOUBLE_EQ(film.width()[3], 1e-5);
  // Points on a bent polyline by arc length.
  auto bent = test::straight_crack({0.0, 1.0, 2.0}, {1e-3, 1e-3, 0}, 0, 7);
  bent.position[2] = Vec2(1, 1);
  CrackGrid g2;
  g2.set(bent, 0, 0);
  EXPECT_NEAR((g2.point_at(1.5) - Vec2(1, 0.5)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((g2.point_at(-1) - Vec2(0, 0)).norm(), 0.0, 1e-15);
}

TEST(FlowRateInlet, ClosedMouthWithoutPreOpeningIsAClearError) {
  FluidConfig c;
  c.inlet.flow_rate = TimeFunction::constant(1e-4);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(1.0, 10, 0.0));
  try {
    fluid.step(1e-6);
    FAIL() << "fluid entered a closed crack without a pre-opening";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pre_opening"), std::string::npos) << e.what();
  }
}

TEST(PressureInlet, ClosedMouthWithoutPreOpeningIsAClearError) {
  FluidConfig c;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(1e6);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(1.0, 10, 0.0));
  EXPECT_THROW(fluid.step(1e-6), std::invalid_argument);
  // With a pre-opening the fluid enters.
  c.inlet.pre_opening = 1e-5;
  FluidSolver opened(c);
  opened.set_crack(test::channel(1.0, 10, 0.0));
  opened.step(1e-6);
  EXPECT_EQ(opened.particles().size(), 1u);
  EXPECT_GT(opened.fluid_mass(), 0.0);
  EXPECT_EQ(opened.fluid_mass(), opened.injected_mass());
}

TEST(FluidSolver, RejectsReorderedIdsAndBadConfig) {
  FluidConfig c;
  FluidSolver fluid(c);
  auto crack = test::channel(1.0, 10, 1e-3);
  fluid.set_crack(crack);
  std::swap(crack.ids[1], crack.ids[2]);
  EXPECT_THROW(fluid.set_crack(crack), std::invalid_argument);
  FluidConfig bad;
  bad.cfl = 1.5;
  EXPECT_THROW(FluidSolver{bad}, std::invalid_argument);
  bad = FluidConfig{};
  bad.bulk_modulus = 0;
  EXPECT_THROW(FluidSolver{bad}, std::invalid_argument);
}

// -dp/dw at each node against a finite difference: a channel filled at
// 1e5 Pa (K = 2 MPa), every width widened by 1e-7 of itself, one step of
// 1e-12 s (nothing moves; the state is recomputed). For a uniform change of
// width the reported stiffness is exact (the row sum of dp_i/dw_j): the
// difference quotient must match it to the curvature of the Tait law over the
// step, ~1e-6 relative; held to 1e-4. The mouth of a pressure inlet holds its
// pressure: stiffness 0 there.
TEST(FluidSolver, ReportsTheStiffnessOfItsPressureToTheCrackWidth) {
  for (const auto kind : {InletConfig::Kind::FlowRate, InletConfig::Kind::Pressure}) {
    FluidConfig c;
    c.bulk_modulus = 2e6;
    c.viscosity = 0.01;
    c.inlet.kind = kind;
    c.inlet.flow_rate = TimeFunction::constant(0);
    c.inlet.pressure = TimeFunction::constant(1e5);
    const double w = 1e-3;
    FluidSolver fluid(c);
    fluid.set_crack(test::channel(1.0, 20, w));
    fluid.fill(1.0, 1e5);
    fluid.step(1e-12);
    const auto p0 = fluid.nodal_pressure();
    const auto s0 = fluid.nodal_stiffness();
    const double dw = 1e-7 * w;
    fluid.set_crack(test::channel(1.0, 20, w + dw));
    fluid.step(1e-12);
    const auto p1 = fluid.nodal_pressure();
    for (std::size_t i = 1; i + 1 < p0.size(); ++i) {
      const double measured = -(p1[i] - p0[i]) / dw;
      EXPECT_NEAR(s0[i] / measured, 1, 1e-4) << "node " << i;
    }
    // K_t J / w at 1e5 Pa: K e^{(1 - J)/c} J / w.
    const double J = fluid.eos().volume_ratio(1e5);
    EXPECT_NEAR(s0[10], -fluid.eos().slope(J) * J / w, 1e-9 * s0[10]);
    if (kind == InletConfig::Kind::Pressure)
      EXPECT_EQ(s0[0], 0.0);
    else
      EXPECT_GT(s0[0], 0.0);
  }
}

// The coupling-lag diagnostic: fluid injected into a crack held at a fixed
// width has nowhere to go but into compression. The inlet injects Q for
// 0.3 s and stops by 0.4 s (a table); by T = 1 s the pressure has equalised
// (diffusion time L^2 / (K w^2 / 12 mu) = 0.06 s here, so 10 of them after
// the inlet stopped), and the rise at every wetted node is the Tait pressure
// of the whole mass in the fixed volume less the fill pressure. A new
// set_crack() starts the count again.
TEST(FluidSolver, FrozenWidthRiseIsThePressureTheInflowBuilt) {
  FluidConfig c;
  c.bulk_modulus = 2e6;
  c.viscosity = 1;
  const double Q = 1e-6, L = 0.1, w = 1e-3, p0 = 1e5, T = 1;
  c.inlet.flow_rate = TimeFunction::table({0, 0.3, 0.4}, {Q, Q, 0});
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(L, 10, w));
  fluid.fill(L, p0);
  EXPECT_EQ(fluid.frozen_width_rise(), 0.0);
  const double mass0 = fluid.fluid_mass();
  fluid.advance(T);
  const double injected = Q * 0.35;  // m^2 at zero pressure: the integral of the table
  // The inlet's quadrature is exact but at the table's kinks (5e-9 of it here).
  EXPECT_NEAR(fluid.injected_volume(), injected, 1e-6 * injected);
  const double J = c.density * L * w / (mass0 + c.density * fluid.injected_volume());
  const double expected = fluid.eos().pressure_no_tension(J) - p0;
  // Uniform to the residual of the diffusion, e^-10 (5e-5) of the gradient
  // the inflow drove (12 mu Q L / w^3 = 1.2 kPa, 4% of the rise): 1e-5 of the rise.
  EXPECT_NEAR(fluid.frozen_width_rise(), expected, 1e-5 * expected);
  EXPECT_GT(expected, 0.2 * c.bulk_modulus * injected / (L * w));  // a real rise: about K dV / V
  fluid.set_crack(test::channel(L, 10, w));
  EXPECT_EQ(fluid.frozen_width_rise(), 0.0);
}

// A fluid compressed past 100 times its bulk modulus stops the run with a
// message, not a pressure that goes on (a failed coupled solve once reported
// 1e13 Pa of water and the run ended "completed"): a closed channel full of
// fluid at 0.9 K (J = 0.785) has its walls squeezed to 0.3 of their width
// (J = 0.24, p = 460 K).
TEST(FluidSolver, CompressionPastTheBulkModulusIsAnError) {
  FluidConfig c;
  c.bulk_modulus = 2e6;
  c.inlet.flow_rate = TimeFunction::constant(0);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(1.0, 20, 1e-3));
  EXPECT_THROW(fluid.fill(1.0, 2.1e6), std::invalid_argument);
  fluid.fill(1.0, 1.8e6);
  fluid.step(1e-6);  // at 0.9 K: allowed
  fluid.set_crack(test::channel(1.0, 20, 0.3e-3));
  try {
    fluid.step(1e-6);
    FAIL() << "no error at J = 0.24";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("above 100 times its bulk modulus 2e+06 Pa"), std::string::npos) << what;
    EXPECT_NE(what.find("has failed"), std::string::npos) << what;
  }
}

// A closed far end (no outlet) is a wall even where a virtual opening keeps
// the tip node open for the fluid: a flow-rate inlet fills the channel, and
// no particle may end beyond the last node (before the wall, particles ran
// past the tip, beyond the grid).
TEST(FluidSolver, ClosedFarEndIsAWallEvenWithAVirtualOpening) {
  FluidConfig c;
  c.bulk_modulus = 2e6;
  c.viscosity = 1e-3;
  c.inlet.flow_rate = TimeFunction::constant(1e-4);
  c.virtual_opening = 2e-5;
  FluidSolver fluid(c);
  auto crack = test::channel(0.2, 8, 0.0);  // closed but for the virtual film
  crack.width.assign(crack.width.size(), 1e-3);
  crack.width.back() = 0;  // the tip
  fluid.set_crack(crack);
  const double dt = 0.5 * fluid.stable_dt();
  // 0.2 m x ~1 mm holds ~1e-4 m^2: inject twice that.
  for (double t = 0; t < 2.0; t += dt) {
    fluid.step(dt);
    ASSERT_LE(fluid.particles().end(fluid.particles().size() - 1), 0.2 * (1 + 1e-9)) << "t = " << t;
  }
  EXPECT_NEAR(fluid.fluid_mass() / fluid.injected_mass(), 1, 1e-12);
  EXPECT_GT(fluid.inlet_pressure(), 1e5);  // the full crack is being compressed
}

// merge_fraction: particles squeezed along the crack are merged with a
// neighbour. A channel with a wall at the far end is filled against the wall
// (the particles near it are compressed along the crack): with merging on,
// after every step no particle but the inlet one is shorter than
// merge_fraction x particle_length, mass stays exactly the injected mass,
// and the stable step is at least cfl x that length / the sound speed. The
// same run without merging has shorter particles (the case merging is for).
TEST(FluidSolver, MergesParticlesSqueezedAlongTheCrack) {
  double shortest_without = 0;
  constexpr double kFraction = 0.75;
  for (const double fraction : {0.0, kFraction}) {
    FluidConfig c;
    c.bulk_modulus = 2e6;
    c.viscosity = 1e-3;
    c.particle_length = 0.0125;
    c.merge_fraction = fraction;
    c.inlet.flow_rate = TimeFunction::constant(2e-4);
    FluidSolver fluid(c);
    auto crack = test::channel(0.2, 8, 1e-3);
    crack.width.back() = 0;  // the tip: a wall
    fluid.set_crack(crack);
    double shortest = 1;
    for (int k = 0; fluid.time() < 1.5; ++k) {  // 0.2 m x 1 mm holds the injection of 1 s
      fluid.step(0.5 * fluid.stable_dt());
      const auto& P = fluid.particles();
      for (std::size_t p = 1; p < P.size(); ++p) {
        shortest = std::min(shortest, P.length[p]);
        if (fraction > 0) {
          ASSERT_GE(P.length[p], fraction * c.particle_length * (1 - 1e-12)) << "step " << k;
        }
        ASSERT_NEAR(P.end(p - 1), P.start(p), 1e-12) << "particles stay contiguous, step " << k;
      }
      ASSERT_NEAR(fluid.fluid_mass() / fluid.injected_mass(), 1, 1e-12) << "step " << k;
    }
    if (fraction == 0) {
      shortest_without = shortest;
    } else {
      EXPECT_LT(shortest_without, kFraction * c.particle_length) << "the case merging is for did not arise";
      double speed = std::sqrt(c.bulk_modulus / c.density);
      for (std::size_t p = 0; p < fluid.particles().size(); ++p)
        speed = std::max(speed, fluid.eos().sound_speed(fluid.particles().jacobian(p), c.density));
      const double inlet_length = fluid.particles().length[0];
      EXPECT_GE(fluid.stable_dt() * (1 + 1e-12),
                c.cfl * std::min({fraction * c.particle_length, inlet_length, 0.2 / 8}) / speed);
    }
  }
}

// Merging keeps the mass exactly and the fluid's extent (the merged particle
// spans its parts).
TEST(FluidSolver, MergingKeepsMassAndExtent) {
  FluidConfig c;
  c.bulk_modulus = 2e6;
  c.particle_length = 0.05;
  c.merge_fraction = 1.9;  // the 0.05 m particles are short; merged pairs (0.1 m) are not
  c.inlet.flow_rate = TimeFunction::constant(0);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(1.0, 20, 1e-3));
  fluid.fill(0.5, 1e5);
  const double mass = fluid.fluid_mass();
  ASSERT_GT(fluid.particles().size(), 2u);
  fluid.step(1e-9);
  // Ten 0.05 m particles: the inlet particle stays, the nine others merge
  // into four of at least 0.095 m (pairs, and one triple).
  ASSERT_EQ(fluid.particles().size(), 5u);
  double total = 0;
  for (std::size_t p = 0; p < 5; ++p) {
    total += fluid.particles().length[p];
    if (p > 0) {
      EXPECT_GE(fluid.particles().length[p], 1.9 * 0.05) << p;
    }
  }
  EXPECT_NEAR(total, 0.5, 1e-6);
  EXPECT_NEAR(fluid.fluid_mass(), mass, 1e-14 * mass);
  EXPECT_NEAR(fluid.particles().end(fluid.particles().size() - 1), 0.5, 1e-6);
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
