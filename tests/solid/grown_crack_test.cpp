// A grown crack against a cut one (issue 17's growth step): the opening of a
// crack grown to a length against a crack cut at that length from the start,
// read from the material and from the crack surfaces, and a growth step
// whose face load is applied over time (fracture.release_transits) ending
// where the step loaded at once does. The onset and the waits of growth:
// propagation_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fracture_setup.hpp"

namespace hfmpm::solid::mpm {
namespace {

// A crack grown to a length must open as a crack cut at that length from the
// start: the static state of a linear-elastic body does not depend on how its
// crack got there. The edge crack of propagation_test.cpp (h = W/20, tension at half the onset
// load, so J stays below J_Ic) is grown from a = 0.3 W by four half-cell
// steps to 0.4 W (growth forced through the zero-lag wait) and compared,
// after 20 damped transits, with a crack cut at 0.4 W. Two openings per crack
// particle: the crack particles' surfaces (what the fluid sees) and the
// material's, the displacement of the nearest particle on each side
// extrapolated to the crack particle with its displacement gradient.
// Compared from 1.5 cells behind the tip (the grown part is the last two
// cells; the particle half a cell from the tip is left out).
struct OpeningProfile {
  std::vector<double> x, surfaces, material;
  double j = 0;  // J at the tip, J/m^2
};

// pressurised: the load is a face pressure equal to the tension (the edges
// free) instead of the tension.
OpeningProfile edge_crack_opening(double a, bool grow, bool between_rows, bool from_material = false,
                                  bool reproject = true, bool pressurised = false) {
  constexpr double kW = 1, kH = 1.5, kFinal = 0.4;
  const double sigma =
      0.5 * std::sqrt(kRock.plane_strain_modulus() * 500) / (tada_edge_factor(0.3 / kW) * std::sqrt(kPi * 0.3));
  const double transit = 2 * kH / kRock.p_wave_speed(kRock.density);
  // HFMPM_GROWN_PRELOAD=f: the tension is f of its value until 12 transits
  // (growth happens under it), then ramps to it over 3; 35 transits in all.
  const char* pre = std::getenv("HFMPM_GROWN_PRELOAD");
  const double f = pre ? std::atof(pre) : 1.0;
  const double t_full = 12 * transit, t_end = (pre ? 35.0 : 25.0) * transit;
  auto config = edge_crack(kW, a, kH, 20,
                           pre ? TimeFunction::table({0, t_full, t_full + 3 * transit}, {f * sigma, f * sigma, sigma})
                               : TimeFunction::constant(pressurised ? 0.0 : sigma));
  const double h = config.grid.h;
  if (between_rows) {
    config.grid.origin.y() -= 0.5 * h;
    config.grid.ny += 1;
  }
  config.materials[0].toughness = 1;  // growth is held by the fluid front alone
  config.fracture.propagate = grow;
  config.fracture.check_interval = 5;
  config.fracture.max_lag_cells = 0;
  config.fracture.straight = true;
  config.fracture.growth_cells = 0.5;
  config.fracture.surfaces_from_material = from_material;
  config.fracture.reproject_grown = reproject;
  Solver solid(config);
  const double dt = solid.stable_dt();
  while (solid.time() < t_end) {
    const double tip = solid.cracks()[0].plane().back().x();
    const bool may_grow = grow && tip < kFinal - 0.1 * h && solid.time() > 5 * transit;
    solid.set_crack_front(0, 0.0, may_grow ? tip : 0.0);
    if (pressurised) solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), sigma));
    solid.step(dt);
  }
  std::printf("%s crack, %s: %llu node contacts\n", grow ? "grown" : "cut", between_rows ? "between rows" : "on a row",
              static_cast<unsigned long long>(solid.contacts()));
  OpeningProfile out;
  out.j = solid.tips().at(0).j;
  const auto& crack = solid.cracks()[0];
  const auto& p = solid.particles();
  for (std::size_t k = 0; k < crack.size(); ++k) {
    const Vec2 xk = crack.plane()[k];
    Vec2 u[2] = {Vec2::Zero(), Vec2::Zero()};
    double nearest[2] = {1e9, 1e9};
    for (std::size_t q = 0; q < p.x.size(); ++q) {
      const Vec2 d = p.x[q] - xk;
      if (std::abs(d.x()) > 0.6 * h || std::abs(d.y()) > h) continue;
      const int side = d.y() > 0 ? 0 : 1;
      if (d.norm() < nearest[side]) {
        nearest[side] = d.norm();
        u[side] = p.displacement[q] + p.grad_u[q] * (xk - p.x[q]);
      }
    }
    out.x.push_back(xk.x());
    out.surfaces.push_back(crack.width(k));
    out.material.push_back((u[0] - u[1]).y());
  }
  return out;
}

