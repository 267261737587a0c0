// A run-time energy check for coupled runs: the solid's kinetic energy
// against the energy the run can have given it, E = W_in + p0 V0 + W_r: the work
// the inlet has done, W_in = integral of p_inlet dV_injected, plus the
// initial fill's p0 V0 (its inlet pressure times its volume at the start, the
// work it would do doubling its volume at that pressure; a generous scale for
// its stored energy, p0^2 V0 / 2K), and the in-situ elastic energy the
// cracks released by sliding, W_r (the solid's released_energy: an in-situ
// stress with shear on a crack's plane does work on the faces' slip as soon as
// nothing holds them, a real source). With loads that do no work of their own
// (constant tractions, a confining stress held by them, as in every
// hydraulic-fracture scene) the fluid is the only source of energy, so
// KE <= E; dissipation (viscous flow, grid damping, PIC) keeps it well below
// (docs/stability.md lists the measured ratios). A
// coupled step that creates energy (an exchange interval or a fluid too stiff
// for the explicit exchange) can run away while no particle moves a cell in
// one step, and then ends "completed" with a wrong answer; this turns it into
// a named failure. No sockets here: the coupler feeds it the reports'
// diagnostics.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "hfmpm/exchange.hpp"

namespace hfmpm::coupling {

class EnergyWatch {
 public:
  // bound: KE may reach bound x W_in (0: no check, only bookkeeping);
  explicit EnergyWatch(double bound) : bound_(bound) {}

  // The fluid's state at the start (the Ready report).
  void start(const SideDiagnostics& fluid);

  // After each command (every control round): accumulate W_in (trapezoid
  // over the reports) and check. Returns the failure's text, or nullopt.
  std::optional<std::string> update(double t, std::uint64_t step, const SideDiagnostics& solid,
                                    const SideDiagnostics& fluid);

  double inlet_work() const { return work_; }           // J/m
  double initial_energy() const { return e0_; }         // J/m, p0 V0
  double released_energy() const { return released_; }  // J/m, W_r at the last update
  double largest_ratio() const { return largest_; }     // max KE / (W_in + p0 V0)
  double largest_ratio_time() const { return largest_t_; }

  // The accumulators, for checkpoints.
  struct State {
    double e0 = 0, p = 0, v = 0, work = 0, largest = 0, largest_t = 0;
  };
  State state() const { return {e0_, p_, v_, work_, largest_, largest_t_}; }
  void restore(const State& s) {
    e0_ = s.e0;
    p_ = s.p;
    v_ = s.v;
    work_ = s.work;
    largest_ = s.largest;
    largest_t_ = s.largest_t;
  }

 private:
  double bound_;
  double e0_ = 0;
  double p_ = 0, v_ = 0;  // last inlet pressure and injected volume
  double work_ = 0;
  double largest_ = 0, largest_t_ = 0;
  double released_ = 0;
};

// The end-of-run check of a dry run (no fluid): is the solid at rest? Mean
// kinetic energy against mean strain energy over the last tenth of the run
// (the reports of that window). A damped, quasi-static run ends with KE a
// small fraction of its strain energy (the settled growth runs of issue 18:
// 4e-4); a body vibrating freely has them equal on average; the chatter of
// issue 18 (particles at a fresh tip moving at 20-40 m/s to the end) had KE
// several times its strain energy, and the run said "completed". Above
// `bound` (0.1: a tenth of the elastic energy in motion is no rest) the run
// says so in run.json and the log. A warning, not a failure: a dry run may be
// meant to move (waves); the status stays "completed".
class RestWatch {
 public:
  RestWatch(double end_time, double bound = 0.1) : window_start_(0.9 * end_time), bound_(bound) {}

  // After each command: the solid's diagnostics at time t.
  void update(double t, const SideDiagnostics& solid);

  bool measured() const { return reports_ > 0; }
  double mean_kinetic_energy() const { return reports_ ? kinetic_ / reports_ : 0; }  // J/m
  double mean_strain_energy() const { return reports_ ? strain_ / reports_ : 0; }    // J/m
  double ratio() const;  // mean KE / mean strain energy over the last tenth of the run
  // The warning's text, or nullopt when the solid ends at rest.
  std::optional<std::string> warning() const;

  // The accumulators, for checkpoints.
  struct State {
    double kinetic = 0, strain = 0;
    int reports = 0;
  };
  State state() const { return {kinetic_, strain_, reports_}; }
  void restore(const State& s) {
    kinetic_ = s.kinetic;
    strain_ = s.strain;
    reports_ = s.reports;
  }

 private:
  double window_start_, bound_;
  double kinetic_ = 0, strain_ = 0;
  int reports_ = 0;
};

}  // namespace hfmpm::coupling
