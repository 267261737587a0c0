// Inlet at the mouth, optional outlet at the last node, and the insertion,
// splitting and merging of particles there.
//
// The inlet particle (particle 0) always starts at the mouth. After each G2P
// its rear end, which moved with the grid, is put back at s = 0 and the
// particle is given the mass that crossed the mouth in the step:
//   flow-rate inlet: dm = rho0 integral_t^{t+dt} Q dt (trapezoid: exact for a
//     piecewise-linear Q whose kinks fall on step ends). Its pressure follows
//     from J = rho0 l w / m, so the pressure at the mouth is whatever pushes
//     rho0 Q into the crack; the mouth is held at that pressure (the well is
//     in equilibrium with the inlet particle);
//   pressure inlet: p_in(t) is the well's pressure, the fluid at rest there.
//     The mouth is held at its static pressure p_m = p_in - rho v^2 / 2 for
//     inflow at the mouth's velocity v after the last step (Bernoulli from
//     the well; p_in for outflow), a traction p_m w(0) on node 0; the fluid
//     that moved in over [0, a] (a = where the rear end went) enters at the
//     density rho0 / J(p_m) and with the grid's velocity, so that what comes
//     in brings p_m + rho v^2 / 2 = p_in per unit volume, pressure work and
//     kinetic energy together. (Held at p_in itself, the inflow's kinetic
//     energy came for free: a thin fluid entering a crack at 87 m/s under
//     2.3 MPa, whose rho v^2 / 2 is 3.8 MPa, gave the solid more kinetic
//     energy than the well had supplied; docs/fluid.md, "Pressure inlet".)
//     If the rear end moved out (a < 0), the part outside leaves with its
//     share of the particle's mass.
// Mass is conserved exactly: the added masses are summed into
// injected_mass(), and splits and merges only redistribute mass.
// When the inlet particle reaches twice particle_length, its front
// particle_length is released as a new particle (mass shared by volume, so
// both keep the same J and pressure). An empty crack is seeded with an inlet
// particle of particle_length: for a flow rate with the first step's mass
// (it fills at zero pressure, J > 1, until it is full), for a pressure inlet
// full at the inlet pressure.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {

double FluidSolver::entrance_pressure(double t, double v) const {
  const double p_in = std::max(0.0, config_.inlet.pressure(t));
  if (!(v > 0)) return p_in;
  const double rho = config_.density / eos_.volume_ratio(p_in);
  return std::max(0.0, p_in - 0.5 * rho * v * v);
}

double FluidSolver::mouth_pressure() const {
  if (config_.inlet.kind == InletConfig::Kind::Pressure) {
    // The fluid's velocity at the mouth: the inlet particle's there (the
    // nodal velocities do not outlive a new crack from the solid).
    const auto& P = particles_;
    const double v = P.size() > 0 ? P.velocity[0] + (config_.affine ? P.gradient[0] * (0.0 - P.s[0]) : 0.0) : 0.0;
    return entrance_pressure(t_, v);
  }
  return particles_.size() > 0 ? particles_.pressure[0] : 0.0;
}

double FluidSolver::inlet_pressure() const {
  if (config_.inlet.kind == InletConfig::Kind::Pressure) return std::max(0.0, config_.inlet.pressure(t_));
  // The implicit step reports the mouth pressure it solved over the step.
  if (config_.implicit_interface && !nodal_pressure_.empty()) return nodal_pressure_[0];
  return mouth_pressure();
}

double FluidSolver::inflow_mass(double dt) const {
  const auto& q = config_.inlet.flow_rate;
  return config_.density * (inlet_share_ * 0.5 * (q(t_) + q(t_ + dt)) + inlet_transfer_) * dt;
}

void FluidSolver::set_inlet_split(double share, double transfer) {
  if (!(share >= 0 && share <= 1))
    throw std::invalid_argument("fluid: the inlet share must be between 0 and 1, got " + std::to_string(share));
  if (!std::isfinite(transfer))
    throw std::invalid_argument("fluid: the inlet transfer must be finite, got " + std::to_string(transfer));
  inlet_share_ = share;
  inlet_transfer_ = transfer;
}

