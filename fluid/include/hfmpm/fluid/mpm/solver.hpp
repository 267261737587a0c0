// 1D MPM of the fluid in one crack (nested-manifold MPM, docs/fluid.md).
//
// Momentum balance. Width-averaged (lubrication) flow in a channel of opening
// w(s), per unit thickness and per unit length along the crack:
//   rho w Dv/Dt = -d(p w)/ds + p dw/ds - k(w, v) w v  =  -w dp/ds - k w v,
// where p dw/ds is the push of the (inclined) crack faces on the slice and
// k = 12 mu / w^2 for a Newtonian fluid (Rheology). The face term matters: a
// fluid at rest under a uniform pressure in a tapering crack must stay at rest.
// Weak form with the hats N_i, the pressure constant over each particle domain
// [a_p, b_p], the inlet pressure p_in at the mouth and p = 0 beyond the front:
//   -int w dp/ds N_i ds = sum_p p_p [w N_i]_{a_p}^{b_p} + p_in w(0) N_i(0)
// (integrate by parts on each particle; the jumps of p between particles are
// the interface forces). So the internal force is
//   f_i = sum_p p_p (w(b_p) N_i(b_p) - w(a_p) N_i(a_p)),
// which in a channel of constant width is the usual CPDI form
// sum_p p_p V_p Gbar_ip with V_p = l_p w. (Dropping the face term gives
// sum_p p_p V_p Gbar_ip everywhere, which drives a spurious flow towards the
// narrow end of a tapering crack at uniform pressure.)
// Friction: c_i = sum_p Nbar_ip k_p V_p, integrated implicitly on the grid:
//   v_i^{n+1} = (m_i v_i^n + dt f_i) / (m_i + dt c_i),
// so vanishing widths near the tip do not limit dt.
//
// One step (update stress last):
//   1. particle state from the current crack: w_p = mean effective width over
//      [a_p, b_p], F22 = w / w0, J = F11 F22; the pressure from the Tait law
//      with J limited to <= 1 (no tension), by default one pressure per
//      element from the volume ratio of the fluid in it (element_pressure(),
//      against volumetric locking; config smooth_jacobian);
//   2. P2G with the CPDI weights: m_i, m_i v_i, c_i, f_i (+ the inlet and
//      outlet boundary forces);
//   3. grid velocities with the implicit friction;
//   4. G2P: v_p from the new grid velocities (PIC, or a FLIP blend); the two
//      ends of each domain move with the grid velocity there (the CPDI
//      corner update), so neighbours stay contiguous;
//      F11 <- F11 l^{n+1} / l^n = (1 + Gbar v dt) F11 with Gbar v = dv/ds the
//      CPDI velocity gradient: the same to first order in dt as
//      exp(dv/ds dt) F11, but consistent with the moved ends;
//      with the exponential and l = l0 F11, the ends of neighbours would drift
//      apart, opening gaps and overlaps between particles;
//   5. inlet (and outlet): the inlet particle is re-extended to the mouth and
//      given the mass that entered; it is split when it grows long;
//   6. state and nodal pressures at the end of the step.
//
// Known limitations (measured in tests/fluid):
// - A sudden start (a step in the inlet flow rate, a water hammer of
//   rho c v >> the viscous pressure) leaves particle-to-particle differences
//   of J that the element pressure does not see but that are carried with the
//   fluid (with more particles than elements the split of an element's volume
//   among its particles is not controlled): nodal pressures then wander by
//   ~10% until those particles leave. A ramp over a few
//   tau = rho w^2 / (12 mu) avoids it.
// - Nodal pressures are a lumped (mass-weighted) projection: first order on
//   an uneven grid (off by ~ (h_i - h_{i-1}) / 4 times the gradient).
// - The fluid does not follow the crack's own motion along itself: particles
//   keep their arc length when the grid moves (no convection of the fluid
//   with a stretching crack), and curvature forces are ignored.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/fluid/mpm/config.hpp"
#include "hfmpm/fluid/mpm/crack_grid.hpp"
#include "hfmpm/fluid/mpm/eos.hpp"
#include "hfmpm/fluid/mpm/particles.hpp"
#include "hfmpm/fluid/mpm/shape.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::fluid::mpm {

