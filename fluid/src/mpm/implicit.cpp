// The implicit interface step (coupling.scheme IMPLICIT; docs/fluid.md,
// "The implicit interface step").
//
// Why. Stepped explicitly against a frozen crack, a stiff fluid can take the
// inflow of a step only by compressing: its pressure rises by about
// K dt (dw/dt) / w over each step, a rise the crack faces never carry
// (docs/stability.md, "The stiff-fluid lag"), and its own acoustic step is
// sqrt(K) times shorter than the solid's. Here the fluid's pressure over a
// step is instead solved together with the crack's opening over that step.
//
// The solid has done its P2G for the step and reported, per crack particle,
// the opening rate r_i, the opening acceleration a_i from every load but the
// face pressure, and the lumped compliance c_i (opening acceleration per Pa
// of face pressure). With face pressures p_i over the step, its explicit
// update opens node i to
//   w_i' = w_i + dt (r_i + dt (a_i + c_i p_i)),
// exactly for a uniform pressure while no contact acts (the response of an
// explicit step is affine in its load). The unknowns are the element
// pressures P_e (the fluid's element-constant pressure). A trial step with P
// moves the fluid as step() does (CPDI P2G forces from P, implicit wall
// friction, the corner update of every particle domain, the inlet's mass and
// the wetted outlet) and opens the crack by the response above under the
// nodal pressures P projects to; each element then holds fluid of volume V_e
// and zero-pressure volume V0_e, and the residual is
//   R_e(P) = P_e - p_Tait(V_e(P) / V0_e)   (p = 0 where J >= 1: no tension).
// R is close to affine in P (exactly, but for the width floors, the moved
// ends seeing the new widths and the no-tension cut), so Newton's method
// with one finite-difference Jacobian converges in a few iterations. P_e
// touches only the residuals of elements a few away, so the Jacobian is
// banded: it is built from one trial per colour (elements 2 jacobian_reach + 1 apart,
// perturbed together; implicit_detail.hpp) and factorised sparse.
//
// For an incompressible fluid P is the Lagrange multiplier that makes the
// crack's new volume hold the fluid it received; for a compressible one the
// compression is part of the same balance. Either way the faces carry, over
// the step, the pressure the fluid has at the step's end, and the step is
// limited by the solid's CFL and the fluid's advection, not by K.
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "hfmpm/fluid/mpm/solver.hpp"

#include "implicit_detail.hpp"

namespace hfmpm::fluid::mpm {

using namespace implicit_detail;  // NOLINT(google-build-using-namespace): this step's own helpers

void FluidSolver::pressure_force(const std::vector<double>& pp, double mouth, std::vector<double>& force) const {
  const auto& arc = grid_.arc();
  const std::size_t n = grid_.size();
  force.assign(n, 0.0);
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    if (!(pp[p] > 0)) continue;
    const double a = particles_.start(p), b = particles_.end(p);
    const HatPoint ha = hat_at(arc, a), hb = hat_at(arc, b);
    const double fa = pp[p] * grid_.width_at(a), fb = pp[p] * grid_.width_at(b);
    force[ha.node] -= fa * ha.n0;
    force[ha.node + 1] -= fa * ha.n1;
    force[hb.node] += fb * hb.n0;
    force[hb.node + 1] += fb * hb.n1;
  }
  force[0] += mouth * grid_.width()[0];
  front_force(force);
  if (outlet_wetted_) force[n - 1] -= std::max(0.0, config_.outlet.pressure(t_)) * grid_.width()[n - 1];
}