bool FluidSolver::seed(double dt) {
  const auto& inlet = config_.inlet;
  const double rho0 = config_.density;
  const double L = std::min(particle_length_, grid_.length());
  const bool flow_rate = inlet.kind == InletConfig::Kind::FlowRate;
  const double q = flow_rate ? inflow_mass(dt) / (rho0 * dt) : 0.0;
  const double p_in = flow_rate ? 0.0 : std::max(0.0, inlet.pressure(t_ + dt));
  if (!(q > 0) && !(p_in > 0)) return false;  // nothing pushes fluid in yet
  if (grid_.width()[0] <= 0) {
    std::ostringstream out;
    out << "fluid: crack " << grid_.crack_id()
        << ": the mouth is closed (width 0) and inlet.pre_opening is 0, so no fluid can enter; set "
           "inlet.pre_opening > 0 (a small virtual opening, e.g. 1e-3 of the expected mouth opening)";
    throw std::invalid_argument(out.str());
  }
  const double m = flow_rate ? rho0 * q * dt : rho0 / eos_.volume_ratio(p_in) * grid_.width_integral(0, L);
  particles_.insert(0, 0.5 * L, L, m, 0.0);
  reset_reference(0);
  injected_mass_ += m;
  return true;
}

void FluidSolver::inlet(double dt) {
  auto& P = particles_;
  const auto& in = config_.inlet;
  const double rho0 = config_.density;
  if (P.size() == 0) {
    if (seed(dt)) split_inlet();
    return;
  }
  // Particles pushed out through the mouth entirely leave the crack.
  while (P.size() > 0 && P.end(0) <= 0) {
    injected_mass_ -= P.mass[0];
    P.erase(0);
  }
  if (P.size() == 0) return;
  const double a = P.start(0), b = P.end(0);
  double dm = 0;
  if (in.kind == InletConfig::Kind::FlowRate) {
    dm = inflow_mass(dt);
  } else if (a > 0) {
    const double p_m = entrance_pressure(t_ + dt, v_new_.empty() ? 0.0 : v_new_[0]);
    dm = rho0 / eos_.volume_ratio(p_m) * grid_.width_integral(0, a);
  }
  if (a < 0 && in.kind == InletConfig::Kind::Pressure) {
    const double outside = grid_.width_integral(a, 0), all = grid_.width_integral(a, b);
    dm = -P.mass[0] * (all > 0 ? outside / all : -a / (b - a));
  }
  if (!(P.mass[0] + dm > 0)) {
    std::ostringstream out;
    out << "fluid: crack " << grid_.crack_id() << ": the inlet withdrew " << -dm << " kg/m in one step, more than the "
        << P.mass[0] << " kg/m the inlet particle holds";
    throw std::runtime_error(out.str());
  }
  P.s[0] = 0.5 * b;
  P.length[0] = b;
  P.mass[0] += dm;
  // Re-extended to the mouth with new fluid, the inlet particle's affine
  // velocity no longer describes it. Behind a pressure inlet the mouth's
  // velocity sets the inflow, and it takes the velocity the grid has over its
  // new domain, mean and slope (with none, a velocity rising towards the
  // mouth lost its slope at every step as under PIC, and the inflow with
  // it: the widening-channel test). Behind a flow-rate inlet the inflow is
  // given and the particle keeps its mean velocity only: with the grid's
  // slope the mouth's pressure in steady channel flow swung by 2.6-5% with
  // the inlet particle's cycle, against 0.5% (tests/fluid/channel_flow_test).
  if (config_.affine && in.kind == InletConfig::Kind::Pressure && v_new_.size() == grid_.size() && b > 0) {
    const auto& arc = grid_.arc();
    P.velocity[0] = integrate(arc, v_new_, 0.0, b) / b;
    P.gradient[0] = (interpolate(arc, v_new_, b) - interpolate(arc, v_new_, 0.0)) / b;
  } else {
    P.gradient[0] = 0;
  }
  injected_mass_ += dm;
  reset_reference(0);
  if (P.size() > 1 && P.length[0] < 0.5 * particle_length_) merge(0);  // backflow shortened it
  split_inlet();
}

