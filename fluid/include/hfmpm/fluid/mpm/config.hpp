// What a fluid simulation on one crack is built from. Plain C++; the side
// adapter fills it from the scene. SI units, 2D per unit thickness. The
// member defaults are the library's, for programs and tests that build a
// config themselves, and equal the scene schema's (proto/hfmpm/scene.proto),
// which the adapter's to_fluid_config sets for every member a scene key
// stands for (docs/architecture.md, "Defaults").
#pragma once

#include <memory>

#include "hfmpm/fluid/mpm/rheology.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::fluid::mpm {

// The inlet at the crack mouth (node 0).
struct InletConfig {
  enum class Kind { FlowRate, Pressure };
  Kind kind = Kind::FlowRate;
  // FlowRate: Q(t), m^2/s, into this crack, as volume at zero pressure
  // (mass rate rho0 Q). With a symmetry plane at the mouth, the half of the
  // total rate that enters the simulated wing.
  TimeFunction flow_rate = TimeFunction::constant(0);
  // Pressure: p_in(t), Pa (values < 0 act as 0: no suction), the pressure of
  // the well or reservoir that feeds the mouth, where the fluid is at rest.
  // Fluid flowing in at speed v has the static pressure p_in - rho v^2 / 2 at
  // the mouth (Bernoulli along the streamline from the well); fluid flowing
  // back out has p_in (it stops in the well, its kinetic energy lost there).
  // So the inlet gives the fluid p_in per unit volume of energy, kinetic and
  // pressure work together, as the energy check counts it.
  TimeFunction pressure = TimeFunction::constant(0);
  // Virtual pre-opening: crack nodes with arc length <= pre_opening_length
  // (m; the mouth node always) are pre_opening (m) wider for the fluid than
  // the crack, so fluid can enter a closed crack.
  double pre_opening = 0;
  double pre_opening_length = 0;
};

// An optional outlet at the last crack node, held at a pressure: fluid that
// crosses it leaves the simulation (and enters if the pressure pushes it
// back). Not for fractures (their tip is closed); for channel-flow
// verification (steady Poiseuille flow, waves over a base pressure).
struct OutletConfig {
  bool enabled = false;
  TimeFunction pressure = TimeFunction::constant(0);  // Pa
};