bool FluidSolver::interface_trial(const std::vector<double>& P, double dt, Trial& t,
                                  std::vector<double>& residual) const {
  const auto& arc = grid_.arc();
  const auto& part = particles_;
  const std::size_t n = grid_.size(), elements = n - 1, np = part.size();
  const double rho0 = config_.density;
  const auto& in = config_.inlet;
  t.squeezed = -1;
  t.why = "";
  // Particle pressures from the element pressures, and what the faces carry.
  t.pp.assign(np, 0.0);
  for (std::size_t p = 0; p < np; ++p)
    for (const auto& [e, f] : pieces_[p]) t.pp[p] += f * P[e];
  project_pressure(t.pp, t.nodal, t.scratch);
  // The fluid's momentum update under P (as p2g + grid_update).
  pressure_force(t.pp, t.nodal[0], t.force);
  t.v.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (mass_[i] > 0) t.v[i] = (momentum_[i] + dt * t.force[i]) / (mass_[i] + dt * drag_[i]);
  }
  hold_at_tip(t.v);
  // The crack at the end of the step, opened by the solid's response to the nodal pressures.
  const auto& crack = grid_.crack_width();
  const auto& effective = grid_.width();
  t.width.resize(n);
  t.opened.resize(n);
  const bool whole = wall_start_.size() != n;  // step_implicit sets the step's wall; else a whole step of dt
  const auto& start = whole ? crack : wall_start_;
  const double tau = whole ? dt : wall_tau_, span = whole ? dt : wall_dt_;
  const std::size_t band = wall_band_, row = 2 * band + 1;
  for (std::size_t i = 0; i < n; ++i) {
    double load = 0;  // m/s^2, sum_j C_ij p_j
    const std::size_t lo = i >= band ? i - band : 0, hi = std::min(n - 1, i + band);
    for (std::size_t j = lo; j <= hi; ++j) load += wall_compliance_[i * row + j + band - i] * t.nodal[j];
    // Over a fluid substep ending at tau within the solid's step of
    // wall_dt_, the opening the response gives at tau (tau = dt = wall_dt_
    // in a step taken whole: exactly the solid's update).
    const double opened = start[i] + tau * (wall_rate_[i] + span * (wall_acceleration_[i] + load));
    t.opened[i] = std::max(0.0, opened);
    t.width[i] = t.opened[i] + (effective[i] - crack[i]);  // + the virtual and pre-opening
  }
  // The particle domains at the end of the step (the CPDI corner update).
  t.a.resize(np);
  t.b.resize(np);
  t.mass.assign(part.mass.begin(), part.mass.end());
  for (std::size_t p = 0; p < np; ++p) {
    // A particle starts where the one before it ends (FluidParticles::contiguous).
    t.a[p] = p == 0 ? part.start(p) + dt * interpolate(arc, t.v, part.start(p)) : t.b[p - 1];
    t.b[p] = moved_end(p + 1 == np, part.end(p), t.a[p], part.end(p) + dt * interpolate(arc, t.v, part.end(p)), arc,
                       t.width, t.mass[p] / rho0);
    if (!(t.b[p] > t.a[p])) {
      t.squeezed = static_cast<std::ptrdiff_t>(p);
      t.why = "its ends cross";
      return false;
    }
  }
  // The inlet particle is re-extended to the mouth with the mass that crossed it (inlet()).
  if (np > 0) {
    if (in.kind == InletConfig::Kind::FlowRate) {
      t.mass[0] += inflow_mass(dt);
    } else if (t.a[0] > 0) {
      const double p_m = entrance_pressure(t_ + dt, t.v[0]);  // inlet(): the static pressure at the mouth
      t.mass[0] += rho0 / eos_.volume_ratio(p_m) * integrate(arc, t.width, 0.0, t.a[0]);
    } else if (t.a[0] < 0) {
      const double all = integrate(arc, t.width, t.a[0], t.b[0]), outside = integrate(arc, t.width, t.a[0], 0.0);
      t.mass[0] -= t.mass[0] * (all > 0 ? outside / all : -t.a[0] / (t.b[0] - t.a[0]));
    }
    t.a[0] = 0;
    if (!(t.b[0] > 0) || !(t.mass[0] > 0)) {
      // The inlet particle flows back out of the mouth, or empties: merged
      // with its neighbour it is long enough to stay in (Squeezed below).
      t.squeezed = 0;
      t.why = "the inlet particle leaves through the mouth";
      return false;
    }
    // A wetted outlet cuts the last particle at the end of the crack (outlet()).
    if (outlet_wetted_) {
      const std::size_t q = np - 1;
      const double end = grid_.length();
      if (t.b[q] > end) {
        const double all = integrate(arc, t.width, t.a[q], t.b[q]), outside = integrate(arc, t.width, end, t.b[q]);
        t.mass[q] -= t.mass[q] * (all > 0 ? outside / all : (t.b[q] - end) / (t.b[q] - t.a[q]));
      } else if (t.b[q] < end) {
        const double p_out = std::max(0.0, config_.outlet.pressure(t_ + dt));
        t.mass[q] += rho0 / eos_.volume_ratio(p_out) * integrate(arc, t.width, t.b[q], end);
      }
      t.b[q] = end;
      if (!(t.b[q] > t.a[q])) {
        t.squeezed = static_cast<std::ptrdiff_t>(q);
        t.why = "the outlet particle leaves through the outlet";
        return false;
      }
    }
  }
  // The crack moves along itself and carries the fluid (set_crack maps the
  // particles the same way when the solid publishes the crack).
  const auto& end_arc = predicted_arc_.size() == n ? predicted_arc_ : arc;
  if (&end_arc != &arc) {
    for (std::size_t p = 0; p < np; ++p) {
      t.a[p] = map_arc(t.a[p], arc, end_arc);
      t.b[p] = map_arc(t.b[p], arc, end_arc);
    }
  }
  // Each element's fluid: its volume in the opened crack against its zero-pressure volume.
  t.volume.assign(elements, 0.0);
  t.volume0.assign(elements, 0.0);
  for (std::size_t p = 0; p < np; ++p) {
    const double v = integrate(end_arc, t.width, t.a[p], t.b[p]), v0 = t.mass[p] / rho0;
    for_pieces(end_arc, t.a[p], t.b[p], [&](std::size_t e, double f) {
      t.volume[e] += f * v;
      t.volume0[e] += f * v0;
    });
  }
  residual.resize(elements);
  for (std::size_t e = 0; e < elements; ++e) {
    // Volume strain the fluid leaves unfilled (> 0) or overfills (< 0) at
    // its pressure P_e; an empty element never constrains P (g = 1).
    residual[e] = t.volume0[e] > 0 ? t.volume[e] / t.volume0[e] - eos_.volume_ratio(P[e]) : 1.0;
  }
  return true;
}

