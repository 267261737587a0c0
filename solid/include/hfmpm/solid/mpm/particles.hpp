// Material points in structure-of-arrays form. Units SI, per unit thickness.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "hfmpm/exchange.hpp"

namespace hfmpm::solid::mpm {

// Stress in plane strain as (xx, yy, xy, zz); tension positive.
using Voigt = Eigen::Vector4d;

// The traction sigma n of a plane-strain stress on a plane with unit normal n.
inline Vec2 traction(const Voigt& s, const Vec2& n) {
  return {s[0] * n.x() + s[2] * n.y(), s[2] * n.x() + s[1] * n.y()};
}

struct Particles {
  std::vector<Vec2> x;            // m, position
  std::vector<Vec2> v;            // m/s, velocity
  std::vector<double> mass;       // kg/m (after density scaling)
  std::vector<double> volume;     // m^2, initial area (small strain: kept constant)
  std::vector<double> half_size;  // m, uGIMP half-width lp
  std::vector<Voigt> stress;      // Pa, Cauchy stress including the initial stress (with
                                  // in_situ_reference: its change from it; Solver::total_stress)
  // Kept only with cracks (empty otherwise): contact needs the displacement,
  // the J-integral its gradient.
  std::vector<Vec2> displacement;       // m, since the start
  std::vector<Eigen::Matrix2d> grad_u;  // du_i/dx_j since the start (small strain)
  std::vector<std::int32_t> material;   // index into the material table
  // Kept only with SolidConfig::in_situ_reference (empty otherwise): the
  // region whose initial stress the particle's stress is measured from.
  std::vector<std::int32_t> region;

  std::size_t size() const { return x.size(); }
  void add(const Vec2& position, double m, double v0, double lp, const Voigt& initial_stress, std::int32_t mat) {
    x.push_back(position);
    v.push_back(Vec2::Zero());
    mass.push_back(m);
    volume.push_back(v0);
    half_size.push_back(lp);
    stress.push_back(initial_stress);
    material.push_back(mat);
  }
  void shrink_to_fit() {
    x.shrink_to_fit();
    v.shrink_to_fit();
    mass.shrink_to_fit();
    volume.shrink_to_fit();
    half_size.shrink_to_fit();
    stress.shrink_to_fit();
    material.shrink_to_fit();
    region.shrink_to_fit();
  }
};

}  // namespace hfmpm::solid::mpm