// Arc length s on the grid `from` carried to the grid `to` (same node
// count): the same fraction of its element; beyond the ends, shifted with
// the end node.
double map_arc(double s, const std::vector<double>& from, const std::vector<double>& to);

class FluidSolver {
 public:
  // Throws std::invalid_argument naming a config field that is out of range.
  explicit FluidSolver(FluidConfig config);

  // The crack (the grid) as the solid published it; call before every step.
  // Nodes are appended when the crack grows; see CrackGrid::set for what is rejected.
  void set_crack(const CrackGeometry& crack);
  // Initial condition: fill [0, front] (m) with fluid at rest at `pressure`
  // (Pa, >= 0), in particles of about particle_length. Only into an empty crack.
  void fill(double front, double pressure);

  // One explicit step of dt (s); dt must not exceed stable_dt().
  void step(double dt);
  // Advance by dt_total (s) in equal substeps no longer than stable_dt() (the
  // crack is frozen meanwhile). Returns the number of substeps.
  int advance(double dt_total);
  // s, cfl * min(smallest particle length, smallest node spacing) / c, with
  // c the fastest sound speed of the particles (>= sqrt(K / rho0)); with
  // implicit_interface (pressure waves implicit, advection explicit) the
  // smallest over the particles of cfl * min(l_p, smallest node spacing) /
  // |v_p| (+inf at rest).
  double stable_dt() const;
  // One implicit interface step of dt (implicit.cpp): the element pressures
  // P_e over the step are solved so that each element's fluid, after the
  // step's flow and inflow, fills the crack as the solid's reported response
  // opens it under those pressures,
  //   P_e = p_Tait(V_e(P) / V0_e),
  //   w_i(t + dt) = w_i + dt (rate_i + dt (acceleration_i + sum_j C_ij p_j(P))),
  // by Newton's method on a finite-difference Jacobian (banded, found by
  // colouring). The fluid then moves under P, and the nodal pressures it
  // reports are the ones the faces must carry over the same step. Needs the
  // solid's response with the last set_crack(); throws std::logic_error
  // without it. A step whose solve fails (Newton's method ends with an
  // element misfit |Phi_e| V0_e above 1e-8 of the crack's fluid, or every
  // start turns a particle inside out) is not committed: it is taken again in 2, 4, ... kMaxSubsteps fluid substeps,
  // each solved against the faces' response at its end (the opening interpolated linearly over the step, as if its
  // pressure held all step); the last substep ends at dt, where the response is the solid's own. If that fails too, a
  // step whose solve ended above the bound is taken whole at its best iterate and reported
  // (interface_committed_above_bound); one that turns a particle inside out throws std::runtime_error naming the
  // particle and why.
  void step_implicit(double dt);
  // Implicit interface: Pa, the largest difference at a wetted node between
  // the pressure the faces carried over the last step and the fluid's
  // pressure at the crack the solid then published (0 if consistent; the
  // lumped response and contact make it differ). Newton's last residual, Pa.
  double interface_mismatch() const { return interface_mismatch_; }
  double interface_residual() const { return interface_residual_; }
  int interface_iterations() const { return interface_iterations_; }
  // Over the run: Newton iterations, solves that stopped above the tolerance
  // (committed if no element misfit exceeds 1e-8 of the crack's fluid,
  // else retried in fluid substeps), particles merged before a step.
  std::uint64_t interface_newton_total() const { return interface_newton_; }
  std::uint64_t interface_unconverged_steps() const { return interface_unconverged_; }
  std::uint64_t interface_merges() const { return interface_merges_; }
  // Solves that the forward-difference Jacobian left above the tolerance and
  // the careful one finished (implicit.cpp); steps taken in more than one
  // fluid substep, and the most substeps one step took.
  std::uint64_t interface_rescued() const { return interface_rescued_; }
  std::uint64_t interface_subcycled_steps() const { return interface_subcycled_; }
  std::uint64_t interface_max_substeps() const { return interface_max_substeps_; }
  // Steps that no number of substeps up to kMaxSubsteps solved within the
  // bound and that were taken whole at their best iterate (reported).
  std::uint64_t interface_committed_above_bound() const { return interface_committed_above_; }
  bool interface_last_above_bound() const { return interface_above_bound_; }
  // The last step: its fluid substeps (1: taken whole), and why the whole
  // step failed when it was subcycled ("" otherwise).
  int interface_substeps() const { return interface_substeps_; }
  const std::string& interface_retry_why() const { return interface_retry_why_; }
  // The most fluid substeps step_implicit tries (doubling from 1) before it
  // stops the run.
  static constexpr int kMaxSubsteps = 256;

