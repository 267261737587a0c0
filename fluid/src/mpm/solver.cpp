#include "hfmpm/fluid/mpm/solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <sstream>
#include <stdexcept>

namespace hfmpm::fluid::mpm {
namespace {

void require(bool ok, const char* key, double value, const char* allowed) {
  if (ok) return;
  std::ostringstream out;
  out << "fluid config: " << key << " = " << value << " is out of range; allowed: " << allowed;
  throw std::invalid_argument(out.str());
}

}  // namespace

FluidSolver::FluidSolver(FluidConfig config) : config_(std::move(config)) {
  const auto& c = config_;
  require(c.density > 0 && std::isfinite(c.density), "density", c.density, "> 0 kg/m^3");
  require(c.bulk_modulus > 0 && std::isfinite(c.bulk_modulus), "bulk_modulus", c.bulk_modulus, "> 0 Pa");
  require(c.tait_c > 0 && std::isfinite(c.tait_c), "tait_c", c.tait_c, "> 0 (0.0894 for water)");
  require(c.cfl > 0 && c.cfl <= 1, "cfl", c.cfl, "(0, 1]");
  require(c.lag_pressure >= 0 && std::isfinite(c.lag_pressure), "lag_pressure", c.lag_pressure, ">= 0 Pa");
  require(c.merge_fraction >= 0 && c.merge_fraction < 2, "merge_fraction", c.merge_fraction, ">= 0 and < 2");
  require(c.particle_length >= 0 && std::isfinite(c.particle_length), "particle_length", c.particle_length,
          ">= 0 m (0: half the mouth element)");
  require(c.flip >= 0 && c.flip <= 1, "flip", c.flip, "[0, 1]");
  require(c.min_width > 0 && std::isfinite(c.min_width), "min_width", c.min_width, "> 0 m");
  require(c.inlet.pre_opening >= 0 && std::isfinite(c.inlet.pre_opening), "inlet.pre_opening", c.inlet.pre_opening,
          ">= 0 m");
  require(c.inlet.pre_opening_length >= 0 && std::isfinite(c.inlet.pre_opening_length), "inlet.pre_opening_length",
          c.inlet.pre_opening_length, ">= 0 m");
  require(c.virtual_opening >= 0 && std::isfinite(c.virtual_opening), "virtual_opening", c.virtual_opening, ">= 0 m");
  eos_ = TaitEos{c.bulk_modulus, c.tait_c};
  rheology_ = c.rheology ? c.rheology : std::make_shared<const Newtonian>(c.viscosity);
}

void FluidSolver::set_crack(const CrackGeometry& crack) {
  const std::vector<double> old_arc = grid_.empty() ? std::vector<double>{} : grid_.arc();
  grid_.set(crack, config_.inlet.pre_opening, config_.inlet.pre_opening_length, config_.virtual_opening);
  if (config_.implicit_interface && !old_arc.empty()) {
    // The fluid moves with the crack along itself (the walls carry it): each
    // particle end keeps its place within its element as the nodes move.
    // Left out, a stiff fluid is squeezed or stretched by the crack's own
    // in-plane motion (0.2 um of a 17 mm element is 24 kPa of water).
    // A tip element that the solid lengthened by growth (its tip particle
    // moved ahead; elastic stretching is orders of magnitude below 10%) is
    // new crack, not stretched wall: the fluid in it moves with the node
    // behind it.
    const std::size_t m = old_arc.size();
    std::vector<double> moved(m);
    std::copy_n(grid_.arc().begin(), m, moved.begin());
    const double tip_before = old_arc[m - 1] - old_arc[m - 2], tip_after = moved[m - 1] - moved[m - 2];
    const bool extended = tip_after > 1.1 * tip_before;
    auto carry = [&](double s) {
      if (extended && s > old_arc[m - 2]) return std::min(moved[m - 2] + (s - old_arc[m - 2]), moved[m - 1]);
      return map_arc(s, old_arc, moved);
    };
    double previous = 0;  // the end of the particle before (FluidParticles::contiguous)
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      const double a = p == 0 ? carry(particles_.start(p)) : previous;
      const double b = carry(particles_.end(p));
      previous = b;
      particles_.f11[p] *= (b - a) / particles_.length[p];
      particles_.s[p] = 0.5 * (a + b);
      particles_.length[p] = b - a;
    }
  }
  wall_rate_ = crack.opening_rate;
  wall_acceleration_ = crack.opening_acceleration;
  wall_compliance_ = crack.opening_compliance;
  wall_band_ = crack.compliance_band;
  wall_plane_rate_ = crack.plane_rate;
  wall_plane_acceleration_ = crack.plane_acceleration;
  if (config_.lag == FluidConfig::Lag::TipAsymptote) {
    if (!(crack.tip_modulus > 0) || !(crack.resolution > 0)) {
      std::ostringstream out;
      out << "fluid: crack " << crack.crack_id << ": lag TIP_ASYMPTOTE needs the solid's tip_modulus_pa and "
          << "resolution_m (> 0) with the crack; got " << crack.tip_modulus << " Pa and " << crack.resolution
          << " m (0: the solid side does not send them; use lag FIXED_PRESSURE with such a side)";
      throw std::invalid_argument(out.str());
    }
    tip_modulus_ = crack.tip_modulus;
    resolution_ = crack.resolution;
  }
  const std::vector<double> carried = nodal_pressure_;  // what the faces carried over the last step
  if (particle_length_ == 0) {
    particle_length_ = config_.particle_length > 0 ? config_.particle_length : 0.5 * (grid_.arc()[1] - grid_.arc()[0]);
  }
  const std::size_t n = grid_.size();
  for (auto* field : {&mass_, &momentum_, &drag_, &force_, &v_old_, &v_new_}) field->assign(n, 0.0);
  nodal_pressure_.resize(n, 0.0);
  // The particles now see the new widths (F22, and so J and p, change).
  update_state();
  project_pressure();
  pressure_at_set_ = nodal_pressure_;
  if (config_.implicit_interface) {
    // How far the fluid's own state at the published crack is from the
    // pressure the faces carried (wetted nodes whose pressure no boundary holds).
    interface_mismatch_ = 0;
    const double front = front_position() + 1e-12 * grid_.length();
    const std::size_t first = config_.inlet.kind == InletConfig::Kind::Pressure ? 1 : 0;
    const std::size_t end = std::min(carried.size(), outlet_wetted_ ? n - 1 : n);
    for (std::size_t i = first; i < end && particles_.size() > 0; ++i) {
      if (grid_.arc()[i] > front) break;
      interface_mismatch_ = std::max(interface_mismatch_, std::abs(nodal_pressure_[i] - carried[i]));
    }
  }
}

