// uGIMP shape functions (Bardenhagen and Kober 2004): partition of unity,
// gradients summing to zero, reproduction of linear fields, continuity of the
// piecewise definition, and the linear (classic MPM) limit lp -> 0.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

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

// ugimp_stencil before issue 20 (std::floor, the divisions per call): the
// reference the faster one must match bit for bit.
Stencil1D reference_stencil(double x, double h, double lp) {
  Stencil1D st;
  const double inv_h = 1 / h, inv_hlp = 1 / (h * lp);
  st.first = static_cast<int>(std::floor(x * inv_h + 0.5)) - 1;
  for (int k = 0; k < 3; ++k) {
    const double d = x - (st.first + k) * h;
    const double a = std::abs(d);
    const double sign = d < 0 ? -1.0 : 1.0;
    double s = 0, g = 0;
    if (a < lp) {
      s = 1 - 0.5 * (d * d + lp * lp) * inv_hlp;
      g = -d * inv_hlp;
    } else if (a <= h - lp) {
      s = 1 - a * inv_h;
      g = -sign * inv_h;
    } else if (a < h + lp) {
      const double r = h + lp - a;
      s = 0.25 * r * r * inv_hlp;
      g = -0.5 * sign * r * inv_hlp;
    }
    st.s[static_cast<std::size_t>(k)] = s;
    st.g[static_cast<std::size_t>(k)] = g;
  }
  return st;
}

// The stencil's floor by truncation and the reciprocals shared by both
// directions give the same bits as before, also at the ends of the pieces
// (|d| = lp, h - lp, h + lp to within a few ulps: one particle per cell puts
// every particle there), on nodes, and left of the origin.
TEST(Ugimp, FasterStencilGivesTheSameBits) {
  const double h = 0.04;
  std::vector<double> positions;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(-2 * h, 200 * h), frac(0.01, 0.5);
  for (int k = 0; k < 20000; ++k) positions.push_back(pos(rng));
  for (int cell = -2; cell < 50; ++cell) {
    for (double offset : {0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875}) {
      double x = (cell + offset) * h;
      for (int step = 0; step < 4; ++step) x = std::nextafter(x, -1e9);
      for (int step = 0; step < 9; ++step, x = std::nextafter(x, 1e9)) positions.push_back(x);
    }
  }
  auto same = [](double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); };
  for (double lp : {h / 2, h / 4, h / 6, h / 8, frac(rng) * h}) {
    const StencilScale scale(h, lp);
    for (double x : positions) {
      const Stencil1D st = ugimp_stencil(x, scale), ref = reference_stencil(x, h, lp);
      ASSERT_EQ(st.first, ref.first) << "x = " << x << ", lp = " << lp;
      for (std::size_t a = 0; a < 3; ++a) {
        ASSERT_TRUE(same(st.s[a], ref.s[a]) && same(st.g[a], ref.g[a]))
            << "x = " << x << ", lp = " << lp << ", node " << a << ": " << st.s[a] << " " << ref.s[a] << ", " << st.g[a]
            << " " << ref.g[a];
      }
    }
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
