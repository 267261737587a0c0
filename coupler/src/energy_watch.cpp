#include "hfmpm/coupling/energy_watch.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hfmpm::coupling {

void EnergyWatch::start(const SideDiagnostics& fluid) {
  p_ = fluid.inlet_pressure;
  v_ = fluid.injected_volume;
  e0_ = std::max(0.0, fluid.inlet_pressure * fluid.fluid_volume);
}

std::optional<std::string> EnergyWatch::update(double t, std::uint64_t step, const SideDiagnostics& solid,
                                               const SideDiagnostics& fluid) {
  work_ += 0.5 * (p_ + fluid.inlet_pressure) * (fluid.injected_volume - v_);
  p_ = fluid.inlet_pressure;
  v_ = fluid.injected_volume;
  released_ = std::max(0.0, solid.released_energy);
  const double available = work_ + e0_ + released_;
  if (!(available > 0)) return std::nullopt;
  const double ratio = solid.kinetic_energy / available;
  if (ratio > largest_) {
    largest_ = ratio;
    largest_t_ = t;
  }
  if (bound_ <= 0 || !(ratio > bound_)) return std::nullopt;
  std::ostringstream out;
  out << "energy is being created: at step " << step << " (t = " << t << " s) the solid's kinetic energy is "
      << solid.kinetic_energy << " J/m, " << ratio << " x the energy the run can have given it (" << available
      << " J/m: " << work_ << " J/m of inlet work, " << e0_ << " J/m for the initial fill, p0 V0, and " << released_
      << " J/m of in-situ stress released by the faces' slip; the bound is " << bound_
      << " x, coupling.energy_bound). The inlet pressure is " << fluid.inlet_pressure << " Pa, the fluid volume "
      << fluid.fluid_volume << " m^2 against " << fluid.injected_volume << " m^2 injected, the mouth opening "
      << solid.mouth_opening
      << " m. The coupled step is the likely source: the method every fracture scene is verified with "
         "exchanges every step through the implicit interface (coupling.scheme: IMPLICIT, "
         "coupling.exchange_interval: 1; docs/stability.md). Otherwise check the cracks' paths in solid.h5.";
  return out.str();
}

void RestWatch::update(double t, const SideDiagnostics& solid) {
  if (t < window_start_) return;
  kinetic_ += solid.kinetic_energy;
  strain_ += solid.strain_energy;
  ++reports_;
}

double RestWatch::ratio() const {
  if (!measured()) return 0;
  return strain_ > 0 ? kinetic_ / strain_ : (kinetic_ > 0 ? std::numeric_limits<double>::infinity() : 0);
}

std::optional<std::string> RestWatch::warning() const {
  if (!measured() || !(ratio() > bound_)) return std::nullopt;
  std::ostringstream out;
  out << "the solid did not come to rest: over the last tenth of the run (from t = " << window_start_ << " s, "
      << reports_ << " reports) its mean kinetic energy is " << mean_kinetic_energy() << " J/m, " << ratio()
      << " x its mean strain energy (" << mean_strain_energy() << " J/m; at rest the ratio tends to 0, "
      << "a freely vibrating body has 1; the bound is " << bound_
      << "). A quasi-static answer needs more damping or a longer run; particles chattering at a crack "
         "(docs/solid.md) or a growth that never settles look like this too.";
  return out.str();
}

}  // namespace hfmpm::coupling
