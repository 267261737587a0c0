// Shape functions of the background grid (uniform square cells of size h).
//
// uGIMP (Bardenhagen and Kober 2004, "The generalized interpolation material
// point method", CMES 5(6), eq. 34 with a particle of half-width lp <= h/2 that
// keeps its initial size): the hat function convolved with the particle's box.
// A particle touches up to 3 nodes per direction, 9 in 2D. Linear (classic MPM)
// is the limit lp -> 0 and touches 2 nodes per direction.
#pragma once

#include <array>
#include <cmath>

namespace hfmpm::solid::mpm {

// 1D uGIMP weight and its derivative for a node at distance d = x_p - x_i.
struct Weight1D {
  double s = 0;  // shape function value
  double g = 0;  // derivative with respect to x_p
};

inline Weight1D ugimp_1d(double d, double h, double lp) {
  const double a = std::abs(d);
  const double sign = d < 0 ? -1.0 : 1.0;
  if (a < lp) return {1 - (d * d + lp * lp) / (2 * h * lp), -d / (h * lp)};
  if (a <= h - lp) return {1 - a / h, -sign / h};
  if (a < h + lp) {
    const double r = h + lp - a;
    return {r * r / (4 * h * lp), -sign * r / (2 * h * lp)};
  }
  return {};
}

inline Weight1D linear_1d(double d, double h) {
  const double a = std::abs(d);
  if (a >= h) return {};
  return {1 - a / h, (d < 0 ? 1.0 : -1.0) / h};
}

// The 3 nodes per direction a uGIMP particle may touch: first node index and
// the weights at first, first+1, first+2 (zeros where it does not reach).
struct Stencil1D {
  int first = 0;
  std::array<double, 3> s{};
  std::array<double, 3> g{};
};

// The constants of a particle's stencils: cell size, half-width and their
// reciprocals, computed once for both directions.
struct StencilScale {
  double h, lp, inv_h, inv_hlp;
  StencilScale(double cell, double half_width)
      : h(cell), lp(half_width), inv_h(1 / cell), inv_hlp(1 / (cell * half_width)) {}
};

// x: particle coordinate relative to the grid origin. The same weights as
// ugimp_1d at the 3 nodes, with the two divisions in `scale` (this runs for
// both directions of every particle twice per step).
inline Stencil1D ugimp_stencil(double x, const StencilScale& scale) {
  const double h = scale.h, lp = scale.lp, inv_h = scale.inv_h, inv_hlp = scale.inv_hlp;
  Stencil1D st;
  // The nearest node: the particle's box [x - lp, x + lp] with lp <= h/2 lies
  // within (nearest - 1) .. (nearest + 1) cells' support. floor(t) as the
  // truncation, one less where it rounded a negative t up (std::floor costs
  // four times as many instructions without SSE4.1; t is in int range on any
  // grid).
  const double t = x * inv_h + 0.5;
  int nearest = static_cast<int>(t);
  if (t < nearest) --nearest;
  st.first = nearest - 1;
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

inline Stencil1D ugimp_stencil(double x, double h, double lp) { return ugimp_stencil(x, StencilScale(h, lp)); }

}  // namespace hfmpm::solid::mpm
