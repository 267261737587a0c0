// Shape functions on the fluid's 1D grid: the crack particles at arc lengths
// s_0 < s_1 < ... < s_{n-1} (non-uniform spacing), linear hats N_i between them.
//
// Beyond the ends the hats are extended as constants: N_0 = 1 for s < s_0 and
// N_{n-1} = 1 for s > s_{n-1} (the mouth node carries what lies before it, the
// tip node what lies beyond the tip). The weights then still sum to one and
// their gradients to zero everywhere; linear fields are reproduced inside
// [s_0, s_{n-1}] only. A fluid particle that reaches past the tip is thus
// "clamped": its part beyond the tip moves with the tip node and sees the tip's
// width (zero for a closed tip, which compresses it and pushes it back).
//
// CPDI in 1D (after Sadeghirad, Brannon and Burghardt 2011, "A convected
// particle domain interpolation technique to extend applicability of the
// material point method for problems involving massive deformations", IJNME
// 86(12), eqs. 22-23, reduced to a segment): the domain of particle p is
// [a, b] = [s_p - l_p/2, s_p + l_p/2] and
//   weight   Nbar_ip = (1/l_p) integral_a^b N_i(s) ds   (exact, any number of elements)
//   gradient Gbar_ip = (N_i(b) - N_i(a)) / l_p          (= the mean of dN_i/ds over [a, b])
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace hfmpm::fluid::mpm {

// The hats at a point: N_node = n0, N_{node+1} = n1, all others zero.
struct HatPoint {
  std::size_t node = 0;
  double n0 = 1, n1 = 0;
};

// Hat values at arc length s on the grid `nodes` (size >= 2, increasing); clamped outside.
HatPoint hat_at(std::span<const double> nodes, double s);

// Linear interpolation of nodal `values` at s (clamped outside the grid).
double interpolate(std::span<const double> nodes, std::span<const double> values, double s);

// Integral of the interpolated nodal `values` over [a, b] (a <= b), with the
// constant extension outside the grid. Exact for the piecewise-linear field.
double integrate(std::span<const double> nodes, std::span<const double> values, double a, double b);

// The nodes a particle domain touches: first .. first + count - 1.
struct CpdiRange {
  std::size_t first = 0;
  std::size_t count = 0;
};

// CPDI weights (and, if `gradient` is not null, gradients) of the domain [a, b]
// (a < b), appended to `weight` / `*gradient` for nodes range.first + k.
// Zero-length domains (a == b) get the point values and zero gradients.
CpdiRange cpdi_weights(std::span<const double> nodes, double a, double b, std::vector<double>& weight,
                       std::vector<double>* gradient = nullptr);

// CPDI weights of every particle of a step, in one flat table.
struct ShapeTable {
  std::vector<CpdiRange> range;     // per particle
  std::vector<std::size_t> offset;  // per particle: index of its first weight
  std::vector<double> weight;       // flat: Nbar_ip
  std::vector<double> gradient;     // flat: Gbar_ip, 1/m

  void clear() {
    range.clear();
    offset.clear();
    weight.clear();
    gradient.clear();
  }
  void add(std::span<const double> nodes, double a, double b) {
    offset.push_back(weight.size());
    range.push_back(cpdi_weights(nodes, a, b, weight, &gradient));
  }
};

}  // namespace hfmpm::fluid::mpm