  // A flow-rate inlet feeds this crack share x Q(t) + transfer (m^2/s; by
  // default 1 x Q(t) + 0): one wing of a crack entered at an inner particle
  // takes half of a wellbore's Q(t) and the flow the junction passes to it
  // from the other wing (two_wing.hpp; may be negative). Throws
  // std::invalid_argument unless 0 <= share <= 1 and transfer is finite.
  void set_inlet_split(double share, double transfer);
  double inlet_share() const { return inlet_share_; }
  double inlet_transfer() const { return inlet_transfer_; }

  double time() const { return t_; }
  std::uint64_t steps() const { return steps_; }
  const FluidConfig& config() const { return config_; }
  const TaitEos& eos() const { return eos_; }
  const CrackGrid& grid() const { return grid_; }
  const FluidParticles& particles() const { return particles_; }

  // Output.
  std::vector<Vec2> particle_positions() const;  // m, centres on the crack polyline
  // Pa per crack node: mass-weighted CPDI projection of the particle
  // pressures, >= 0, and 0 at nodes beyond the front; the mouth node carries
  // the inlet pressure (and a wetted outlet node the outlet pressure).
  const std::vector<double>& nodal_pressure() const { return nodal_pressure_; }
  // Pa/m per crack node, -dp/dw: how fast the nodal pressure falls as the
  // crack opens there (the fluid's tangent bulk modulus K_t J over the width;
  // 0 where the pressure does not follow the width). The solid uses it to
  // treat the pressure's change over its own step implicitly (the explicit
  // coupling of a stiff fluid is otherwise unstable: docs/fluid.md, docs/solid.md).
  std::vector<double> nodal_stiffness() const;  // computed when called (once per exchange)
  CrackPressure pressure_message() const;
  // Pa, the largest change of a wetted node's pressure since the last
  // set_crack(): what the fluid's pressure did while the crack was frozen
  // (inflow it compressed, outflow it relaxed). In a coupled run the crack
  // faces never carried this part of the pressure, and the fluid's flow
  // over the step was driven by it: with a stiff fluid it is the coupling's
  // lag error, about K dt (dw/dt) / w (docs/stability.md, "The stiff-fluid
  // lag"). Nodes whose pressure a boundary holds are left out.
  double frozen_width_rise() const;
  // m, arc length of the front (the end of the last particle), at most the crack length; 0 when empty.
  double front_position() const;
  // Pa, the pressure beyond the front that the fluid front pushes against:
  // 0 (a vacuum), or with Lag::TipAsymptote the tip solution's (config.hpp).
  double front_counter_pressure() const;
  // m/s, the front's speed: the mass-weighted mean velocity of the fluid within the solid's cell of the front.
  double front_speed() const;
  // Pa, the inlet's pressure: the well's p_in(t) behind a pressure inlet
  // (the mouth's static pressure is below it by the inflow's rho v^2 / 2,
  // nodal_pressure()[0]), or for a flow-rate inlet the mouth's, solved.
  double inlet_pressure() const;
  // m^2/s, zero-pressure volume per second that came in over the last advance() (or step()).
  double inlet_flux() const { return inlet_flux_; }
  double injected_volume() const { return injected_mass_ / config_.density; }  // m^2, zero-pressure volume in
  double injected_mass() const { return injected_mass_; }                      // kg/m, through the mouth (net)
  double outflow_mass() const { return outflow_mass_; }                        // kg/m, out through the outlet (net)
  double fluid_mass() const;                                                   // kg/m, sum of particle masses
  double fluid_volume() const;                                                 // m^2, sum of l w
  double kinetic_energy() const;                                               // J/m

