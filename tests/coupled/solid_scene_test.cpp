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
  for (const char* set : {"particles", "crack0", "crack0_above", "crack0_below"}) {
    ASSERT_TRUE(summary.grids.count(set)) << set;
  }
  EXPECT_EQ(summary.times.size(), 11u);  // output every 5 ms to 55 ms
  EXPECT_EQ(summary.grids.at("particles").back().count, 20000u);
  EXPECT_TRUE(summary.grids.at("particles").back().attributes.count("stress_xx"));
  EXPECT_TRUE(summary.grids.at("crack0").back().attributes.count("width"));
  EXPECT_GT(summary.hdf_items, 100u);
}

TEST(SolidScene, ConfinedBlockSettles) {
  const auto out = scratch_dir("block");
  const auto result = run({bin("hfmpm"), "run", source("scenarios/confined_block.scene"), "--out", out, "--quiet"}, 300);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto energy = read_csv(out + "/history.csv").values("kinetic_energy_j");
  double peak = 0;
  for (double e : energy) peak = std::max(peak, e);
  EXPECT_GT(peak, 0);
  EXPECT_LT(energy.back(), 1e-2 * peak);
}

}  // namespace
}  // namespace hfmpm::test
