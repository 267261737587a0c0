// Crack growth: the onset load of an edge crack under slowly rising tension
// against the handbook (J_Ic reached), growth straight ahead in mode I, the
// waits a tip keeps, and a pressurised crack in the stiffer of two bonded
// layers turning towards the softer one. What a grown crack is afterwards
// (its opening against a cut one's, a step's load released over time):
// grown_crack_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "fracture_setup.hpp"

namespace hfmpm::solid::mpm {
namespace {

// Edge crack a/W = 0.3 in a strip (half-height 1.5 W, h = W/40) pulled by
// sigma(t) rising linearly; growth when J >= J_Ic. The handbook onset load is
//   sigma_c = sqrt(E' J_Ic) / (F sqrt(pi a)),   F = 1.6551 (Tada).
// The ramp reaches sigma_c after 30 P-wave transits of the strip (quasi-static:
// the damped response lags the load by about 2%). Measured: growth starts at
// sigma = 1.041 sigma_c, where the computed J is 1.012 J_Ic; the handbook J
// there is 1.084 J_Ic: 1.7% of the load is the discretization (K from J is
// 1.7% low at this grid) and the rest the lag. So K at onset is within 5% of
// K_Ic, and J within 8.4% of J_Ic (the 5% on J is met by the computed
// J, not by the handbook J at this grid and ramp rate). The crack grows
// straight: the new particles lie within 1.5e-4 h of the crack line.
TEST(Propagation, EdgeCrackStartsAtToughnessAndGrowsStraight) {
  constexpr double kW = 1, kA = 0.3, kH = 1.5 * kW, kToughness = 500;  // J/m^2
  const double e_prime = kRock.plane_strain_modulus();
  const double sigma_c = std::sqrt(e_prime * kToughness) / (tada_edge_factor(kA / kW) * std::sqrt(kPi * kA));
  const double transit = 2 * kH / kRock.p_wave_speed(kRock.density);
  const double ramp_time = 30 * transit;
  auto config = edge_crack(kW, kA, kH, 40, TimeFunction::table({0, ramp_time}, {0, sigma_c}));
  // The table is constant after its end: extend the ramp's slope to 1.5 sigma_c.
  config.tractions[0].normal = config.tractions[1].normal =
      TimeFunction::table({0, 1.5 * ramp_time}, {0, 1.5 * sigma_c});
  config.materials[0].toughness = kToughness;
  config.fracture.propagate = true;
  config.fracture.check_interval = 10;
  Solver solid(config);
  const std::size_t initial = solid.cracks()[0].size();
  const double dt = solid.stable_dt();
  double onset = -1;
  while (solid.time() < 1.5 * ramp_time && solid.cracks()[0].size() < initial + 6) {
    solid.step(dt);
    if (onset < 0 && solid.cracks()[0].size() > initial) onset = solid.time();
  }
  ASSERT_GT(onset, 0) << "the crack never grew";
  const double sigma_onset = sigma_c * onset / ramp_time;
  const double j_handbook = std::pow(sigma_onset / sigma_c, 2) * kToughness;
  std::printf(
      "edge crack growth onset at sigma = %.4f sigma_c: handbook J there %.4f J_Ic; J computed at onset %.4f J_Ic\n",
      sigma_onset / sigma_c, j_handbook / kToughness, solid.last_tips().at(0).j / kToughness);
  // The criterion fires when the computed J reaches J_Ic (not later: the
  // check interval and the load step are small), and physically at the
  // handbook load: K at onset within 5% of K_Ic = sqrt(E' J_Ic).
  EXPECT_NEAR(solid.last_tips().at(0).j / kToughness, 1, 0.05);
  EXPECT_NEAR(sigma_onset / sigma_c, 1, 0.05);
  const auto& crack = solid.cracks()[0];
  double worst = 0;
  for (std::size_t k = initial; k < crack.size(); ++k) worst = std::max(worst, std::abs(crack.plane()[k].y()));
  std::printf("grew %zu particles to x = %.4f m; largest distance from the crack line %.3e h\n", crack.size() - initial,
              crack.plane().back().x(), worst / solid.grid().h);
  EXPECT_EQ(crack.size(), initial + 6);
  EXPECT_LT(worst, 1e-3 * solid.grid().h);
  EXPECT_GT(crack.plane().back().x(), kA + 2.5 * solid.grid().h);
}

// The edge crack of the test above (a/W = 0.3, h = W/20) under a load held
// at 1.5 sigma_c (J well above J_Ic), checked for growth every 5 steps.
constexpr double kDrivenA = 0.3, kDrivenH = 1.5;
SolidConfig driven_edge_crack() {
  constexpr double kW = 1, kToughness = 500;
  const double e_prime = kRock.plane_strain_modulus();
  const double sigma_c =
      std::sqrt(e_prime * kToughness) / (tada_edge_factor(kDrivenA / kW) * std::sqrt(kPi * kDrivenA));
  auto config = edge_crack(kW, kDrivenA, kDrivenH, 20, TimeFunction::constant(1.5 * sigma_c));
  config.materials[0].toughness = kToughness;
  config.fracture.propagate = true;
  config.fracture.check_interval = 5;
  return config;
}

// Zero toughness (a material that holds no crack; the builder's K_Ic = 0, the
// M-vertex's own problem): growth needs energy released, J > 0, not only J >=
// J_Ic. Unloaded, the edge crack's J is exactly 0 and it must stay as it is
// over three P-wave transits of the strip; under a load of a hundredth of the
// 500 J/m^2 crack's onset load (J about 1e-4 of that crack's J_Ic) it grows as
// soon as the load's wave has reached the tip and J turned positive.
TEST(Propagation, ZeroToughnessGrowsOnlyWhereEnergyIsReleased) {
  for (const double load : {0.0, 0.01}) {
    auto config = driven_edge_crack();
    const double sigma = load * config.tractions[0].normal(0) / 1.5;
    config.tractions[0].normal = config.tractions[1].normal = TimeFunction::constant(sigma);
    config.materials[0].toughness = 0;
    Solver solid(config);
    const std::size_t initial = solid.cracks()[0].size();
    const double dt = solid.stable_dt();
    const double transit = 2 * kDrivenH / kRock.p_wave_speed(kRock.density);
    while (solid.time() < 3 * transit && solid.cracks()[0].size() == initial) solid.step(dt);
    ASSERT_FALSE(solid.last_tips().empty());
    if (load == 0) {
      EXPECT_EQ(solid.last_tips().at(0).j, 0) << "no load, no energy";
      EXPECT_EQ(solid.cracks()[0].size(), initial) << "an unloaded crack grew";
    } else {
      EXPECT_GT(solid.last_tips().at(0).j, 0);
      EXPECT_GT(solid.cracks()[0].size(), initial) << "a loaded crack in a material with no toughness did not grow";
    }
  }
}

// fracture.max_lag_cells (the zero-lag closure of fluid-driven cracks): the
// same edge crack under a load held at 1.5 sigma_c (J well above J_Ic) does
// not grow while the fluid front reported on it lies more than max_lag_cells
// cells behind the tip, and grows once the front is within that distance
// (at the next check: the settling wait after the front's arrival, tested
// below, is off here).
TEST(Propagation, TipWaitsForTheFluidFrontWithMaxLag) {
  auto config = driven_edge_crack();
  config.fracture.max_lag_cells = 0.5;
  config.fracture.front_settle_transits = 0;
  Solver solid(config);
  const double h = solid.grid().h, dt = solid.stable_dt();
  const std::size_t initial = solid.cracks()[0].size();
  solid.set_crack_front(0, 0.0, kDrivenA - 0.6 * h);  // 0.6 cells of dry crack: too far
  const double transit = 2 * kDrivenH / kRock.p_wave_speed(kRock.density);
  while (solid.time() < 3 * transit) solid.step(dt);
  ASSERT_FALSE(solid.last_tips().empty());
  EXPECT_GT(solid.last_tips().at(0).j, 1.5 * solid.config().materials[0].toughness) << "the load must drive growth";
  EXPECT_EQ(solid.cracks()[0].size(), initial) << "grew with the fluid front 0.6 cells behind the tip";
  solid.set_crack_front(0, 0.0, kDrivenA - 0.4 * h);  // within half a cell: may grow
  for (int k = 0; k < 10 && solid.cracks()[0].size() == initial; ++k) solid.step(dt);
  EXPECT_EQ(solid.cracks()[0].size(), initial + 1);
}

// Straight growth finer than half a cell (fracture.growth_cells 0.25): the
// tip advances by growth_cells h at every growth step, but a tip segment
// shorter than half a cell is lengthened instead of followed by a new crack
// particle, so no two crack particles end up closer than half a cell (the
// faces' opening is linear within a cell; a fluid pressure per quarter cell
// has modes the faces cannot resist: docs/solid.md). Before this rule every
// step added a particle a quarter cell ahead. With the fluid front held at
// the start of the tip segment, at most half a cell behind the tip, the
// crack keeps growing under max_lag_cells 0.25: the wait for the fluid allows
// the tip segment, up to half a cell, as lag (the fluid need not enter the
// segment that closes at the tip; without that allowance the KGD crack
// stalled; beyond half a cell the allowance grew with each step).
TEST(Propagation, StraightQuarterCellGrowthKeepsCrackParticlesHalfACellApart) {
  auto config = driven_edge_crack();
  config.fracture.straight = true;
  config.fracture.growth_cells = 0.25;
  config.fracture.max_lag_cells = 0.25;
  Solver solid(config);
  const double h = solid.grid().h, dt = solid.stable_dt();
  const std::size_t initial = solid.cracks()[0].size();
  std::vector<double> tips{solid.cracks()[0].plane().back().x()};
  const double transit = 2 * kDrivenH / kRock.p_wave_speed(kRock.density);
  while (solid.time() < 6 * transit && tips.size() < 9) {
    const auto& line = solid.cracks()[0].plane();
    const double length = (line.back() - line[0]).norm(), segment = (line.back() - line[line.size() - 2]).norm();
    solid.set_crack_front(0, 0.0, length - std::min(segment, 0.5 * h));  // the fluid at the tip segment's start
    solid.step(dt);
    const double tip = solid.cracks()[0].plane().back().x();
    if (tip > tips.back() + 0.1 * h) tips.push_back(tip);
  }
  ASSERT_EQ(tips.size(), 9u) << "the crack must grow 8 times";
  for (std::size_t k = 1; k < tips.size(); ++k) {
    EXPECT_NEAR(tips[k] - tips[k - 1], 0.25 * h, 1e-3 * h) << "growth step " << k;
  }
  const auto& plane = solid.cracks()[0].plane();
  std::printf("8 growth steps of a quarter cell added %zu crack particles; segments (cells):", plane.size() - initial);
  for (std::size_t k = initial - 1; k < plane.size(); ++k) std::printf(" %.3f", (plane[k] - plane[k - 1]).norm() / h);
  std::printf("\n");
  EXPECT_EQ(plane.size(), initial + 4);
  for (std::size_t k = 1; k + 1 < plane.size(); ++k) {
    EXPECT_GE((plane[k] - plane[k - 1]).norm(), 0.5 * h * (1 - 1e-3)) << "segment " << k;
  }
  EXPECT_LE((plane.back() - plane[plane.size() - 2]).norm(), 0.625 * h);
}

// settle_transits: after a tip grows it waits settle_transits x L / c_s (L the
// crack's length, c_s the shear-wave speed) before it may grow again. The
// edge crack of the test above under 1.5 sigma_c grows at every check
// without the wait (steps 5 apart); with settle_transits 1 the gaps between
// growth steps are at least L / c_s and at most that plus a check interval.
TEST(Propagation, GrownTipWaitsSettleTransitsBeforeGrowingAgain) {
  constexpr double kW = 1, kA = 0.3, kH = 1.5 * kW, kToughness = 500;
  const double e_prime = kRock.plane_strain_modulus();
  const double sigma_c = std::sqrt(e_prime * kToughness) / (tada_edge_factor(kA / kW) * std::sqrt(kPi * kA));
  auto growth_times = [&](double settle) {
    auto config = edge_crack(kW, kA, kH, 20, TimeFunction::constant(1.5 * sigma_c));
    config.materials[0].toughness = kToughness;
    config.fracture.propagate = true;
    config.fracture.check_interval = 5;
    config.fracture.settle_transits = settle;
    Solver solid(config);
    const double dt = solid.stable_dt();
    std::vector<std::pair<double, double>> grown;  // (time, crack length before)
    std::size_t size = solid.cracks()[0].size();
    const double transit = 2 * kH / kRock.p_wave_speed(kRock.density);
    while (solid.time() < 6 * transit && grown.size() < 4) {
      const double length = solid.cracks()[0].plane().back().x();
      solid.step(dt);
      if (solid.cracks()[0].size() > size) grown.emplace_back(solid.time(), length);
      size = solid.cracks()[0].size();
    }
    return std::make_pair(grown, dt);
  };
  const double c_s = std::sqrt(kRock.shear_modulus() / kRock.density);
  const auto [eager, dt] = growth_times(0);
  ASSERT_GE(eager.size(), 3u);
  EXPECT_NEAR(eager[2].first - eager[1].first, 5 * dt, 1e-9 * dt) << "without the wait: every check";
  const auto [settled, dt2] = growth_times(1);
  ASSERT_GE(settled.size(), 3u) << "the settled crack must still grow";
  for (std::size_t k = 1; k < settled.size(); ++k) {
    const double gap = settled[k].first - settled[k - 1].first;
    const double wait = settled[k].second / c_s;  // the crack's length after the previous growth
    std::printf("growth %zu: %.3e s after the previous one; the wait L / c_s is %.3e s\n", k, gap, wait);
    EXPECT_GE(gap, wait - 1e-12);
    EXPECT_LE(gap, wait + 5 * dt2 + 1e-12);
  }
}

// front_settle_transits: with the zero-lag wait, a tip that kinks (maximum
// hoop stress) grows only after 4 shear-wave transits of its J domain
// (outer_cells h / c_s) have passed since the fluid front came within reach;
// a straight tip grows at the first check. The edge crack above under
// 1.5 sigma_c (J well above J_Ic from the start) with its fluid front held
// at a tenth of the notch: no growth (the zero-lag wait). At t_a the front
// moves to the tip: the kinking tip's first growth comes at least the wait
// after t_a and at most the wait plus two check intervals (the arrival is
// seen at the first check after t_a, growth at the first check after the
// wait); without the wait, and for a straight tip, within one check interval.
TEST(Propagation, KinkingTipWaitsForTheFieldAfterTheFluidFrontArrives) {
  constexpr double kW = 1, kA = 0.3, kH = 1.5 * kW, kToughness = 500;
  constexpr int kCheck = 5;
  const double e_prime = kRock.plane_strain_modulus();
  const double sigma_c = std::sqrt(e_prime * kToughness) / (tada_edge_factor(kA / kW) * std::sqrt(kPi * kA));
  struct FirstGrowth {
    double arrival = 0, growth = -1, dt = 0, wait = 0;
  };
  auto first_growth = [&](double settle, bool straight) {
    auto config = edge_crack(kW, kA, kH, 20, TimeFunction::constant(1.5 * sigma_c));
    config.materials[0].toughness = kToughness;
    config.fracture.propagate = true;
    config.fracture.check_interval = kCheck;
    config.fracture.max_lag_cells = 0.5;
    config.fracture.straight = straight;
    config.fracture.front_settle_transits = settle;
    Solver solid(config);
    FirstGrowth out;
    out.dt = solid.stable_dt();
    out.wait = settle * config.fracture.outer_cells * config.grid.h / std::sqrt(kRock.shear_modulus() / kRock.density);
    const double transit = 2 * kH / kRock.p_wave_speed(kRock.density);
    const std::size_t size = solid.cracks()[0].size();
    solid.set_crack_front(0, 0.0, 0.1 * kA);
    while (solid.time() < 2 * transit) solid.step(out.dt);
    EXPECT_EQ(solid.cracks()[0].size(), size) << "grew with the front far behind the tip";
    out.arrival = solid.time();
    solid.set_crack_front(0, 0.0, kA);
    while (solid.time() < out.arrival + out.wait + 10 * kCheck * out.dt) {
      solid.step(out.dt);
      if (solid.cracks()[0].size() > size) {
        out.growth = solid.time();
        break;
      }
    }
    return out;
  };
  const FirstGrowth waited = first_growth(4, false), eager = first_growth(0, false), straight = first_growth(4, true);
  std::printf(
      "first growth after the front's arrival: %.3e s kinking with the wait (wait %.3e s), %.3e s without, "
      "%.3e s straight; check interval %.3e s\n",
      waited.growth - waited.arrival, waited.wait, eager.growth - eager.arrival, straight.growth - straight.arrival,
      kCheck * waited.dt);
  ASSERT_GT(waited.wait, 10 * kCheck * waited.dt) << "the wait must span several checks to be seen";
  ASSERT_GE(waited.growth, 0) << "the kinking tip never grew";
  EXPECT_GE(waited.growth - waited.arrival, waited.wait - 1e-12);
  EXPECT_LE(waited.growth - waited.arrival, waited.wait + 2 * kCheck * waited.dt + 1e-12);
  ASSERT_GE(eager.growth, 0);
  EXPECT_LE(eager.growth - eager.arrival, kCheck * eager.dt + 1e-12);
  ASSERT_GE(straight.growth, 0);
  EXPECT_LE(straight.growth - straight.arrival, kCheck * straight.dt + 1e-12);
}

// A pressurised edge crack in the stiffer of two bonded layers, parallel to
// the interface and a few cells below it, turns towards the softer layer
// (cracks are drawn to compliant material: the mismatch gives K_II of the
// sign that kinks the tip towards the soft side). Asserted: the kink angles
// at growth are positive (counter-clockwise, towards the soft layer above) and
// the tip ends above the starting line.
TEST(Propagation, CrackInStiffLayerTurnsTowardsSoftLayer) {
  constexpr double kL = 2, kDepth = 0.1, kLength = 0.4, kToughness = 200;
  const double h = kL / 64;
  SolidConfig c;
  c.grid.origin = Vec2(-2 * h, -kL / 2 - 2 * h);
  c.grid.h = h;
  c.grid.nx = c.grid.ny = 68;
  const Material stiff{"stiff", 4e10, 0.25, 2500, kToughness};
  const Material soft{"soft", 1e10, 0.25, 2500, kToughness};
  c.materials = {stiff, soft};
  Region lower, upper;
  lower.kind = upper.kind = Region::Kind::Layer;
  lower.lo = Vec2(0, -kL / 2);
  lower.hi = Vec2(kL, 0);
  lower.material = 0;
  upper.lo = Vec2(0, 0);
  upper.hi = Vec2(kL, kL / 2);
  upper.material = 1;
  c.regions = {lower, upper};
  CrackSpec crack;
  // On a cell-centre line, so that no node lies on the crack.
  const double y0 = -kDepth - h / 2;
  const int segments = static_cast<int>(std::lround(2 * kLength / h));
  for (int k = 0; k <= segments; ++k) crack.points.emplace_back(kLength * k / segments, y0);
  c.cracks = {crack};
  c.fracture.propagate = true;
  c.fracture.check_interval = 20;
  const double c_p = stiff.p_wave_speed(stiff.density);
  c.damping.grid_alpha = 2 * kPi * c_p / (4 * kL);
  c.threads = 2;
  Solver solid(c);
  const std::size_t initial = solid.cracks()[0].size();
  // Pressure for K_I ~ 1.12 p sqrt(pi a) = sqrt(E' J_Ic), reached after 20 transits.
  const double p_c = std::sqrt(stiff.plane_strain_modulus() * kToughness) / (1.12 * std::sqrt(kPi * kLength));
  const double ramp_time = 20 * kL / c_p;
  const double dt = solid.stable_dt();
  double kink_sum = 0;
  int checks = 0;
  while (solid.time() < 3 * ramp_time && solid.cracks()[0].size() < initial + 10) {
    const double p = 2 * p_c * solid.time() / ramp_time;
    solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), p));
    const std::size_t before = solid.cracks()[0].size();
    solid.step(dt);
    if (solid.cracks()[0].size() > before) {
      kink_sum += solid.last_tips().at(0).kink;
      ++checks;
    }
  }
  const auto& cr = solid.cracks()[0];
  const double rise = cr.plane().back().y() - y0;
  std::printf(
      "layered: grew %zu particles, tip at (%.4f, %.4f) m, rise %.3f h towards the soft layer, mean kink %.2f deg\n",
      cr.size() - initial, cr.plane().back().x(), cr.plane().back().y(), rise / h,
      checks ? kink_sum / checks * 180 / kPi : 0.0);
  ASSERT_GE(cr.size(), initial + 8) << "the crack did not grow";
  EXPECT_GT(kink_sum / checks, 0) << "the tip turned away from the soft layer";
  EXPECT_GT(rise, 0.05 * h);
}

}  // namespace
}  // namespace hfmpm::solid::mpm

namespace hfmpm::solid::mpm {
namespace {}  // namespace
}  // namespace hfmpm::solid::mpm