  // Checkpoints (checkpoint.cpp): everything a later step, report or output
  // reads: the grid (the crack as last set, with the solid's response), the
  // particles, the nodal fields, the shape table, the inlet's and outlet's
  // accounts, time and step, the implicit interface's state and counters.
  // load() into a solver built from the same config restores it bit for bit.
  void save(StateWriter& out) const;
  void load(const StateReader& in);

 private:
  void update_state(std::size_t p);  // w, F22, p of one particle from the crack
  void update_state();
  void element_pressure();              // element-constant pressure (smooth_jacobian)
  void reset_reference(std::size_t p);  // w0 = w, F11 from the mass (after mass changed)
  void build_shapes();
  void p2g();
  void grid_update(double dt);
  void g2p(double dt);
  // inlet.cpp
  double mouth_pressure() const;  // boundary pressure at the mouth for the force
  // Pa, the static pressure at the mouth behind a pressure inlet at time t
  // with the fluid's velocity v there (m/s, > 0 inward): p_in(t) - rho v^2 / 2
  // for inflow, p_in(t) for outflow, at least 0 (InletConfig::pressure).
  double entrance_pressure(double t, double v) const;
  bool seed(double dt);
  void inlet(double dt);
  void outlet(double dt);
  void split_inlet();
  void merge(std::size_t p);  // merge particle p + 1 into p
  void merge_short();         // see FluidConfig::merge_fraction
  // Throws when a particle's pressure exceeds kCompressionLimit x the bulk
  // modulus (J < 0.37 for c = 0.0894): no coupled solution compresses a
  // liquid to a third of its volume, so the step that did it has failed.
  static constexpr double kCompressionLimit = 100;
  void check_compression() const;
  // nodal_pressure.cpp
  void project_pressure();
  // Nodal pressures from particle pressures `pp` (the mass-weighted CPDI
  // projection with the front, lag and boundary rules; see nodal_pressure()).
  void project_pressure(const std::vector<double>& pp, std::vector<double>& nodal, std::vector<double>& scratch) const;
  // implicit.cpp
  struct Trial {
    std::vector<double> pp, nodal, scratch, force, v, width, opened, a, b, mass, volume, volume0;
    std::ptrdiff_t squeezed = -1;  // a particle the step turned inside out (the trial failed), or -1
    const char* why = "";          // what failed the trial, for the error message
  };
  // Residual P_e - p_Tait(V_e / V0_e) of element pressures P after a trial step of dt.
  bool interface_trial(const std::vector<double>& P, double dt, Trial& t, std::vector<double>& residual) const;
  // One fluid substep of h ending at tau within the step step_implicit
  // takes (last: it ends the step); returns the nodal pressures the faces
  // carry. Throws StepFailed (implicit_detail.hpp) without committing anything if
  // the solve fails.
  std::vector<double> implicit_substep(double h, double tau, bool last);
  void pressure_force(const std::vector<double>& pp, double mouth, std::vector<double>& force) const;
  // The push of front_counter_pressure() back on the front end (a no-op when it is 0).
  void front_force(std::vector<double>& force) const;
  // The zero-lag closure (Lag::Front, no outlet) fills the crack to its tip
  // (fluid/src/mpm/front.cpp).
  bool fills_to_tip() const;
  // Whether the closed tip's node holds the fluid back this step (its
  // velocity at most 0): always without an outlet, but when the fluid fills
  // to the tip only once it has reached it.
  bool tip_holds_fluid() const;
  void hold_at_tip(std::vector<double>& v) const;  // the tip node's velocity, as above
  // A particle end moved from old_end to b (its start at a): when the fluid
  // fills to the tip, no further than the tip, and the front's (front) no
  // further than its rest volume fills the crack's width (no cavitating
  // stretch). Otherwise b.
  double moved_end(bool front, double old_end, double a, double b, std::span<const double> arc,
                   std::span<const double> width, double rest_volume) const;

