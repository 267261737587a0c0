#include "hfmpm/solid/mpm/predicates.hpp"

#include <cmath>
#include <limits>

namespace hfmpm::solid::mpm {
namespace {

// a + b = x + y exactly.
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

// a * b = x + y exactly (FMA).
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

// Adds b to the nonoverlapping expansion e[0..n) (increasing magnitude), zeros dropped.
int grow(double* e, int n, double b) {
  double q = b;
  int m = 0;
  for (int i = 0; i < n; ++i) {
    double sum = 0, err = 0;
    two_sum(q, e[i], sum, err);
    q = sum;
    if (err != 0) e[m++] = err;
  }
  if (q != 0) e[m++] = q;
  return m;
}

int exact_orient(const Vec2& a, const Vec2& b, const Vec2& c) {
  // det = (ax - cx)(by - cy) - (ay - cy)(bx - cx), every difference and product exact.
  double d[4][2];
  two_sum(a.x(), -c.x(), d[0][0], d[0][1]);
  two_sum(b.y(), -c.y(), d[1][0], d[1][1]);
  two_sum(a.y(), -c.y(), d[2][0], d[2][1]);
  two_sum(b.x(), -c.x(), d[3][0], d[3][1]);
  double e[32];
  int n = 0;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      double x = 0, y = 0;
      two_product(d[0][i], d[1][j], x, y);
      n = grow(e, n, y);
      n = grow(e, n, x);
      two_product(d[2][i], d[3][j], x, y);
      n = grow(e, n, -y);
      n = grow(e, n, -x);
    }
  }
  if (n == 0) return 0;
  return e[n - 1] > 0 ? 1 : -1;  // the largest component decides the sign
}

}  // namespace

int orient2d(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double left = (a.x() - c.x()) * (b.y() - c.y());
  const double right = (a.y() - c.y()) * (b.x() - c.x());
  const double det = left - right;
  // Shewchuk's ccwerrboundA = (3 + 16 eps) eps with eps = 2^-53.
  constexpr double eps = std::numeric_limits<double>::epsilon() / 2;
  const double bound = (3.0 + 16.0 * eps) * eps * (std::abs(left) + std::abs(right));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return exact_orient(a, b, c);
}

bool segments_cross(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b) {
  auto side = [](int o) { return o >= 0 ? 1 : -1; };  // on the line counts as left
  if (side(orient2d(a, b, p)) == side(orient2d(a, b, q))) return false;
  return side(orient2d(p, q, a)) != side(orient2d(p, q, b));
}

}  // namespace hfmpm::solid::mpm