void FluidSolver::split_inlet() {
  auto& P = particles_;
  const double L = particle_length_;
  while (P.length[0] >= 2 * L) {
    const double b = P.end(0), cut = b - L;
    const double front = grid_.width_integral(cut, b), all = grid_.width_integral(0, b);
    const double m_front = P.mass[0] * (all > 0 ? front / all : L / b);
    // Each piece takes the particle's affine velocity at its own centre,
    // measured from the pieces' mass centre (the mass is shared by volume, not
    // by length), so that the split keeps the momentum exactly.
    const double v = P.velocity[0], g = P.gradient[0], m = P.mass[0];
    const double rear = 0.5 * cut, ahead = cut + 0.5 * L;
    const double centre = ((m - m_front) * rear + m_front * ahead) / m;
    P.insert(1, ahead, L, m_front, v + g * (ahead - centre));
    P.gradient[1] = g;
    P.velocity[0] = v + g * (rear - centre);
    P.s[0] = 0.5 * cut;
    P.length[0] = cut;
    P.mass[0] -= m_front;
    reset_reference(0);
    reset_reference(1);
  }
}

void FluidSolver::merge(std::size_t p) {
  auto& P = particles_;
  const double a = P.start(p), b = P.end(p + 1);
  const double m = P.mass[p] + P.mass[p + 1];
  P.velocity[p] = (P.mass[p] * P.velocity[p] + P.mass[p + 1] * P.velocity[p + 1]) / m;  // momentum conserved
  P.gradient[p] = (P.mass[p] * P.gradient[p] + P.mass[p + 1] * P.gradient[p + 1]) / m;
  P.mass[p] = m;
  P.s[p] = 0.5 * (a + b);
  P.length[p] = b - a;
  P.erase(p + 1);
  reset_reference(p);
}

void FluidSolver::merge_short() {
  auto& P = particles_;
  const double shortest = config_.merge_fraction * particle_length_;
  if (!(shortest > 0)) return;
  // The inlet particle (0) is left alone: the inlet keeps it between half and
  // twice particle_length. Any other short particle joins the shorter of its
  // neighbours (the last one joins the one before it).
  std::size_t p = 1;
  while (p < P.size() && P.size() > 1) {
    if (P.length[p] >= shortest) {
      ++p;
      continue;
    }
    const bool before = p + 1 == P.size() || P.length[p - 1] <= P.length[p + 1];
    merge(before ? p - 1 : p);
    if (before) p = std::max<std::size_t>(1, p - 1);
  }
}

void FluidSolver::outlet(double dt) {
  auto& P = particles_;
  if (!config_.outlet.enabled || P.size() == 0) return;
  const double end = grid_.length();
  if (!outlet_wetted_) {
    if (P.end(P.size() - 1) < end) return;
    outlet_wetted_ = true;
  }
  while (P.size() > 1 && P.start(P.size() - 1) >= end) {  // wholly beyond the outlet: gone
    outflow_mass_ += P.mass.back();
    P.erase(P.size() - 1);
  }
  const std::size_t q = P.size() - 1;
  const double a = P.start(q), b = P.end(q);
  if (!(a < end)) {
    throw std::runtime_error("fluid: the last particle crossed the outlet in one step (fluid leaves too fast)");
  }
  double dm = 0;  // mass that leaves
  if (b > end) {
    const double outside = grid_.width_integral(end, b), all = grid_.width_integral(a, b);
    dm = P.mass[q] * (all > 0 ? outside / all : (b - end) / (b - a));
  } else if (b < end) {
    const double p_out = std::max(0.0, config_.outlet.pressure(t_ + dt));
    dm = -config_.density / eos_.volume_ratio(p_out) * grid_.width_integral(b, end);
  }
  P.mass[q] -= dm;
  outflow_mass_ += dm;
  P.s[q] = 0.5 * (a + end);
  P.length[q] = end - a;
  P.gradient[q] = 0;  // cut at the outlet: its affine part no longer describes it
  reset_reference(q);
  if (q > 0 && P.length[q] < 0.5 * particle_length_) merge(q - 1);
}

}  // namespace hfmpm::fluid::mpm
