// Tait equation of state of a weakly compressible liquid (water), docs/fluid.md:
//   p(J) = c K (exp((1 - J) / c) - 1),   c = 0.0894 for water,
// J = V / V0 the volume ratio (V0 the volume at zero pressure). With the "-1"
// the reference state is unloaded, p(1) = 0, and dp/dJ(1) = -K, so K is the
// bulk modulus at zero pressure. (The nested-manifold MPM paper prints the
// formula without the -1; only with it do both facts hold.)
//
// No tension: the fluid never pulls on the crack faces. When the faces move
// apart faster than the fluid follows, J > 1 and the fluid is treated as
// cavitated: p = 0 (equivalently, J is limited to <= 1 for the pressure).
// The particle keeps its true J, so it is at zero pressure until it has been
// compressed back to J = 1 (it is "partly filled").
#pragma once

#include <algorithm>
#include <cmath>

namespace hfmpm::fluid::mpm {

struct TaitEos {
  double bulk_modulus = 2.2e9;  // Pa, K
  double c = 0.0894;            // -, Tait exponent scale

  // Pa, p(J) for any J (negative for J > 1).
  double pressure(double J) const { return c * bulk_modulus * std::expm1((1 - J) / c); }
  // Pa, dp/dJ.
  double slope(double J) const { return -bulk_modulus * std::exp((1 - J) / c); }
  // Pa, p(min(J, 1)) >= 0: the pressure the fluid exerts (no tension).
  double pressure_no_tension(double J) const { return J < 1 ? pressure(J) : 0.0; }
  // -, the volume ratio at pressure p (inverse of p(J)): J = 1 - c ln(1 + p / (c K)).
  double volume_ratio(double p) const { return 1 - c * std::log1p(p / (c * bulk_modulus)); }
  // m/s, sound speed at J of a fluid with reference density rho0 (kg/m^3):
  // c_s^2 = dp/drho = -J^2 / rho0 dp/dJ (rho = rho0 / J). For J >= 1 the
  // zero-pressure value sqrt(K / rho0) (the fluid may be recompressed).
  double sound_speed(double J, double rho0) const {
    const double j = std::min(J, 1.0);
    return j * std::sqrt(bulk_modulus * std::exp((1 - j) / c) / rho0);
  }
};

}  // namespace hfmpm::fluid::mpm