  FluidConfig config_;
  TaitEos eos_;
  std::shared_ptr<const Rheology> rheology_;
  CrackGrid grid_;
  FluidParticles particles_;
  ShapeTable shapes_;
  // nodal fields
  std::vector<double> mass_, momentum_, drag_, force_, v_old_, v_new_, nodal_pressure_;
  std::vector<double> pressure_at_set_;        // Pa per node, right after the last set_crack
  std::vector<double> drag_k_, widths_floor_;  // scratch per particle
  double particle_length_ = 0;                 // m, resolved target length
  double t_ = 0;
  std::uint64_t steps_ = 0;
  double injected_mass_ = 0, outflow_mass_ = 0;
  double inlet_flux_ = 0;
  double inlet_share_ = 1, inlet_transfer_ = 0;  // of a flow-rate inlet's Q(t), and m^2/s besides
  // kg/m, the zero-pressure mass a flow-rate inlet feeds over [t, t + dt] (share x the trapezoid of Q + transfer).
  double inflow_mass(double dt) const;
  bool outlet_wetted_ = false;
  // implicit interface
  std::vector<double> wall_rate_, wall_acceleration_, wall_compliance_;  // from the solid (CrackGeometry)
  std::size_t wall_band_ = 0;
  std::vector<Vec2> wall_plane_rate_, wall_plane_acceleration_;  // the crack plane's motion (may be empty)
  double tip_modulus_ = 0, resolution_ = 0;                      // Pa, m: from the solid, for Lag::TipAsymptote
  std::vector<double> predicted_arc_;                            // node arc lengths at the end of the step
  std::vector<double> solved_;  // Pa, the element pressures of the last implicit step (the next start)
  std::vector<std::vector<std::pair<std::size_t, double>>> pieces_;  // per particle: (element, fraction) now
  double interface_mismatch_ = 0, interface_residual_ = 0;
  int interface_iterations_ = 0;
  std::uint64_t interface_merges_ = 0;       // particles merged because a step would have squeezed them
  std::uint64_t interface_newton_ = 0;       // Newton iterations over the run
  std::uint64_t interface_unconverged_ = 0;  // solves that stopped above their tolerance
  std::uint64_t interface_rescued_ = 0;      // solves the careful Jacobian finished
  std::uint64_t interface_subcycled_ = 0;    // steps taken in fluid substeps
  std::uint64_t interface_max_substeps_ = 1;
  std::uint64_t interface_committed_above_ = 0;  // steps taken whole above the bound after every retry
  bool interface_above_bound_ = false;           // the last step was
  int interface_substeps_ = 1;                   // the last step's
  std::string interface_retry_why_;              // why the last step was subcycled
  // The step step_implicit is taking: the crack and its nodes at its start,
  // its length, and the end of the substep being solved (empty / 0 outside).
  std::vector<double> wall_start_;
  std::vector<Vec2> wall_start_position_;
  double wall_dt_ = 0, wall_tau_ = 0;
};

}  // namespace hfmpm::fluid::mpm