double map_arc(double s, const std::vector<double>& from, const std::vector<double>& to) {
  const std::size_t n = from.size();
  if (s <= from[0]) return to[0] + (s - from[0]);
  if (s >= from[n - 1]) return to[n - 1] + (s - from[n - 1]);
  const HatPoint h = hat_at(from, s);
  return to[h.node] + h.n1 * (to[h.node + 1] - to[h.node]);
}

void FluidSolver::update_state(std::size_t p) {
  auto& P = particles_;
  const double a = P.start(p), b = P.end(p);
  P.width[p] = b > a ? grid_.width_integral(a, b) / (b - a) : grid_.width_at(P.s[p]);
  P.f22[p] = P.width[p] / P.w0[p];
  P.pressure[p] = eos_.pressure_no_tension(P.jacobian(p));
}

void FluidSolver::update_state() {
  auto& P = particles_;
  build_shapes();
  for (std::size_t p = 0; p < P.size(); ++p) update_state(p);
  if (config_.smooth_jacobian && P.size() > 0) element_pressure();
}

void FluidSolver::element_pressure() {
  // Element-constant pressure (the 1D analogue of the Q1-P0 element; cf.
  // Coombs, Charlton, Cortis and Augarde 2018, "Overcoming volumetric locking
  // in material point methods", CMAME 333): element e has the volume ratio of
  // the fluid inside it,
  //   J_e = sum_p f_pe V_p / sum_p f_pe V0_p,   V0_p = m_p / rho0,
  // f_pe the fraction of particle p's length inside element e (parts beyond
  // the ends count to the end elements), and particle p the pressure
  //   p_p = sum_e f_pe p(min(J_e, 1)).
  // With several particles per element, per-particle J of a nearly
  // incompressible fluid over-constrains the element strain rates
  // (volumetric locking): the particle pressures then take an intra-element
  // pattern the nodal forces cannot see, and the nodal pressures get noisy.
  // One pressure per element has no such pattern in 1D (every difference of
  // element pressures moves a node). The f_pe change continuously as
  // particles cross nodes. A uniform J is unchanged.
  auto& P = particles_;
  const auto& arc = grid_.arc();
  const std::size_t elements = grid_.size() - 1;
  auto& volume = mass_;  // scratch, per element
  auto& volume0 = force_;
  std::fill(volume.begin(), volume.end(), 0.0);
  std::fill(volume0.begin(), volume0.end(), 0.0);
  // Visit the element pieces of particle p: fn(element, length fraction).
  auto pieces = [&](std::size_t p, auto&& fn) {
    const double a = P.start(p), b = P.end(p), l = b - a;
    const std::size_t first = hat_at(arc, a).node, last = hat_at(arc, b).node;
    for (std::size_t e = first; e <= last; ++e) {
      const double lo = e == 0 ? a : std::max(a, arc[e]);
      const double hi = e + 1 == elements ? b : std::min(b, arc[e + 1]);
      if (hi > lo) fn(e, (hi - lo) / l);
    }
  };
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double v = P.volume(p), v0 = P.mass[p] / config_.density;
    pieces(p, [&](std::size_t e, double f) {
      volume[e] += f * v;
      volume0[e] += f * v0;
    });
  }
  for (std::size_t e = 0; e < elements; ++e) {
    volume[e] = volume0[e] > 0 ? eos_.pressure_no_tension(volume[e] / volume0[e]) : 0.0;  // now p_e
  }
  for (std::size_t p = 0; p < P.size(); ++p) {
    double pressure = 0;
    pieces(p, [&](std::size_t e, double f) { pressure += f * volume[e]; });
    P.pressure[p] = pressure;
  }
}

