// The MPM solid as a process, on the shipped dry scenes:
// - scenarios/sneddon.scene runs with `hfmpm run`; its mouth opening in
//   history.csv matches Sneddon's 4 p a / E' x F (finite width, F = 1.0245)
//   within 3% (measured +0.9% at this h = a/10), and solid.h5 + solid.xmf form
//   a valid ParaView pair: the XDMF parses, and every dataset it references
//   exists in the HDF5 file with the stated dimensions.
// - scenarios/confined_block.scene settles (kinetic energy falls by > 100x).
// - A Sneddon crack written with no face or method key (the derived faces)
//   holds Sneddon's opening at every face point over many transits.
#include <cmath>

#include "coupled_support.hpp"
#include "h5_reader.hpp"
#include "xdmf_check.hpp"

namespace hfmpm::test {
namespace {

TEST(SolidScene, SneddonRunsAndWritesAValidXdmf) {
  const auto out = scratch_dir("sneddon");
  const auto result = run({bin("hfmpm"), "run", source("scenarios/sneddon.scene"), "--out", out, "--quiet"}, 300);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv history = read_csv(out + "/history.csv");
  const double e_prime = 1e10 / (1 - 0.25 * 0.25);
  const double mouth = 1.0245 * 4 * 1e6 * 1.0 / e_prime;
  EXPECT_NEAR(history.values("mouth_opening_m").back(), mouth, 0.03 * mouth);
  EXPECT_NEAR(history.values("crack_length_m").back(), 1.0, 1e-3);
  EXPECT_EQ(history.values("crack_particles").back(), 21.0);

  const auto summary = check_xdmf(out + "/solid.xmf", out + "/solid.h5");  // throws on any problem
  for (const char* set : {"particles", "crack0", "crack0_above", "crack0_below", "tips"}) {
    ASSERT_TRUE(summary.grids.count(set)) << set;
  }
  EXPECT_EQ(summary.times.size(), 11u);  // output every 5 ms to 55 ms
  EXPECT_EQ(summary.grids.at("particles").back().count, 20000u);
  EXPECT_TRUE(summary.grids.at("particles").back().attributes.count("stress_xx"));
  EXPECT_TRUE(summary.grids.at("crack0").back().attributes.count("width"));
  EXPECT_GT(summary.hdf_items, 100u);
  for (const char* field : {"j", "k1", "k2", "kink_angle"}) {
    EXPECT_TRUE(summary.grids.at("tips").back().attributes.count(field)) << field;
  }
}

// The fracture keys are validated before anything runs, naming key, value and range.
TEST(SolidScene, BadFractureSettingsAreRefused) {
  struct Case {
    std::string set, key, allowed;
  };
  const std::vector<Case> cases = {
      {"solid.mpm.fracture.j_outer_cells=1", "solid.mpm.fracture.j_outer_cells", "more than j_inner_cells"},
      {"solid.mpm.fracture.growth_cells=1.5", "solid.mpm.fracture.growth_cells", "cells"},
      {"solid.mpm.fracture.check_interval=0", "solid.mpm.fracture.check_interval", "at least 1 step"},
      {"solid.mpm.fracture.direction=DIRECTION_UNSPECIFIED", "solid.mpm.fracture.direction",
       "MAX_HOOP_STRESS or STRAIGHT"},
      {"solid.mpm.fracture.max_lag_cells=-0.5", "solid.mpm.fracture.max_lag_cells", ">= 0"},
      {"solid.mpm.damping.feedback_q_m2=-1", "solid.mpm.damping.feedback_q_m2", "m^2"},
      {"solid.mpm.materials=[{name: \"rock\" youngs_modulus_pa: 1e10 poisson_ratio: 0.25 density_kg_m3: 2500 "
       "toughness_j_m2: 1 toughness_pa_sqrt_m: 1e5}]",
       "solid.mpm.materials[0].toughness_pa_sqrt_m", "give one of them"},
      {"solid.mpm.materials=[{name: \"rock\" youngs_modulus_pa: 1e10 poisson_ratio: 0.25 density_kg_m3: 2500 "
       "toughness_j_m2: -1}]",
       "solid.mpm.materials[0].toughness_j_m2", "J/m^2"},
      // The explicit step's measured limit (docs/stability.md).
      {"solid.mpm.cfl=0.55", "solid.mpm.cfl", "unstable from about 0.55"},
      // The in-situ stress as reference needs it in equilibrium across regions.
      {"solid.mpm.in_situ_reference=true --set solid.mpm.regions=[{material: \"rock\" rectangle { x_min_m: 0 "
       "y_min_m: -1 x_max_m: 1 y_max_m: 0 } initial_stress { yy_pa: -1e6 }}, {material: \"rock\" rectangle { "
       "x_min_m: 0 y_min_m: 0 x_max_m: 1 y_max_m: 1 } initial_stress { yy_pa: -2e6 }}]",
       "solid.mpm.regions[1].initial_stress", "in equilibrium across the regions"},
      {"solid.mpm.in_situ_reference=true --set solid.mpm.regions=[{material: \"rock\" polygon { x_m: [0, 1, 0] "
       "y_m: [0, 0, 1] }}]",
       "solid.mpm.regions[0].polygon", "rectangle or layer regions"},
      {"solid.mpm.regions=[{material: \"rock\" rectangle { x_min_m: 0 y_min_m: -1 x_max_m: 1 y_max_m: 1 } "
       "particles_per_cell: 5}]",
       "solid.mpm.regions[0].particles_per_cell", "1, 2, 3 or 4"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {bin("hfmpm"), "validate", source("scenarios/sneddon.scene")};
    for (std::string rest = c.set;;) {  // one case may set several keys
      const auto cut = rest.find(" --set ");
      args.push_back("--set");
      args.push_back(rest.substr(0, cut));
      if (cut == std::string::npos) break;
      rest = rest.substr(cut + 7);
    }
    const auto result = run(args, 30);
    EXPECT_EQ(result.exit_code, 2) << c.set;
    EXPECT_NE(result.err.find(c.key), std::string::npos) << c.set << ": " << result.err;
    EXPECT_NE(result.err.find(c.allowed), std::string::npos) << c.set << ": " << result.err;
  }
}

// A pressurised crack written by hand with the defaults: E = 8 MPa,
// nu = 0.3, p = 20 kPa, a = 0.75 m, h = a / 15, the body +-7.5 m (10 a),
// the crack on a node row with its tip on a node, damping 2 pi c_p / (4 b) =
// 13.7 /s, 1.4 s (about 12 P-wave transits of the body). With the faces that
// move with their side's velocity (the former default; --set
// solid.mpm.fracture.surfaces_from_material=false) the crack particle next
// to the tip opened to 1.6, 2.8 and 5.1 times Sneddon's at 0.2, 0.6 and 1.4 s
// (an error of 1.04 mouth openings); the derived default reads the faces
// from the material. Sneddon's
// opening w = 4 p / E' sqrt(a^2 - x^2), mouth 4 p a / E', K_I = p sqrt(pi a)
// (infinite body; a box of 10 a opens about 1% more). Asserted over the last
// 0.4 s: every face point within 3% of the mouth opening of Sneddon's (at
// the issue's tolerance, which allows for the cell's averaging within a cell
// of the tip), the mouth and K_I within 2%. Measured: 1.0%, 1.0% and 1.1%.
TEST(SolidScene, SneddonWithTheDefaultFacesHoldsEveryFacePoint) {
  const auto out = scratch_dir("sneddon_default");
  const std::string scene = R"(
    name: "sneddon-default"
    time { end_s: 1.4 }
    output { interval_s: 0.2 }
    solid {
      mpm {
        grid { x_min_m: 0 y_min_m: -7.6 x_max_m: 7.6 y_max_m: 7.6 }
        cell_size_m: 0.05
        materials { name: "rock" youngs_modulus_pa: 8e6 poisson_ratio: 0.3 density_kg_m3: 2500 }
        regions { material: "rock" rectangle { x_min_m: 0 y_min_m: -7.5 x_max_m: 7.5 y_max_m: 7.5 } particles_per_cell: 1 }
        regions { material: "rock" rectangle { x_min_m: 0 y_min_m: -1.5 x_max_m: 1.5 y_max_m: 1.5 } particles_per_cell: 2 }
        constraints { symmetry_x_m: 0 }
        damping { grid_alpha_per_s: 13.7 }
        cracks { x_m: [0, 0.75] y_m: [0, 0] start_is_tip: false end_is_tip: true pressure_pa { constant: 2e4 } }
      }
    })";
  const auto result = run_scene(scene, out, {}, 600);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const double a = 0.75, p = 2e4, e_prime = 8e6 / (1 - 0.3 * 0.3);
  const double mouth = 4 * p * a / e_prime, k1 = p * std::sqrt(M_PI * a);
  H5Reader h5(out + "/solid.h5");
  const auto frames = h5.children("/frames");
  ASSERT_GE(frames.size(), 7u);
  double worst_point = 0, worst_mouth = 0, worst_k = 0;
  for (std::size_t f = frames.size() - 3; f < frames.size(); ++f) {  // 1.0, 1.2 and 1.4 s
    const auto xy = h5.f64("/frames/" + frames[f] + "/crack0/positions");
    const auto width = h5.f64("/frames/" + frames[f] + "/crack0/width");
    ASSERT_EQ(xy.size(), 2 * width.size());
    for (std::size_t k = 0; k < width.size(); ++k) {
      // Sneddon's opening at the particle's place on the crack as cut (its
      // spacing a / (n - 1)); the tip particle's exact opening is zero.
      const double x = a * static_cast<double>(k) / static_cast<double>(width.size() - 1);
      const double exact = 4 * p / e_prime * std::sqrt(std::max(0.0, a * a - x * x));
      worst_point = std::max(worst_point, std::abs(width[k] - exact) / mouth);
    }
    worst_mouth = std::max(worst_mouth, std::abs(width.front() / mouth - 1));
    worst_k = std::max(worst_k, std::abs(h5.f64("/frames/" + frames[f] + "/tips/k1").front() / k1 - 1));
  }
  std::printf(
      "Sneddon with the default faces, 1.0-1.4 s: every face point within %.4f of the mouth opening; "
      "mouth %.4f, K_I %.4f\n",
      worst_point, worst_mouth, worst_k);
  EXPECT_LT(worst_point, 0.03);
  EXPECT_LT(worst_mouth, 0.02);
  EXPECT_LT(worst_k, 0.02);
}

TEST(SolidScene, ConfinedBlockSettles) {
  const auto out = scratch_dir("block");
  const auto result =
      run({bin("hfmpm"), "run", source("scenarios/confined_block.scene"), "--out", out, "--quiet"}, 300);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto energy = read_csv(out + "/history.csv").values("kinetic_energy_j");
  double peak = 0;
  for (double e : energy) peak = std::max(peak, e);
  EXPECT_GT(peak, 0);
  EXPECT_LT(energy.back(), 1e-2 * peak);
}

}  // namespace
}  // namespace hfmpm::test
