// Viscous resistance of the fluid between the crack faces.
//
// The width-averaged momentum balance of a channel (lubrication) carries a
// wall friction per unit fluid volume of -k(w, v) v, with k the drag
// coefficient in Pa s / m^2. A rheology supplies k; the solver integrates the
// friction implicitly on the grid, so a large k (narrow channel near the tip)
// never limits the time step. One call per batch of particles, not per
// particle (no virtual call in the hot loop).
#pragma once

#include <memory>
#include <span>
#include <string>

namespace hfmpm::fluid::mpm {

class Rheology {
 public:
  virtual ~Rheology() = default;
  // k[p] in Pa s / m^2 for particles of width[p] (m, > 0: already floored by
  // the solver) moving at velocity[p] (m/s, mean over the cross-section).
  virtual void drag(std::span<const double> width, std::span<const double> velocity, std::span<double> k) const = 0;
  virtual std::string name() const = 0;
};

// Newtonian fluid in laminar flow between parallel plates (plane Poiseuille):
// mean velocity v = -(w^2 / (12 mu)) dp/ds, so the wall friction per unit
// volume is 12 mu v / w^2 and k = 12 mu / w^2 (e.g. Batchelor, "An
// introduction to fluid dynamics", 4.2; the cubic law q = w^3 / (12 mu) dp/ds).
class Newtonian final : public Rheology {
 public:
  explicit Newtonian(double viscosity);  // Pa s, >= 0
  void drag(std::span<const double> width, std::span<const double> velocity, std::span<double> k) const override;
  std::string name() const override { return "newtonian"; }
  double viscosity() const { return viscosity_; }

 private:
  double viscosity_;
};

}  // namespace hfmpm::fluid::mpm
