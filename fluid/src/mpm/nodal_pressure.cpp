// The fluid's nodal pressure (the one the solid's faces carry) and what the
// fluid reports from it: the projection with the front and lag rules, the
// stiffness -dp/dw, the front, the messages; and the initial fill.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {

void FluidSolver::fill(double front, double pressure) {
  if (grid_.empty()) throw std::logic_error("fluid: set_crack() must be called before fill()");
  if (particles_.size() > 0)
    throw std::logic_error("fluid: fill() is an initial condition: the crack already holds fluid");
  if (!(front > 0) || front > grid_.length() * (1 + 1e-12)) {
    std::ostringstream out;
    out << "fluid: fill front " << front << " m must lie in (0, " << grid_.length() << "] m (the crack length)";
    throw std::invalid_argument(out.str());
  }
  if (!(pressure >= 0) || !(pressure <= config_.bulk_modulus)) {
    std::ostringstream out;
    out << "fluid: fill pressure must lie in [0, " << config_.bulk_modulus
        << "] Pa (at most the bulk modulus: no liquid's equation of state holds beyond), got " << pressure;
    throw std::invalid_argument(out.str());
  }
  const double J = eos_.volume_ratio(pressure);
  const auto count = static_cast<std::size_t>(std::max(1.0, std::ceil(front / particle_length_ - 1e-9)));
  const double l = front / static_cast<double>(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double a = static_cast<double>(k) * l;
    const double w = grid_.width_integral(a, a + l) / l;
    if (w < config_.min_width) {
      std::ostringstream out;
      out << "fluid: fill: the crack is closed (mean width " << w << " m < min_width) over [" << a << ", " << a + l
          << "] m; fill only the open part";
      throw std::invalid_argument(out.str());
    }
    const double m = config_.density * l * w / J;  // V0 = V / J at the fill pressure
    particles_.insert(k, a + 0.5 * l, l, m, 0.0);
    reset_reference(k);
  }
  outlet_wetted_ = config_.outlet.enabled && front >= grid_.length() * (1 - 1e-12);
  update_state();
  project_pressure();
  pressure_at_set_ = nodal_pressure_;  // the fill is the start, not a change
}

void FluidSolver::project_pressure() { project_pressure(particles_.pressure, nodal_pressure_, mass_); }

void FluidSolver::project_pressure(const std::vector<double>& pp, std::vector<double>& nodal,
                                   std::vector<double>& scratch) const {
  // Mass-weighted CPDI projection p_i = sum Nbar_ip m_p p_p / sum Nbar_ip m_p;
  // masses never vanish, so every wetted node has a value.
  const std::size_t n = grid_.size();
  nodal.assign(n, 0.0);
  if (particles_.size() == 0) return;  // the shapes are current: update_state() built them
  scratch.assign(n, 0.0);
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const CpdiRange r = shapes_.range[p];
    const double* N = shapes_.weight.data() + shapes_.offset[p];
    const double m = particles_.mass[p], mp = m * pp[p];
    for (std::size_t k = 0; k < r.count; ++k) {
      scratch[r.first + k] += N[k] * m;
      nodal[r.first + k] += N[k] * mp;
    }
  }
  const double front = front_position() + 1e-12 * grid_.length();
  for (std::size_t i = 0; i < n; ++i) {
    const bool wetted = grid_.arc()[i] <= front && scratch[i] > 0;
    nodal[i] = wetted ? std::max(0.0, nodal[i] / scratch[i]) : 0.0;  // lag zone beyond the front
  }
  if (config_.lag == FluidConfig::Lag::Fixed || config_.lag == FluidConfig::Lag::TipAsymptote) {
    for (std::size_t i = 0; i < n; ++i)
      if (grid_.arc()[i] > front) nodal[i] = config_.lag_pressure;
  }
  const double mouth = config_.inlet.kind == InletConfig::Kind::Pressure ? mouth_pressure() : pp[0];
  if (config_.lag == FluidConfig::Lag::Front) {
    const double p_front = std::min(pp[particles_.size() - 1], mouth);
    // Only up to the first node beyond the front: the crack the fluid is
    // about to enter. Further on, the crack is dry (p = 0): a lag zone
    // loaded all the way to the tip let a crack with little toughness run
    // dry (0.25 -> 1.02 m in 0.25 s in the viscosity-dominated KGD).
    for (std::size_t i = 0; i < n; ++i) {
      if (grid_.arc()[i] > front) {
        nodal[i] = p_front;
        break;
      }
    }
  }
  // Where the pressure is held (the mouth, a wetted outlet) the node carries
  // that boundary value, not the one-sided projection (which is the pressure
  // about half an element inside).
  nodal[0] = mouth;
  if (outlet_wetted_) nodal[n - 1] = std::max(0.0, config_.outlet.pressure(t_));
}