void FluidSolver::step_implicit(double dt) {
  if (grid_.empty()) throw std::logic_error("fluid: set_crack() must be called before step_implicit()");
  if (!(dt > 0) || !std::isfinite(dt)) {
    throw std::invalid_argument("fluid: step dt must be finite and > 0 s, got " + std::to_string(dt));
  }
  const std::size_t n = grid_.size();
  if (wall_rate_.size() != n || wall_acceleration_.size() != n || wall_compliance_.size() != n * (2 * wall_band_ + 1)) {
    throw std::logic_error(
        "fluid: the implicit interface step needs the solid's face response (CrackGeometry::opening_rate, "
        "opening_acceleration, opening_compliance) with every crack; the last crack had none");
  }
  const double injected_before = injected_mass_, t_start = t_;
  interface_iterations_ = 0;
  interface_residual_ = 0;
  interface_substeps_ = 1;
  interface_above_bound_ = false;
  interface_retry_why_.clear();
  std::vector<double> faces;  // the pressures the faces carry over this step
  if (particles_.size() > 0) {
    // The solid's response holds for the whole step: the crack as it was
    // published, and where its nodes are.
    wall_start_ = grid_.crack_width();
    wall_start_position_ = grid_.position();
    wall_dt_ = dt;
    // What a failed attempt restores (the fluid's state at the step's start).
    const FluidParticles particles = particles_;
    const CrackGrid grid = grid_;
    const double injected = injected_mass_, outflow = outflow_mass_;
    const bool wetted = outlet_wetted_;
    const std::vector<double> solved = solved_;
    auto restore = [&] {
      particles_ = particles;
      grid_ = grid;
      injected_mass_ = injected;
      outflow_mass_ = outflow;
      outlet_wetted_ = wetted;
      solved_ = solved;
      t_ = t_start;
    };
    for (int substeps = 1;; substeps *= 2) {
      try {
        for (int k = 1; k <= substeps; ++k) {
          // Substep k ends at tau = k dt / substeps; the last one at dt exactly.
          const double tau = k == substeps ? dt : dt * k / substeps;
          faces = implicit_substep(tau - (t_ - t_start), tau, k == substeps);
        }
        interface_substeps_ = substeps;
        break;
      } catch (const StepFailed& failed) {
        if (substeps >= kMaxSubsteps && failed.misfit && !interface_above_bound_) {
          // Every try ended above the bound without turning a particle
          // inside out: the step is taken whole at its best iterate, as
          // before this remedy existed (a stop here failed seven coupled
          // KGD and stability tests whose steps so committed were rare and
          // small), and reported (fluid.log, and counted).
          restore();
          interface_above_bound_ = true;
          interface_retry_why_ = failed.message;
          try {
            faces = implicit_substep(dt, dt, true);
          } catch (const StepFailed& whole) {
            interface_above_bound_ = false;
            wall_start_.clear();
            throw std::runtime_error("fluid: crack " + std::to_string(grid_.crack_id()) +
                                     ": at t = " + std::to_string(t_start) +
                                     " s the implicit interface step cannot be solved: " + whole.message);
          }
          ++interface_committed_above_;
          interface_substeps_ = 1;
          break;
        }
        if (substeps >= kMaxSubsteps) {
          wall_start_.clear();
          std::ostringstream out;
          out << "fluid: crack " << grid_.crack_id() << ": at t = " << t_start << " s the implicit interface step of "
              << dt << " s cannot be solved, also in " << substeps << " fluid substeps of " << dt / substeps
              << " s against the faces' response interpolated over the step: " << failed.message
              << ". The fluid cannot follow the crack over this step (docs/fluid.md, \"The implicit interface "
                 "step\"); the step was not committed";
          throw std::runtime_error(out.str());
        }
        if (substeps == 1) interface_retry_why_ = failed.message;
        restore();
      }
    }
    interface_newton_ += static_cast<std::uint64_t>(interface_iterations_);
    if (interface_substeps_ > 1) {
      ++interface_subcycled_;
      interface_max_substeps_ = std::max(interface_max_substeps_, static_cast<std::uint64_t>(interface_substeps_));
    }
    t_ = t_start + dt;
    wall_start_.clear();
  } else {
    inlet(dt);
    outlet(dt);
    merge_short();
    t_ += dt;
  }
  ++steps_;
  inlet_flux_ = (injected_mass_ - injected_before) / (config_.density * dt);
  if (faces.empty()) {
    // Nothing flowed yet (or the first particle was just seeded): the state's pressure.
    update_state();
    project_pressure();
  } else {
    // The pressures the faces carry over the step just taken; the particles'
    // own state follows from the crack the solid publishes next (set_crack).
    nodal_pressure_ = std::move(faces);
  }
}

}  // namespace hfmpm::fluid::mpm