// The material: with the particles a growth step cuts given the strain of
// their fields' nodal displacements (fracture.reproject_grown, the default;
// Solver::reproject_strains), the grown crack's material opening is within 5%
// of the cut crack's from 1.5 cells behind the tip, on a node row and
// between rows (measured 4 December: between rows 1.000, 1.013, 1.035,
// 0.999, 1.032 from x = 0.225 to 0.325; on a row 0.982-1.001). Without it,
// between rows, the particles beside the grown faces keep +-2 MPa under a
// 0.7 MPa tension and the grown part opens 0.885 and 0.964 of the cut
// crack's at 2 and 1.5 cells (asserted below 0.92 at one of them, so that
// the comparison shows what it measures). The same between rows with the
// load a face pressure (the edges free, the KGD's load): material 1.001-1.031
// from x = 0.225 to 0.325. J of the grown crack within 1% of the cut crack's
// in all three (measured +0.02%, +0.02%, -0.28%; without the reprojection
// -0.5% under tension: J, an integral over a domain of three cells, hardly
// sees the defect, the opening does). 5%: the cut crack's own opening
// two cells from the tip is within a few percent of the exact one at this
// resolution, and the reprojected gradient is a cell-wide average of the
// one it replaces. The crack particles' own surfaces (integrated from their
// fields' velocities, the default) still read 0.84-0.87 of the cut crack's
// there, printed, not asserted: their history is the open item of
// docs/verification.md ("The grown crack"); surfaces_from_material removes
// it (next test).
TEST(Propagation, GrownCrackMaterialOpensAsACrackCutAtThatLength) {
  const double h = 1.0 / 20;
  OpeningProfile cut_between_rows;  // under tension: also the reference of the run without the reprojection
  for (const bool between_rows : {false, true}) {
    for (const bool pressurised : {false, true}) {
      if (pressurised && !between_rows) continue;
      const auto cut = edge_crack_opening(0.4, false, between_rows, false, true, pressurised);
      if (between_rows && !pressurised) cut_between_rows = cut;
      const auto grown = edge_crack_opening(0.3, true, between_rows, false, true, pressurised);
      ASSERT_EQ(cut.x.size(), grown.x.size());
      const double tip = cut.x.back();
      const char* where = between_rows ? (pressurised ? "between rows, pressurised" : "between rows") : "on a row";
      std::printf("%s: J grown / cut %.5f; x, grown/cut opening (surfaces, material)\n", where, grown.j / cut.j);
      EXPECT_NEAR(grown.j / cut.j, 1, 0.01) << where;
      for (std::size_t k = 1; k + 1 < cut.x.size(); ++k) {
        const double rs = grown.surfaces[k] / cut.surfaces[k], rm = grown.material[k] / cut.material[k];
        std::printf("  %.4f %.4f %.4f\n", cut.x[k], rs, rm);
        if (tip - cut.x[k] < 1.5 * h - 1e-9) continue;  // the particle next to the tip
        EXPECT_NEAR(rm, 1, 0.05) << where << ", x = " << cut.x[k];
      }
    }
  }
  const auto& cut = cut_between_rows;
  const auto kept = edge_crack_opening(0.3, true, true, false, false);
  double worst = 1;
  for (std::size_t k = 1; k + 1 < cut.x.size(); ++k) {
    if (cut.x.back() - cut.x[k] < 1.5 * h - 1e-9) continue;
    worst = std::min(worst, kept.material[k] / cut.material[k]);
  }
  std::printf("without the reprojection, between rows: lowest grown/cut material opening %.4f\n", worst);
  EXPECT_LT(worst, 0.92) << "the comparison no longer sees the strain the uncut body leaves";
}

