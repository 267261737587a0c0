// The fluid side's scene rules (fluid_scene_rules.hpp):
// fluid.prescribed_pressure here, fluid.mpm in scene_rules_mpm.cpp; and the
// SideSceneRules that hands them, the stable step, the cost per step and
// whether the model writes checkpoints to the coupler's validation.
#include <cmath>
#include <string>

#include "fluid_scene_rules.hpp"

namespace hfmpm::fluid {
namespace {

using proto::check_time_function;
using proto::Checker;

void check_prescribed_pressure(Checker& c, const scene::PrescribedPressure& p) {
  const std::string key = "fluid.prescribed_pressure.";
  if (!p.has_inlet_pressure_pa())
    c.missing(key + "inlet_pressure_pa", "the inlet pressure p(t) (Pa), a TimeFunction");
  else
    check_time_function(c, key + "inlet_pressure_pa", p.inlet_pressure_pa(), 0.0, "Pa");
  if (p.profile() == scene::PrescribedPressure::PROFILE_UNSPECIFIED) {
    c.bad(key + "profile", "PROFILE_UNSPECIFIED", "UNIFORM or LINEAR");
  }
  c.range(key + "front_fraction", p.front_fraction(), 0, 1, true, "fraction of the crack length");
  if (!p.has_stable_dt_s())
    c.missing(key + "stable_dt_s", "the step this stand-in reports (s), > 0");
  else
    c.positive(key + "stable_dt_s", p.stable_dt_s(), "s");
}

void check_fluid(Checker& c, const scene::Scene& s) {
  if (s.fluid().has_prescribed_pressure()) {
    check_prescribed_pressure(c, s.fluid().prescribed_pressure());
  } else if (s.fluid().has_mpm()) {
    check_mpm_fluid(c, s);
  }
}

// The MPM fluid's step is known only once it runs (it can only make the
// run's step smaller).
proto::SceneStep stable_step(const scene::Scene& s) {
  proto::SceneStep step;
  if (s.fluid().has_prescribed_pressure()) {
    step.dt_s = s.fluid().prescribed_pressure().stable_dt_s();
    step.known = step.dt_s > 0 && std::isfinite(step.dt_s);  // else its own rule reports it
    step.source = "fluid.prescribed_pressure.stable_dt_s";
  }
  return step;
}

// Wall time per coupled step on the reference machine (docs/performance.md,
// "Water: the implicit interface scheme's cost" and the quiet-machine table):
// the MPM fluid and the exchange in kgd-viscosity's runs over 12,172 steps,
// explicit (Gauss-Seidel, 2 MPa) 3.2 s + 1.7 s, implicit interface (water)
// 17.4 s + 2.1 s.
constexpr double kExplicitMpmStepS = (3.2 + 1.7) / 12172;
constexpr double kImplicitMpmStepS = (17.4 + 2.1) / 12172;
// The stand-in's step and the exchange (protocol cost only).
constexpr double kPrescribedStepS = 150e-6;

// No particles before it runs (they enter at the inlet); the cost per step.
proto::SceneSize size(const scene::Scene& s) {
  proto::SceneSize size;
  if (s.fluid().has_prescribed_pressure()) {
    size.step_s = kPrescribedStepS;
    size.throughput = "stand-in fluid " + proto::text(kPrescribedStepS * 1e6, 2) + " us/step";
  } else if (s.fluid().has_mpm()) {
    const bool implicit = s.coupling().scheme() == scene::Coupling::IMPLICIT;
    size.step_s = implicit ? kImplicitMpmStepS : kExplicitMpmStepS;
    size.throughput = "MPM fluid and exchange " + proto::text(size.step_s * 1e3, 2) + " ms/step (" +
                      (implicit ? "implicit interface" : "explicit") + ")";
  }
  return size;
}

// The MPM fluid writes checkpoints (MpmFluidSide::save_checkpoint); the
// stand-in does not.
std::string checkpoint_refusal(const scene::Scene& s) {
  if (s.fluid().has_prescribed_pressure()) {
    return "fluid.prescribed_pressure does not write checkpoints (fluid.mpm does)";
  }
  return "";
}

}  // namespace

proto::SideSceneRules scene_rules() { return {check_fluid, stable_step, size, checkpoint_refusal}; }

}  // namespace hfmpm::fluid