struct FluidConfig {
  double density = 1000;                     // kg/m^3, rho0, at zero pressure (J = 1)
  double bulk_modulus = 2.2e9;               // Pa, K at zero pressure (Tait)
  double tait_c = 0.0894;                    // -, Tait exponent scale (water)
  double viscosity = 1e-3;                   // Pa s, Newtonian viscosity (used when `rheology` is null)
  std::shared_ptr<const Rheology> rheology;  // the wall friction law; null: Newtonian(viscosity)
  double cfl = 0.5;                          // -, dt = cfl * min(particle length, node spacing) / sound speed
  // m, length of the particles inserted at the inlet (the inlet particle is
  // split when it reaches twice this). 0: half the mouth element, fixed at
  // the first set_crack().
  double particle_length = 0;
  // -, a particle (not the inlet particle) shorter than merge_fraction x
  // particle_length after a step is merged with its shorter neighbour (mass
  // and momentum kept): particles squeezed along the crack near a closed tip
  // otherwise set the fluid's stable step. 0: never; < 2 (the split length).
  double merge_fraction = 0;
  double flip = 0;  // -, FLIP fraction of the particle velocity update (0 = PIC)
  // Affine particle-in-cell (APIC; Jiang et al. 2015, reduced to the 1D
  // CPDI domain): each particle also carries its velocity gradient, taken
  // from the grid with the velocity and given back with it, so that a
  // velocity varying linearly along the crack goes to the grid and back
  // unchanged. Plain PIC averages that variation away at every step: a loss
  // per step, not per second, which throttled a pressure inlet's inflow in
  // proportion to the step (layered-ci's mouth opening at 0.5 s was 4.2e-5,
  // 3.3e-5, 2.4e-5 and 1.5e-5 m at 0.9, 0.45, 0.225 and 0.1 of the step;
  // docs/fluid.md, "Particle-grid transfer"). false: PIC (with `flip`). Scene key
  // fluid.mpm.affine_transfer.
  bool affine = true;
  // Pressure constant per element, from the volume ratio of the fluid in it
  // (against volumetric locking, see FluidSolver::element_pressure); false:
  // each particle's pressure from its own J = F11 F22.
  bool smooth_jacobian = true;
  // The implicit interface step (coupling.scheme IMPLICIT; docs/fluid.md):
  // advance() takes one step per call in which the element pressures are
  // solved together with the crack's opening over the step, as the solid
  // reported it with the geometry (CrackGeometry::opening_*). The acoustic
  // step limit then does not apply; stable_dt() is the advective one.
  bool implicit_interface = false;
  // Virtual opening (m) added to the crack's width at every node, grown ones
  // included: the fluid can always enter the closed crack ahead of its
  // front (a thin film instead of a lag). Without it a segment the crack
  // grew is shut by the confining stress, the fluid cannot enter it (zero
  // width, infinite drag), and the tip advances only under a pressure far
  // above the zero-lag solution's. Its volume (virtual_opening x length)
  // stays in the fluid.
  double virtual_opening = 0;
  // Pressure on the crack between the fluid front and the tip (the lag):
  // Zero (vapour pressure), or Front: the first crack node
  // beyond the front carries the pressure of the fluid at the front, at most
  // the mouth's (the fluid flows towards the
  // tip; the last particle, compressed against the closed tip, can carry
  // far more) (the zero-lag closure of the KGD solutions, valid for
  // t >> 12 mu E'^2 / sigma0^3). With growth in steps of half a cell, a dry
  // segment at zero pressure is shut by the confining stress until the net
  // pressure is several times the zero-lag one (the step is much longer than
  // the physical lag); Front lets the fluid's pressure reach the tip.
  // Fixed: every node beyond the front carries lag_pressure (a cavity at a
  // pore pressure; or the confining stress as a zero-lag closure, so the dry
  // zone the grid cannot make small carries no net load; pair it with the
  // solid's fracture.max_lag_cells, or a crack with little toughness runs dry).
  // TipAsymptote: the zero-lag closure of a viscosity-dominated crack whose
  // last cell the solid does not resolve (docs/fluid.md, "The tip closure"):
  // nodes beyond the front carry lag_pressure (the confining stress: no net
  // load), and the fluid front meets, instead of a vacuum, the pressure of
  // the zero-toughness tip solution at the solid's resolution d (one cell),
  //   p_tip = max(0, lag_pressure - (3 / beta_m^2) (mu' V E'^2)^(1/3) d^(-1/3)),
  // with beta_m = 2^(1/3) 3^(5/6), V the front's speed, mu' = k w^2 the
  // front particle's drag coefficient times its width squared (12 mu for a
  // Newtonian fluid), and E', d from the solid (CrackGeometry::tip_modulus,
  // resolution; required).
  enum class Lag { Zero, Front, Fixed, TipAsymptote };
  Lag lag = Lag::Zero;
  double lag_pressure = 0;  // Pa, for Lag::Fixed and Lag::TipAsymptote
  // With Lag::TipAsymptote: the tip solution's level matched to the fluid
  // (scene lag TIP_ASYMPTOTE_MATCHED; FluidSolver::front_counter_pressure):
  // the front, s_f >= d/2 from the tip, meets p0 - A s_f^(-1/3), p0 the mean
  // of p + A s^(-1/3) over the fluid's pressures 2 to 4 cells behind it,
  // clamped to [0, lag_pressure]. False: p0 = lag_pressure and s_f = d.
  bool tip_level_matched = false;
  double min_width = 1e-9;  // m, width floor in the drag and in w0 (numerical; the drag is implicit)
  InletConfig inlet;
  OutletConfig outlet;
};

}  // namespace hfmpm::fluid::mpm