// The same comparison with the surfaces placed from the material at every
// step (fracture.surfaces_from_material, Solver::anchor_crack_surfaces). On a
// node row and between rows, every crack particle from 1.5 cells behind the
// tip opens within 2% of the cut crack's (measured 4 December, with the cut
// particles' strain reprojected: between rows 1.003-1.012 from x = 0.225 to
// 0.325; on a node row 0.992-1.000; without the reprojection between rows
// 0.960 and 0.966 at 2 and 1.5 cells; the default velocity surfaces read
// 0.84-0.87 there; no contact acts in any of the four runs). 2%: the
// material they are read from is within 3.5% (test above) at single
// particles, and the surfaces average it over a cell. More than a cell
// behind the notch's tip (x <= 0.25: the crack cut from the start, out of
// the tip cell's reach) the two cracks agree within 1% (measured 0.55%).
// Every surface opening is positive and finite.
TEST(Propagation, GrownCrackWithSurfacesFromTheMaterialOpensAsACutCrack) {
  for (const bool between_rows : {true, false}) {
    const auto cut = edge_crack_opening(0.4, false, between_rows, true);
    const auto grown = edge_crack_opening(0.3, true, between_rows, true);
    ASSERT_EQ(cut.x.size(), grown.x.size());
    const double h = 1.0 / 20, tip = cut.x.back();
    for (std::size_t k = 1; k + 1 < cut.x.size(); ++k) {
      const double rs = grown.surfaces[k] / cut.surfaces[k];
      std::printf("%s x %.4f grown/cut surfaces %.4f material %.4f\n", between_rows ? "between rows" : "on a row",
                  cut.x[k], rs, grown.material[k] / cut.material[k]);
      ASSERT_TRUE(std::isfinite(rs) && grown.surfaces[k] > 0) << "x = " << cut.x[k];
      if (tip - cut.x[k] < 1.5 * h - 1e-9) continue;  // the particle next to the tip
      EXPECT_NEAR(rs, 1, cut.x[k] < 0.3 - h + 1e-9 ? 0.01 : 0.02)
          << (between_rows ? "between rows" : "on a row") << ", x = " << cut.x[k];
    }
  }
}

