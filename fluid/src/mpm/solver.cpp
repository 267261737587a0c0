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
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      const double a = carry(particles_.start(p));
      const double b = carry(particles_.end(p));
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
  for (std::size_t p = 0; p < np; ++p) {
    const CpdiRange r = shapes_.range[p];
    const double* N = shapes_.weight.data() + shapes_.offset[p];
    const double m = P.mass[p], mv = m * P.velocity[p];
    const double c = drag_k_[p] * P.length[p] * widths_floor_[p];  // N s/m^2: friction = -c v
    for (std::size_t k = 0; k < r.count; ++k) {
      mass_[r.first + k] += N[k] * m;
      momentum_[r.first + k] += N[k] * mv;
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

double FluidSolver::front_speed() const {
  const std::size_t np = particles_.size();
  if (np == 0) return 0.0;
  // The mass-weighted mean velocity of the fluid within d of the front. (The
  // front particle's own velocity jumps as particles merge and as it crosses
  // into a new element: with it as the closure's V, two runs that differed
  // only in the fluid's stiffness differed by 3% in opening and pressure,
  // against 0.8%.)
  const std::size_t last = np - 1;
  const double front = particles_.end(last);
  double m = 0, mv = 0;
  for (std::size_t p = np; p-- > 0;) {
    if (p < last && particles_.s[p] < front - resolution_) break;
    m += particles_.mass[p];
    mv += particles_.mass[p] * particles_.velocity[p];
  }
  return m > 0 ? std::max(0.0, mv / m) : 0.0;
}

double FluidSolver::front_counter_pressure() const {
  const std::size_t np = particles_.size();
  if (config_.lag != FluidConfig::Lag::TipAsymptote || np == 0) return 0.0;
  // The zero-toughness, zero-lag tip solution of a crack running at V
  // (Desroches et al. 1994; docs/fluid.md): w = beta_m (mu' V / E')^(1/3) s^(2/3)
  // and, from the lubrication flux V w = -(w^3 / mu') dp/ds,
  // p = -(3 / beta_m^2) (mu' V E'^2)^(1/3) s^(-1/3).
  constexpr double kBetaSquared = 9.9057817466838;  // beta_m^2 = 2^(2/3) 3^(5/3)
  const std::size_t last = np - 1;
  const double V = front_speed();
  const double w = std::max(particles_.width[last], config_.min_width);
  double k = 0;  // Pa s / m^2, the drag coefficient at the front particle's width and speed V
  rheology_->drag(std::span<const double>(&w, 1), std::span<const double>(&V, 1), std::span<double>(&k, 1));
  const double mu_prime = k * w * w;  // 12 mu for a Newtonian fluid
  const double A = 3.0 / kBetaSquared * std::cbrt(mu_prime * V * tip_modulus_ * tip_modulus_);  // Pa m^(1/3)
  if (!config_.tip_level_matched) {
    // lag TIP_ASYMPTOTE: the tip solution's pressure one cell d from the
    // tip, about the lag pressure (the confining stress) as its level.
    return std::max(0.0, config_.lag_pressure - A / std::cbrt(resolution_));
  }
  // lag TIP_ASYMPTOTE_MATCHED. The tip solution fixes the pressure's fall
  // towards the tip, not its level: near a tip p = p0 - A s^(-1/3) +
  // O(s^(1/3)), where p0 comes from the whole crack (in the KGD M-vertex it
  // is 1.30 times the net inlet pressure above the confining stress; p +
  // A s^(-1/3) is 1.305 to 1.349 times it from s = 0.01 to 0.2 of the
  // half-length: `tools/kgd_transition.py --tip-closure`). Taken as the
  // confining stress (TIP_ASYMPTOTE) the level over-sucks the front by about
  // p0 once the crack's widths are read right, and ran kgd-viscosity-ci's
  // front 6-8% long, an error that fell only as (h / l)^(1/3) (docs/fluid.md).
  // Here p0 is the mean of p + A s^(-1/3) over the fluid's pressures two to
  // four solid cells d behind the front (with the implicit interface step the
  // element pressures the last step solved, at the elements' centres: the
  // particles' own state at the crack the solid then published differs from
  // them by the step's small misfit times the fluid's bulk modulus, tens of
  // kPa for water; else the nodal pressures). Nearer the front the level
  // followed each growth step's dip in pressure there and deepened it: two
  // runs that differed only in the fluid's stiffness then differed by 2.1-2.8%
  // in inlet pressure at a row. For a fluid shorter than that, the point d
  // behind the front (at least the mouth). The front meets p0 - A s_f^(-1/3),
  // s_f its distance from the tip but at least d / 2 (the tip segment the
  // fluid cannot enter is up to half a cell; a floor of d / 4 let the front's
  // pressure jump with every quarter-cell growth step); never more than the
  // lag pressure (a viscous tip's net pressure is negative, which also starts
  // a fluid at rest, V = 0) and never less than a vacuum.
  const double front = particles_.end(last);
  const double tip = grid_.length(), d = resolution_;
  const double s_f = std::max(tip - front, 0.5 * d);
  const auto& arc = grid_.arc();
  const bool solved = config_.implicit_interface && !solved_.empty() && solved_[0] > 0;
  const std::size_t samples = solved ? std::min(solved_.size(), arc.size() - 1) : arc.size();
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t e = 0; e < samples; ++e) {
    const double x = solved ? 0.5 * (arc[e] + arc[e + 1]) : arc[e];
    const double p = solved ? solved_[e] : nodal_pressure_[e];
    if (x < front - 4 * d || x > front - 2 * d || !(p > 0)) continue;
    sum += p + A / std::cbrt(tip - x);
    ++count;
  }
  double p0 = 0;
  if (count > 0) {
    p0 = sum / static_cast<double>(count);
  } else {
    const double at = std::max(0.0, front - d);
    const std::size_t e = std::min(hat_at(arc, at).node, samples - 1);
    p0 = (solved ? solved_[e] : grid_.interpolate(at, nodal_pressure_)) + A / std::cbrt(tip - at);
  }
  const double matched = p0 - A / std::cbrt(s_f);
  return std::max(0.0, std::min(config_.lag_pressure, matched));
}

void FluidSolver::front_force(std::vector<double>& force) const {
  const double counter = front_counter_pressure();
  if (!(counter > 0)) return;
  const double b = particles_.end(particles_.size() - 1);
  const HatPoint hb = hat_at(grid_.arc(), b);
  const double fb = counter * grid_.width_at(b);
  force[hb.node] -= fb * hb.n0;
  force[hb.node + 1] -= fb * hb.n1;
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

void FluidSolver::hold_at_tip(std::vector<double>& v) const {
  if (tip_holds_fluid()) v.back() = std::min(0.0, v.back());
}

bool FluidSolver::tip_holds_fluid() const {
  if (config_.outlet.enabled) return false;
  if (config_.lag != FluidConfig::Lag::Front) return true;
  // The zero-lag closure: the fluid fills the crack to its tip, and the tip
  // is a wall once the fluid is there. Held from within the tip element, the
  // front stopped where the tip node's hat pushed it back, half a cell short,
  // and was squeezed there by its own push into the dry crack (the fluid
  // meets no counter-pressure with this closure): the last crack particle
  // carried twice the crack's net pressure in kgd-toughness-ci, and at full
  // size the crack pinched shut behind a stalled tip (docs/verification.md,
  // "The toughness scenes' front").
  const std::size_t np = particles_.size();
  return np > 0 && particles_.end(np - 1) >= grid_.length() * (1 - 1e-12);
}

double FluidSolver::end_at_tip(double b) const {
  // With the zero-lag closure a particle's end stops at the tip (above).
  return !config_.outlet.enabled && config_.lag == FluidConfig::Lag::Front ? std::min(b, grid_.length()) : b;
}

double FluidSolver::front_end_at_rest(std::span<const double> arc, std::span<const double> width, double a, double b,
                                      double rest_volume) const {
  // With the zero-lag closure the front, free of the tip's hold, is drawn
  // into the dry crack by its own pressure; it may go only as far as its
  // fluid fills the crack at zero pressure (J = 1), not stretch past it
  // and cavitate (a 2 MPa fluid's front did, into each new segment, and the
  // faces, unloaded, slammed shut). Bisection on the end: the volume is
  // increasing in it.
  if (config_.outlet.enabled || config_.lag != FluidConfig::Lag::Front || !(b > a)) return b;
  if (!(integrate(arc, width, a, b) > rest_volume)) return b;
  double lo = a, hi = b;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (integrate(arc, width, a, mid) > rest_volume ? hi : lo) = mid;
  }
  return lo;
}

void FluidSolver::g2p(double dt) {
  auto& P = particles_;
  const auto& arc = grid_.arc();
  const double flip = config_.flip;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const CpdiRange r = shapes_.range[p];
    const double* N = shapes_.weight.data() + shapes_.offset[p];
    double pic = 0, change = 0;
    for (std::size_t k = 0; k < r.count; ++k) {
      pic += N[k] * v_new_[r.first + k];
      change += N[k] * (v_new_[r.first + k] - v_old_[r.first + k]);
    }
    P.velocity[p] = (1 - flip) * pic + flip * (P.velocity[p] + change);
    // CPDI corner update: both ends move with the grid velocity there.
    const double a = P.start(p) + dt * interpolate(arc, v_new_, P.start(p));
    double b = end_at_tip(P.end(p) + dt * interpolate(arc, v_new_, P.end(p)));
    if (p + 1 == P.size() && b > P.end(p))
      b = std::max(P.end(p), front_end_at_rest(arc, grid_.width(), a, b, P.mass[p] / config_.density));
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
