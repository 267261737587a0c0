// uGIMP shape functions (Bardenhagen and Kober 2004): partition of unity,
// gradients summing to zero, reproduction of linear fields, continuity of the
// piecewise definition, and the linear (classic MPM) limit lp -> 0.
#include <gtest/gtest.h>

#include <random>

#include "hfmpm/solid/mpm/crack.hpp"
#include "hfmpm/solid/mpm/shape.hpp"

namespace hfmpm::solid::mpm {
namespace {

TEST(Ugimp, PartitionOfUnityZeroGradientSumAndLinearReproduction) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(2.0, 20.0), frac(0.01, 0.5);
  for (int trial = 0; trial < 10000; ++trial) {
    const double h = 0.37;
    const double lp = frac(rng) * h;  // up to a half cell (one particle per cell)
    const double x = pos(rng);
    const auto st = ugimp_stencil(x, h, lp);
    double sum = 0, grad = 0, first_moment = 0, grad_moment = 0;
    for (int k = 0; k < 3; ++k) {
      const double xi = (st.first + k) * h - x;  // relative to the particle: no cancellation
      sum += st.s[static_cast<std::size_t>(k)];
      grad += st.g[static_cast<std::size_t>(k)];
      first_moment += st.s[static_cast<std::size_t>(k)] * xi;
      grad_moment += st.g[static_cast<std::size_t>(k)] * xi;
    }
    ASSERT_NEAR(sum, 1.0, 1e-14) << "x = " << x << " lp = " << lp;
    ASSERT_NEAR(grad, 0.0, 1e-12);
    ASSERT_NEAR(first_moment, 0.0, 1e-14);  // sum S_i (x_i - x_p) = 0
    ASSERT_NEAR(grad_moment, 1.0, 1e-12);   // sum dS_i/dx (x_i - x_p) = 1
  }
}

TEST(Ugimp, ContinuousAcrossItsPieces) {
  const double h = 1.0, lp = 0.25;
  for (double d : {lp, h - lp, h + lp}) {
    const double below = ugimp_1d(d - 1e-12, h, lp).s, above = ugimp_1d(d + 1e-12, h, lp).s;
    EXPECT_NEAR(below, above, 1e-11) << "at |d| = " << d;
  }
  EXPECT_EQ(ugimp_1d(h + lp, h, lp).s, 0.0);
  EXPECT_NEAR(ugimp_1d(0, h, lp).s, 1 - lp / (2 * h), 1e-15);
}

TEST(Ugimp, TendsToLinearForSmallParticles) {
  const double h = 1.0;
  for (double d : {-0.9, -0.3, 0.2, 0.7}) {
    EXPECT_NEAR(ugimp_1d(d, h, 1e-7).s, linear_1d(d, h).s, 1e-6);
    EXPECT_NEAR(ugimp_1d(d, h, 1e-7).g, linear_1d(d, h).g, 1e-6);
  }
}

// Growth adds closed crack particles with fresh ids: at the end (append) or,
// for an interior crack's start tip, in front (prepend); the others keep
// their ids, positions and order.
TEST(Crack, GrowthAtEitherEndKeepsIdsAndStartsClosed) {
  CrackSpec spec;
  spec.points = {Vec2(0, 0), Vec2(1, 0), Vec2(2, 0)};
  spec.start_is_tip = spec.end_is_tip = true;
  Crack crack(0, spec);
  crack.surface(1)[1] = Vec2(1, 0.1);
  crack.surface(-1)[1] = Vec2(1, -0.1);
  crack.pressure()[1] = 5;
  crack.append(Vec2(2.5, 0));
  crack.prepend(Vec2(-0.5, 0));
  EXPECT_EQ(crack.ids(), (std::vector<std::uint64_t>{4, 0, 1, 2, 3}));
  EXPECT_EQ(crack.plane().front(), Vec2(-0.5, 0));
  EXPECT_EQ(crack.plane().back(), Vec2(2.5, 0));
  EXPECT_EQ(crack.width(0), 0.0);
  EXPECT_EQ(crack.width(4), 0.0);
  EXPECT_EQ(crack.pressure(), (std::vector<double>{0, 0, 5, 0, 0}));
  EXPECT_NEAR(crack.width(2), 0.2, 1e-15);  // the opened particle moved with its data
  EXPECT_EQ(crack.surface(1)[2], Vec2(1, 0.1));
}

}  // namespace
}  // namespace hfmpm::solid::mpm