void FluidSolver::reset_reference(std::size_t p) {
  // After the mass or extent of a particle changed: a new reference state
  // with w0 = w (floored) and F11 such that m = rho0 (l / F11) w0 still holds,
  // so J = F11 F22 = rho0 l w / m.
  auto& P = particles_;
  const double a = P.start(p), b = P.end(p);
  P.width[p] = grid_.width_integral(a, b) / (b - a);
  P.w0[p] = std::max(P.width[p], config_.min_width);
  P.f11[p] = config_.density * P.length[p] * P.w0[p] / P.mass[p];
  update_state(p);
}

void FluidSolver::build_shapes() {
  shapes_.clear();
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    shapes_.add(grid_.arc(), particles_.start(p), particles_.end(p));
  }
}

void FluidSolver::step(double dt) {
  if (grid_.empty()) throw std::logic_error("fluid: set_crack() must be called before step()");
  if (!(dt > 0) || !std::isfinite(dt)) {
    throw std::invalid_argument("fluid: step dt must be finite and > 0 s, got " + std::to_string(dt));
  }
  const double injected_before = injected_mass_;
  if (particles_.size() > 0) {
    if (config_.outlet.enabled && particles_.end(particles_.size() - 1) >= grid_.length()) outlet_wetted_ = true;
    update_state();
    p2g();
    grid_update(dt);
    g2p(dt);
  }
  inlet(dt);
  outlet(dt);
  merge_short();
  t_ += dt;
  ++steps_;
  update_state();
  check_compression();
  project_pressure();
  inlet_flux_ = (injected_mass_ - injected_before) / (config_.density * dt);
}

