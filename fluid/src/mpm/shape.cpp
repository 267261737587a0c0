#include "hfmpm/fluid/mpm/shape.hpp"

#include <algorithm>

namespace hfmpm::fluid::mpm {
namespace {

// Element k with s_k <= s < s_{k+1}, clamped to [0, n-2].
// Lookups come in order along the crack (particles are sorted and each one
// asks about its two ends), so the element found last, or its neighbour, is
// nearly always the answer: try those before a binary search ("hunting", as
// in Press et al., Numerical Recipes 3.1.2). The hint is per thread and only
// a guess: a hit is verified against the nodes given, so any grid is safe.
std::size_t element_of(std::span<const double> nodes, double s) {
  thread_local std::size_t hint = 0;
  const std::size_t n = nodes.size();
  for (std::size_t k : {hint, hint + 1, hint - 1}) {  // hint - 1 wraps to SIZE_MAX when hint == 0: fails k < n - 1
    if (k < n - 1 && nodes[k] <= s && s < nodes[k + 1]) return hint = k;
  }
  const auto it = std::upper_bound(nodes.begin(), nodes.end(), s);
  const std::size_t k = it == nodes.begin() ? 0 : static_cast<std::size_t>(it - nodes.begin()) - 1;
  return hint = std::min(k, n - 2);
}

}  // namespace

HatPoint hat_at(std::span<const double> nodes, double s) {
  const std::size_t last = nodes.size() - 1;
  if (s <= nodes[0]) return {0, 1, 0};
  if (s >= nodes[last]) return {last - 1, 0, 1};
  const std::size_t k = element_of(nodes, s);
  const double t = (s - nodes[k]) / (nodes[k + 1] - nodes[k]);
  return {k, 1 - t, t};
}

double interpolate(std::span<const double> nodes, std::span<const double> values, double s) {
  const HatPoint h = hat_at(nodes, s);
  return h.n0 * values[h.node] + h.n1 * values[h.node + 1];
}

double integrate(std::span<const double> nodes, std::span<const double> values, double a, double b) {
  const std::size_t last = nodes.size() - 1;
  double sum = 0;
  if (a < nodes[0]) sum += (std::min(b, nodes[0]) - a) * values[0];
  if (b > nodes[last]) sum += (b - std::max(a, nodes[last])) * values[last];
  if (b <= nodes[0] || a >= nodes[last]) return sum;
  // Trapezoid on each overlap with an element: exact for a linear field.
  for (std::size_t e = element_of(nodes, a); e < last && nodes[e] < b; ++e) {
    const double x0 = std::max(a, nodes[e]), x1 = std::min(b, nodes[e + 1]);
    if (x1 <= x0) continue;
    const double h = nodes[e + 1] - nodes[e];
    const double t0 = (x0 - nodes[e]) / h, t1 = (x1 - nodes[e]) / h;
    const double v0 = values[e] + t0 * (values[e + 1] - values[e]);
    const double v1 = values[e] + t1 * (values[e + 1] - values[e]);
    sum += 0.5 * (x1 - x0) * (v0 + v1);
  }
  return sum;
}

CpdiRange cpdi_weights(std::span<const double> nodes, double a, double b, std::vector<double>& weight,
                       std::vector<double>* gradient) {
  const std::size_t last = nodes.size() - 1;
  const double l = b - a;
  if (!(l > 0)) {  // a point: the hats there, no gradient
    const HatPoint h = hat_at(nodes, a);
    weight.push_back(h.n0);
    weight.push_back(h.n1);
    if (gradient) gradient->insert(gradient->end(), {0.0, 0.0});
    return {h.node, 2};
  }
  // First and last node whose hat overlaps (a, b).
  const std::size_t first = a < nodes[0] ? 0 : (a >= nodes[last] ? last : element_of(nodes, a));
  std::size_t stop = last;
  if (b <= nodes[0]) {
    stop = 0;
  } else if (b <= nodes[last]) {
    const std::size_t e = element_of(nodes, b);
    stop = b > nodes[e] ? e + 1 : e;  // a domain ending on a node does not touch the next hat
  }
  const CpdiRange range{first, stop - first + 1};
  const std::size_t base = weight.size();
  weight.resize(base + range.count, 0.0);
  double* w = weight.data() + base;
  // Constant extensions before the mouth and beyond the tip.
  if (a < nodes[0]) w[0 - first] += std::min(b, nodes[0]) - a;
  if (b > nodes[last]) w[last - first] += b - std::max(a, nodes[last]);
  // Each element overlap [x0, x1] (t = local coordinate): integral of N_{e+1} =
  // (x1 - x0) (t0 + t1) / 2, of N_e the rest of (x1 - x0). Exact.
  if (b > nodes[0] && a < nodes[last]) {
    for (std::size_t e = element_of(nodes, a); e < last && nodes[e] < b; ++e) {
      const double x0 = std::max(a, nodes[e]), x1 = std::min(b, nodes[e + 1]);
      if (x1 <= x0) continue;
      const double h = nodes[e + 1] - nodes[e];
      const double right = 0.5 * (x1 - x0) * ((x0 - nodes[e]) / h + (x1 - nodes[e]) / h);
      w[e + 1 - first] += right;
      w[e - first] += (x1 - x0) - right;
    }
  }
  for (std::size_t k = 0; k < range.count; ++k) w[k] /= l;
  if (gradient) {
    const std::size_t gbase = gradient->size();
    gradient->resize(gbase + range.count, 0.0);
    double* g = gradient->data() + gbase;
    const HatPoint ha = hat_at(nodes, a), hb = hat_at(nodes, b);
    // Both end stencils lie inside [first, stop] (a hat that is nonzero at an
    // end overlaps the domain, or the end sits on that hat's edge with value 0).
    auto add = [&](const HatPoint& h, double sign) {
      if (h.n0 != 0) g[h.node - first] += sign * h.n0 / l;
      if (h.n1 != 0) g[h.node + 1 - first] += sign * h.n1 / l;
    };
    add(hb, 1.0);
    add(ha, -1.0);
  }
  return range;
}

}  // namespace hfmpm::fluid::mpm
