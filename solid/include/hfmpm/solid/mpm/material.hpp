// Isotropic linear elastic material in plane strain (small strain).
// sigma = lambda tr(eps) I + 2 G eps, with eps_zz = 0 so sigma_zz = lambda (eps_xx + eps_yy).
#pragma once

#include <cmath>
#include <limits>
#include <string>

namespace hfmpm::solid::mpm {

struct Material {
  std::string name;
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;   // -
  double density = 0;         // kg/m^3 (before any density scaling)
  // Critical energy release rate J_Ic (J/m^2) for crack growth in this
  // material; infinite: cracks do not grow here. From K_Ic: J_Ic = K_Ic^2 / E'.
  double toughness = std::numeric_limits<double>::infinity();

  double shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
  double lame_lambda() const {
    return youngs_modulus * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio));
  }
  // P-wave modulus lambda + 2G: the stiffness of uniaxial strain.
  double p_modulus() const { return lame_lambda() + 2 * shear_modulus(); }
  // Plane-strain modulus E' = E / (1 - nu^2), as in fracture mechanics (K^2 = E' G).
  double plane_strain_modulus() const { return youngs_modulus / (1 - poisson_ratio * poisson_ratio); }
  double p_wave_speed(double density_used) const { return std::sqrt(p_modulus() / density_used); }
};

}  // namespace hfmpm::solid::mpm