int FluidSolver::advance(double dt_total) {
  if (!(dt_total > 0) || !std::isfinite(dt_total)) {
    throw std::invalid_argument("fluid: advance dt must be finite and > 0 s, got " + std::to_string(dt_total));
  }
  if (config_.implicit_interface) {  // one step: the solid's response holds for exactly this dt
    step_implicit(dt_total);
    return 1;
  }
  const double injected_before = injected_mass_;
  const double t_end = t_ + dt_total;
  int substeps = 0;
  for (;;) {
    const double remaining = t_end - t_;
    if (remaining <= 1e-12 * dt_total) break;
    const double substeps_left = std::max(1.0, std::ceil(remaining / stable_dt() - 1e-9));
    step(remaining / substeps_left);
    ++substeps;
  }
  t_ = t_end;
  inlet_flux_ = (injected_mass_ - injected_before) / (config_.density * dt_total);
  return substeps;
}

double FluidSolver::stable_dt() const {
  if (grid_.empty()) throw std::logic_error("fluid: set_crack() must be called before stable_dt()");
  double shortest = grid_.min_spacing();
  if (config_.implicit_interface) {
    // Pressure waves are implicit; a particle must not move more than a
    // fraction of its own length, nor of the shortest element, in a step.
    double limit = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      const double speed = std::abs(particles_.velocity[p]);
      if (speed > 0) limit = std::min(limit, std::min(particles_.length[p], shortest) / speed);
    }
    return config_.cfl * limit;
  }
  double speed = std::sqrt(config_.bulk_modulus / config_.density);
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    shortest = std::min(shortest, particles_.length[p]);
    speed = std::max(speed, eos_.sound_speed(particles_.jacobian(p), config_.density));
  }
  return config_.cfl * shortest / speed;
}

void FluidSolver::p2g() {
  const auto& P = particles_;
  const auto& arc = grid_.arc();
  const std::size_t n = grid_.size(), np = P.size();
  for (auto* field : {&mass_, &momentum_, &drag_, &force_}) std::fill(field->begin(), field->end(), 0.0);
  // Wall friction per unit volume, k_p (Pa s/m^2), for the whole batch.
  widths_floor_.resize(np);
  drag_k_.resize(np);
  for (std::size_t p = 0; p < np; ++p) widths_floor_[p] = std::max(P.width[p], config_.min_width);
  rheology_->drag(widths_floor_, P.velocity, drag_k_);
  const bool affine = config_.affine;
  for (std::size_t p = 0; p < np; ++p) {
    const CpdiRange r = shapes_.range[p];
    const double* N = shapes_.weight.data() + shapes_.offset[p];
    const double m = P.mass[p], mv = m * P.velocity[p];
    const double c = drag_k_[p] * P.length[p] * widths_floor_[p];  // N s/m^2: friction = -c v
    // APIC: node i gets m N_ip (v_p + g_p (s_i - sbar_p)), sbar_p = sum_i
    // N_ip s_i (the domain's centre, s_p inside the grid): the affine part
    // carries no net momentum, and a linear velocity field reaches every
    // node, the ends included, exactly.
    double centre = 0;
    if (affine) {
      for (std::size_t k = 0; k < r.count; ++k) centre += N[k] * arc[r.first + k];
    }
    const double mg = affine ? m * P.gradient[p] : 0.0;
    for (std::size_t k = 0; k < r.count; ++k) {
      mass_[r.first + k] += N[k] * m;
      momentum_[r.first + k] += N[k] * (mv + mg * (arc[r.first + k] - centre));
      drag_[r.first + k] += N[k] * c;
    }
    // Pressure force p_p [w N_i] from a_p to b_p (see solver.hpp).
    const double pressure = P.pressure[p];
    if (pressure > 0) {
      const double a = P.start(p), b = P.end(p);
      const HatPoint ha = hat_at(arc, a), hb = hat_at(arc, b);
      const double fa = pressure * grid_.width_at(a), fb = pressure * grid_.width_at(b);
      force_[ha.node] -= fa * ha.n0;
      force_[ha.node + 1] -= fa * ha.n1;
      force_[hb.node] += fb * hb.n0;
      force_[hb.node + 1] += fb * hb.n1;
    }
  }
  front_force(force_);
  // Boundary pressures: the inlet at the mouth pushes in; a wetted outlet pushes back.
  force_[0] += mouth_pressure() * grid_.width()[0];
  if (outlet_wetted_) force_[n - 1] -= std::max(0.0, config_.outlet.pressure(t_)) * grid_.width()[n - 1];
}

