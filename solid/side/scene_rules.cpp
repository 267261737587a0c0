// The solid side's scene rules (solid_scene_rules.hpp): solid.prescribed_crack
// here, solid.mpm in scene_rules_mpm.cpp; and the SideSceneRules that hands
// them, the stable step, the size and the cost per step, and whether the
// model writes checkpoints to the coupler's validation.
#include <cmath>
#include <string>

#include "solid_scene_rules.hpp"

namespace hfmpm::solid {
namespace {

using proto::check_time_function;
using proto::Checker;
using proto::kInf;
using proto::text;

void check_prescribed_crack(Checker& c, const scene::PrescribedCrack& p) {
  const std::string key = "solid.prescribed_crack.";
  c.range(key + "mouth_x_m", p.mouth_x_m(), -kInf, kInf, false, "m");
  c.range(key + "mouth_y_m", p.mouth_y_m(), -kInf, kInf, false, "m");
  c.range(key + "angle_deg", p.angle_deg(), -180, 180, false, "degrees");
  if (!p.has_initial_length_m())
    c.missing(key + "initial_length_m", "the initial crack length (m), > 0");
  else
    c.positive(key + "initial_length_m", p.initial_length_m(), "m");
  c.non_negative(key + "growth_speed_m_per_s", p.growth_speed_m_per_s(), "m/s");
  const double max_length = p.has_max_length_m() ? p.max_length_m() : p.initial_length_m();
  if (p.has_max_length_m()) {
    c.range(key + "max_length_m", p.max_length_m(), p.initial_length_m(), kInf, false, "m, >= initial_length_m");
  } else if (p.growth_speed_m_per_s() > 0) {
    c.missing(key + "max_length_m",
              "the length where growth stops (m), >= initial_length_m, with growth_speed_m_per_s > 0");
  }
  if (!p.has_spacing_m()) {
    c.missing(key + "spacing_m", "the crack-particle spacing (m), > 0");
  } else {
    c.range(key + "spacing_m", p.spacing_m(), 0, p.initial_length_m(), true, "m, at most initial_length_m");
    if (std::isfinite(max_length) && p.spacing_m() > 0 && max_length / p.spacing_m() > 1e6) {
      c.bad(key + "spacing_m", text(p.spacing_m()), "at most 1e6 crack particles up to max_length_m");
    }
  }
  if (!p.has_mouth_opening_m())
    c.missing(key + "mouth_opening_m", "the mouth opening w(t) (m), a TimeFunction");
  else
    check_time_function(c, key + "mouth_opening_m", p.mouth_opening_m(), 0.0, "m");
  if (p.profile() == scene::PrescribedCrack::PROFILE_UNSPECIFIED) {
    c.bad(key + "profile", "PROFILE_UNSPECIFIED", "ELLIPTIC, UNIFORM or CHANNEL");
  }
  if (!p.has_stable_dt_s())
    c.missing(key + "stable_dt_s", "the step this stand-in reports (s), > 0");
  else
    c.positive(key + "stable_dt_s", p.stable_dt_s(), "s");
}

void check_solid(Checker& c, const scene::Scene& s) {
  if (s.solid().has_prescribed_crack()) {
    check_prescribed_crack(c, s.solid().prescribed_crack());
  } else if (s.solid().has_mpm()) {
    check_mpm_solid(c, s.solid().mpm());
  }
}

proto::SceneStep stable_step(const scene::Scene& s) {
  proto::SceneStep step;
  if (s.solid().has_prescribed_crack()) {
    step.dt_s = s.solid().prescribed_crack().stable_dt_s();
    step.known = step.dt_s > 0 && std::isfinite(step.dt_s);  // else its own rule reports it
    step.source = "solid.prescribed_crack.stable_dt_s";
  } else if (s.solid().has_mpm()) {
    step.known = true;
    step.dt_s = mpm_solid_stable_dt(s.solid().mpm());
    step.source = "the MPM solid's stable step cfl h / c_p";
    step.hint = " (check the materials' youngs_modulus_pa and density_kg_m3 and cell_size_m)";
  }
  return step;
}

// Wall time per coupled step on the reference machine (docs/performance.md,
// "Water: the implicit interface scheme's cost" and the quiet-machine table:
// kgd-viscosity, 10 s, 12,172 steps, quiet 2-core machine, 3 December).
// The MPM solid inside a coupled run, 2 threads: kgd-viscosity's 55.6 s of
// solid compute for its 39,275 particles over 12,172 steps (a crack, J every
// check, 2 x 2 particles per cell near it).
constexpr double kMpmParticleStepsPerS = 39275.0 * 12172 / 55.6;
// The stand-in's step and the exchange (protocol cost only).
constexpr double kPrescribedStepS = 150e-6;

proto::SceneSize size(const scene::Scene& s) {
  proto::SceneSize size;
  if (s.solid().has_prescribed_crack()) {
    size.step_s = kPrescribedStepS;
    size.throughput = "stand-in solid " + text(kPrescribedStepS * 1e6, 2) + " us/step";
  } else if (s.solid().has_mpm()) {
    size.particles = mpm_solid_particles(s.solid().mpm());
    size.nodes = mpm_solid_nodes(s.solid().mpm());
    size.particle_steps_per_s = kMpmParticleStepsPerS;
    size.throughput = "MPM solid " + text(kMpmParticleStepsPerS / 1e6, 2) + " M particle-steps/s";
  }
  return size;
}

// The MPM solid writes checkpoints (MpmSolidSide::save_checkpoint); the
// stand-in does not.
std::string checkpoint_refusal(const scene::Scene& s) {
  if (s.solid().has_prescribed_crack()) return "solid.prescribed_crack does not write checkpoints (solid.mpm does)";
  return "";
}

}  // namespace

proto::SideSceneRules scene_rules() { return {check_solid, stable_step, size, checkpoint_refusal}; }

}  // namespace hfmpm::solid
