#include "hfmpm/fluid/mpm/rheology.hpp"

#include <cmath>
#include <stdexcept>

namespace hfmpm::fluid::mpm {

Newtonian::Newtonian(double viscosity) : viscosity_(viscosity) {
  if (!(viscosity >= 0) || !std::isfinite(viscosity)) {
    throw std::invalid_argument("fluid viscosity must be finite and >= 0 Pa s, got " + std::to_string(viscosity));
  }
}

void Newtonian::drag(std::span<const double> width, std::span<const double> /*velocity*/, std::span<double> k) const {
  const double twelve_mu = 12 * viscosity_;
  for (std::size_t p = 0; p < width.size(); ++p) k[p] = twelve_mu / (width[p] * width[p]);
}

}  // namespace hfmpm::fluid::mpm