void FluidSolver::check_compression() const {
  // A failed solve, not a modelling limit: the soft stand-in fluids of the
  // lab-scale scenes pass their bulk modulus for a few steps at the start
  // (the toughness KGD's 2 MPa fluid reaches 1.01 K at 0.01 s) and recover.
  const double K = config_.bulk_modulus, limit = kCompressionLimit * K;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    if (!(particles_.pressure[p] <= limit)) {
      std::ostringstream out;
      out << "fluid: crack " << grid_.crack_id() << ": at t = " << t_ << " s the fluid at s = " << particles_.s[p]
          << " m is compressed to p = " << particles_.pressure[p] << " Pa, above " << kCompressionLimit
          << " times its bulk modulus " << K << " Pa (volume ratio below " << eos_.volume_ratio(limit)
          << "): the step that did it has failed: a coupled step too large (time.safety_factor; "
             "coupling.scheme: IMPLICIT), or fluid trapped in a crack closed to too little room "
             "(fluid.mpm.virtual_opening_m)";
      throw std::runtime_error(out.str());
    }
  }
}

void FluidSolver::grid_update(double dt) {
  // Momentum update with the wall friction implicit (backward Euler on -c v):
  // unconditionally stable however large c is.
  for (std::size_t i = 0; i < grid_.size(); ++i) {
    if (mass_[i] > 0) {
      v_old_[i] = momentum_[i] / mass_[i];
      v_new_[i] = (momentum_[i] + dt * force_[i]) / (mass_[i] + dt * drag_[i]);
    } else {
      v_old_[i] = v_new_[i] = 0;
    }
  }
  // Without an outlet the far end (the crack tip) is a wall: fluid may flow
  // back from it but not through it. (With a virtual opening the tip node is
  // not closed for the fluid, and particles ran past the tip, beyond the
  // grid, where the CPDI weights are clamped.)
  hold_at_tip(v_new_);
}

void FluidSolver::g2p(double dt) {
  auto& P = particles_;
  const auto& arc = grid_.arc();
  const double flip = config_.flip;
  double previous = 0;  // the end of the particle before, where this one starts (FluidParticles::contiguous)
  for (std::size_t p = 0; p < P.size(); ++p) {
    const CpdiRange r = shapes_.range[p];
    const double* N = shapes_.weight.data() + shapes_.offset[p];
    const double* G = shapes_.gradient.data() + shapes_.offset[p];
    double pic = 0, change = 0, gradient = 0;
    for (std::size_t k = 0; k < r.count; ++k) {
      pic += N[k] * v_new_[r.first + k];
      change += N[k] * (v_new_[r.first + k] - v_old_[r.first + k]);
      gradient += G[k] * v_new_[r.first + k];
    }
    P.velocity[p] = (1 - flip) * pic + flip * (P.velocity[p] + change);
    P.gradient[p] = config_.affine ? gradient : 0.0;  // the mean of dv/ds over the domain
    // CPDI corner update: both ends move with the grid velocity there.
    const double a = p == 0 ? P.start(p) + dt * interpolate(arc, v_new_, P.start(p)) : previous;
    const double b = moved_end(p + 1 == P.size(), P.end(p), a, P.end(p) + dt * interpolate(arc, v_new_, P.end(p)), arc,
                               grid_.width(), P.mass[p] / config_.density);
    previous = b;
    if (!(b > a)) {
      std::ostringstream out;
      out << "fluid: particle " << p << " at s = " << P.s[p] << " m turned inside out in a step of " << dt
          << " s (stable dt " << stable_dt() << " s); the step is too large";
      throw std::runtime_error(out.str());
    }
    P.f11[p] *= (b - a) / P.length[p];
    P.s[p] = 0.5 * (a + b);
    P.length[p] = b - a;
  }
}

}  // namespace hfmpm::fluid::mpm
