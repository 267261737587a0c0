// A fluid that enters a crack at an inner particle (a wellbore inside the
// body) and flows both ways, towards both tips (docs/fluid.md, "Injection
// from inside the body").
//
// The crack is cut at the inlet particle into two wings, each a 1D MPM fluid
// (FluidSolver) with its mouth at the inlet: wing 0 runs from the inlet
// towards the crack's first particle (its start tip), wing 1 towards the
// last. The two meet at the inlet, where two conditions hold over every step:
//   1. one pressure: a flow-rate inlet's Q(t) is split, Q / 2 + x into wing 1
//      and Q / 2 - x into wing 0, with the junction's transfer x (m^2/s, of
//      either sign: fluid may also flow from one wing into the other) chosen
//      so that the two wings' inlet pressures agree at the end of the step
//      (a pressure inlet holds both at p_in(t) already);
//   2. one body: with the implicit interface (coupling.scheme IMPLICIT) the
//      faces' response couples the openings near the inlet to the pressures
//      on both sides of it (the compliance band reaches across); each wing
//      takes the other's pressures there as a known load.
// Both are met by iterating the step: the two wings step from the same
// start, the transfer is corrected by the secant rule on the pressure
// difference and the loads across by the pressures just found, until the
// difference and the change of those loads are below kTolerance of the
// largest pressure in the crack (kMaxIterations at most; a step that ends
// above is taken and counted). A symmetric crack needs one pass when its
// pressures across the inlet change little over a step: its transfer stays 0.
// Only with the implicit interface step (FluidConfig::implicit_interface):
// the explicit fluid's pressure waves cross many of its substeps within a
// coupled step, and one transfer per coupled step, set so that the pressures
// agree at its end, let them drift apart from step to step (measured: the
// first iteration's mismatch doubled every few steps in a rigid channel).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::fluid::mpm {

// One wing of a crack whose fluid enters at particle `inlet` (an inner
// index): particles inlet..last (towards_end) or inlet..0 (reversed, with the
// normals turned so that "above" stays on the wing's left), the inlet first,
// as a mouth. The faces' response is cut to the wing; `across` (empty, or
// one pressure per particle of the whole crack) is the load of the other
// wing's particles within the compliance band, added to the wing's opening
// acceleration. E' at the wing's tip is the crack's start_tip_modulus for
// wing 0.
CrackGeometry wing_geometry(const CrackGeometry& whole, std::size_t inlet, bool towards_end,
                            const std::vector<double>& across);

class TwoWingFluid {
 public:
  // The steps a junction takes at most, and the agreement it asks, relative
  // to the larger inlet pressure.
  static constexpr int kMaxIterations = 8;
  static constexpr double kTolerance = 1e-4;

  // Throws std::invalid_argument naming a config field out of range (FluidSolver's checks), or
  // without config.implicit_interface.
  explicit TwoWingFluid(const FluidConfig& config);

  // The whole crack (has_inlet set, inlet_id one of its inner ids); call
  // before every step. Throws std::invalid_argument as FluidSolver::set_crack.
  void set_crack(const CrackGeometry& crack);
  // Each wing filled from the inlet over min(front, its length) at `pressure`.
  void fill(double front, double pressure);
  // One coupled step of dt (s); returns the fluid steps taken (both wings,
  // every iteration).
  int advance(double dt);

  // The whole crack's pressures (the inlet's: the mean of the wings'), the
  // wetted interval [front_start_position, front_position] from its first
  // particle, the inflow and volume of both wings.
  CrackPressure pressure_message() const;
  const FluidSolver& wing(std::size_t w) const { return wings_.at(w); }
  // A per-node array of each wing (nodes from the inlet) on the whole crack's
  // nodes, the inlet's value the mean of the two; 0 where a wing has none.
  std::vector<double> join(const std::vector<double>& wing0, const std::vector<double>& wing1) const;
  const std::vector<Vec2>& positions() const { return whole_.position; }  // m, the whole crack's nodes
  const std::vector<double>& arc() const { return arc_; }                 // m, their arc lengths
  std::size_t inlet_index() const { return inlet_; }
  const std::vector<std::uint64_t>& ids() const { return whole_.ids; }  // the whole crack's, as last set
  std::uint64_t inlet_id() const { return whole_.inlet_id; }
  // m^2/s, the junction's transfer into wing 1 over the last step (a flow-rate
  // inlet's); and the share of the inflow that wing 1 took (1/2 without inflow).
  double transfer() const { return transfer_; }
  double share() const;
  double inlet_pressure() const;  // Pa, the mean of the wings'
  // Pa, the wings' inlet pressures' difference after the last step.
  double junction_mismatch() const { return mismatch_; }
  int last_iterations() const { return last_iterations_; }
  std::uint64_t iterations_total() const { return iterations_total_; }
  std::uint64_t unconverged_steps() const { return unconverged_; }

  void save(StateWriter& out) const;
  void load(const StateReader& in);

 private:
  // The whole crack's pressures from the wings (the inlet's the mean).
  std::vector<double> merged(const std::array<FluidSolver, 2>& wings) const;
  void set_wings(std::array<FluidSolver, 2>& wings, const std::vector<double>& across) const;

  std::array<FluidSolver, 2> wings_;
  std::array<FluidSolver, 2> before_;  // the wings before the last set_crack (each iteration starts there)
  CrackGeometry whole_;                // the crack as last set
  std::vector<double> arc_;            // m, its arc lengths
  std::vector<double> across_;         // Pa, the whole crack's pressures after the last step
  std::size_t inlet_ = 0;
  bool flow_rate_ = false;
  double transfer_ = 0, slope_ = 0;  // m^2/s, and d(p1 - p0)/d transfer found last (Pa s/m^2; 0: none yet)
  double mismatch_ = 0;
  int last_iterations_ = 0;
  std::uint64_t iterations_total_ = 0, unconverged_ = 0;
};

}  // namespace hfmpm::fluid::mpm