std::vector<double> FluidSolver::nodal_stiffness() const {
  // The stiffness -dp/dw_i projects each particle's stiffness K_t J / w_p
  // (K_t J = -J dp/dJ its tangent bulk modulus, w_p its width) as the
  // pressure is projected: a change dw of the widths around a particle
  // changes its J by -J dw / w_p and its pressure by K_t J dw / w_p, so this
  // is the row sum of dp_i/dw_j, an upper bound of the local stiffness.
  // (Dividing the projected K_t J by the node's width instead underestimates
  // it several fold near the front, where the particles are much narrower
  // than the open node behind them, and the coupling then went unstable.)
  // Zero where the pressure does not depend on the crack's width: cavitated
  // fluid (p = 0), beyond the front, and where a boundary holds the pressure.
  // Computed when asked (once per exchange), not every fluid step.
  const std::size_t n = grid_.size();
  std::vector<double> stiffness(n, 0.0), mass(n, 0.0);
  if (particles_.size() == 0) return stiffness;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const CpdiRange r = shapes_.range[p];
    const double* N = shapes_.weight.data() + shapes_.offset[p];
    const double pressure = particles_.pressure[p], m = particles_.mass[p];
    double k = 0;  // Pa/m, K_t J / w_p
    if (pressure > 0) {
      const double J = eos_.volume_ratio(pressure);
      k = -eos_.slope(J) * J / std::max(particles_.width[p], config_.min_width);
    }
    for (std::size_t j = 0; j < r.count; ++j) {
      mass[r.first + j] += N[j] * m;
      stiffness[r.first + j] += N[j] * m * k;
    }
  }
  const double front = front_position() + 1e-12 * grid_.length();
  for (std::size_t i = 0; i < n; ++i) {
    const bool wetted = grid_.arc()[i] <= front && mass[i] > 0;
    stiffness[i] = wetted && nodal_pressure_[i] > 0 ? stiffness[i] / mass[i] : 0.0;
  }
  if (config_.inlet.kind == InletConfig::Kind::Pressure) stiffness[0] = 0;
  if (outlet_wetted_) stiffness[n - 1] = 0;
  return stiffness;
}

double FluidSolver::frozen_width_rise() const {
  const std::size_t n = nodal_pressure_.size();
  if (particles_.size() == 0 || pressure_at_set_.size() != n) return 0.0;
  const double front = front_position() + 1e-12 * grid_.length();
  const std::size_t first = config_.inlet.kind == InletConfig::Kind::Pressure ? 1 : 0;
  const std::size_t end = outlet_wetted_ ? n - 1 : n;
  double largest = 0;
  for (std::size_t i = first; i < end; ++i) {
    if (grid_.arc()[i] > front) break;
    largest = std::max(largest, std::abs(nodal_pressure_[i] - pressure_at_set_[i]));
  }
  return largest;
}

double FluidSolver::front_position() const {
  if (particles_.size() == 0) return 0.0;
  return std::min(particles_.end(particles_.size() - 1), grid_.length());
}

std::vector<Vec2> FluidSolver::particle_positions() const {
  std::vector<Vec2> x(particles_.size());
  for (std::size_t p = 0; p < particles_.size(); ++p) x[p] = grid_.point_at(particles_.s[p]);
  return x;
}

CrackPressure FluidSolver::pressure_message() const {
  CrackPressure m;
  m.crack_id = grid_.crack_id();
  m.ids = grid_.ids();
  m.pressure = nodal_pressure_;
  if (!config_.implicit_interface) {  // the implicit step's pressure already follows the faces
    m.stiffness = nodal_stiffness();
    m.width = grid_.crack_width();
  }
  m.front_position = front_position();
  m.inlet_flux = inlet_flux_;
  m.fluid_volume = fluid_volume();
  return m;
}

double FluidSolver::fluid_mass() const {
  double sum = 0;
  for (double m : particles_.mass) sum += m;
  return sum;
}

double FluidSolver::fluid_volume() const {
  double sum = 0;
  for (std::size_t p = 0; p < particles_.size(); ++p) sum += particles_.volume(p);
  return sum;
}

double FluidSolver::kinetic_energy() const {
  double sum = 0;
  for (std::size_t p = 0; p < particles_.size(); ++p)
    sum += 0.5 * particles_.mass[p] * particles_.velocity[p] * particles_.velocity[p];
  return sum;
}

}  // namespace hfmpm::fluid::mpm
