// The MPM solid as a process, on the shipped dry scenes:
// - scenarios/sneddon.scene runs with `hfmpm run`; its mouth opening in
//   history.csv matches Sneddon's 4 p a / E' x F (finite width, F = 1.0245)
//   within 3% (measured +0.9% at this h = a/10), and solid.h5 + solid.xmf form
//   a valid ParaView pair: the XDMF parses, and every dataset it references
//   exists in the HDF5 file with the stated dimensions.
// - scenarios/confined_block.scene settles (kinetic energy falls by > 100x).
#include "coupled_support.hpp"
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