// fracture.release_transits (Solver::update_releases): a growth step whose
// face load is applied over two shear-wave transits of the crack
// (tau = 2 a / c_s), as a steadily advancing tip would apply it, ends where
// the step loaded at once does. The edge crack of the tests above (a = 0.3,
// h = W / 20, between node rows, faces from the material, critically damped
// for the strip's lowest mode) with its faces under a held pressure and no
// remote load, settled for 15 P-wave transits of the strip, then grown once
// by a quarter cell (propagate() called by hand). 15 transits later the two
// cracks' volumes and mouth openings agree within 0.1% (measured 2e-7: the
// release changes the path, not the static answer). On the way the released
// crack lags the cut one by up to 1.3% of the step's volume change (printed):
// a dry crack's opening at a step is mostly the material's own stress let
// go, which the release leaves alone; what it changes is the fluid's load on
// the new quarter cell, which the zero-lag fluid of a KGD must follow
// (docs/verification.md, "The load of a growth step applied as the tip
// advances"). That the solid applies the reduced load and reports it to the
// implicit solve: FaceResponse.PredictsTheOpeningWhileAGrowthStepsLoadIsApplied.
TEST(Propagation, ReleasedGrowthStepEndsWhereTheStepLoadedAtOnceDoes) {
  constexpr double kW = 1, kA = 0.3, kH = 1.5;
  const double p =
      0.5 * std::sqrt(kRock.plane_strain_modulus() * 500) / (tada_edge_factor(kA / kW) * std::sqrt(kPi * kA));
  const double transit = 2 * kH / kRock.p_wave_speed(kRock.density);
  const double c_s = std::sqrt(kRock.shear_modulus() / kRock.density);
  auto volume = [](const Crack& crack) {
    double v = 0;
    for (std::size_t k = 0; k < crack.size(); ++k) v += crack.width(k) * crack.tributary_length(k);
    return v;
  };
  struct Result {
    double before = 0, end = 0, mouth_before = 0, mouth_end = 0;
    std::vector<double> at;  // the crack's volume at t0 + fractions[i] tau
  };
  const std::vector<double> fractions{0.05, 0.1, 0.25, 0.5, 0.75, 1.0, 1.5};
  auto grow_once = [&](double release) {
    auto config = edge_crack(kW, kA, kH, 20, TimeFunction::constant(0));
    const double h = config.grid.h;
    config.grid.origin.y() -= 0.5 * h;  // the crack between node rows, as the KGD scenes
    config.grid.ny += 1;
    config.materials[0].toughness = 1e-9;  // propagate() grows whenever asked
    config.fracture.propagate = false;
    config.fracture.straight = true;
    config.fracture.growth_cells = 0.25;
    config.fracture.settle_transits = 2;
    config.fracture.release_transits = release;
    config.fracture.surfaces_from_material = true;
    Solver solid(config);
    const double dt = solid.stable_dt();
    auto step = [&] {
      solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), p));
      solid.step(dt);
    };
    while (solid.time() < 15 * transit) step();
    Result r;
    r.before = volume(solid.cracks()[0]);
    r.mouth_before = solid.cracks()[0].width(0);
    const double tip = solid.cracks()[0].plane().back().x();
    solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), p));
    EXPECT_EQ(solid.propagate(), 1);
    EXPECT_NEAR(solid.cracks()[0].plane().back().x() - tip, 0.25 * h, 1e-3 * h);
    const double tau = 2 * kA / c_s, t0 = solid.time();
    for (const double f : fractions) {
      while (solid.time() < t0 + f * tau) step();
      r.at.push_back(volume(solid.cracks()[0]));
    }
    while (solid.time() < t0 + 15 * transit) step();
    r.end = volume(solid.cracks()[0]);
    r.mouth_end = solid.cracks()[0].width(0);
    return r;
  };
  const Result cut = grow_once(0), released = grow_once(2);
  const double rise = cut.end - cut.before;
  std::printf(
      "crack volume %.6e m^2 before the step, %.6e (loaded at once) and %.6e (released) 15 transits after (tau = %.3e "
      "s); "
      "mouth opening %.6e, %.6e, %.6e m\n",
      cut.before, cut.end, released.end, 2 * kA / c_s, cut.mouth_before, cut.mouth_end, released.mouth_end);
  for (std::size_t i = 0; i < fractions.size(); ++i) {
    std::printf("  t0 + %.2f tau: volume change / final: at once %.4f, released %.4f (1 - r = %.4f)\n", fractions[i],
                (cut.at[i] - cut.before) / rise, (released.at[i] - released.before) / rise,
                0.5 * (1 - std::cos(kPi * std::min(1.0, fractions[i]))));
  }
  ASSERT_GT(rise, 0) << "the grown crack must hold more";
  EXPECT_NEAR(released.end / cut.end, 1, 1e-3);
  EXPECT_NEAR(released.mouth_end / cut.mouth_end, 1, 1e-3);
}

}  // namespace
}  // namespace hfmpm::solid::mpm
