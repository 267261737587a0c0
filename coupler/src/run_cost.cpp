// Run cost before a run: sizes and the step from the scene alone (each
// side's SceneSize and SceneStep, e.g. solid/side/scene_size.cpp), wall time from throughputs measured on this
// project's reference machine (docs/performance.md, "Water: the implicit interface scheme's cost" and the quiet-machine
// table): kgd-viscosity, 10 s, 12,172 steps, quiet 2-core machine, 3 December.
#include "hfmpm/coupling/run_cost.hpp"

#include <cmath>
#include <cstdio>

namespace hfmpm::coupling {
namespace {

// The MPM solid inside a coupled run, 2 threads: kgd-viscosity's 55.6 s of
// solid compute for its 39,275 particles over 12,172 steps (a crack, J every
// check, 2 x 2 particles per cell near it).
constexpr double kSolidParticleStepsPerS = 39275.0 * 12172 / 55.6;
// The MPM fluid and the exchange per coupled step, same runs: explicit
// (Gauss-Seidel, 2 MPa) 3.2 s + 1.7 s, implicit interface (water) 17.4 s +
// 2.1 s, over 12,172 steps.
constexpr double kExplicitFluidStepS = (3.2 + 1.7) / 12172;
constexpr double kImplicitFluidStepS = (17.4 + 2.1) / 12172;
// A stand-in side's step and the exchange (protocol cost only).
constexpr double kStandInStepS = 150e-6;

std::string number(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string count(double v) {  // 12,345
  char b[64];
  std::snprintf(b, sizeof b, "%.0f", v);  // whole digits at any size (%g would give 1e+16)
  std::string s = b;
  for (int i = static_cast<int>(s.size()) - 3; i > 0; i -= 3) s.insert(static_cast<std::size_t>(i), ",");
  return s;
}

std::string duration(double s) {
  char b[32];
  if (s < 120) {
    std::snprintf(b, sizeof b, s < 10 ? "%.1f s" : "%.0f s", s);
    return b;
  }
  if (s < 7200) return number(s / 60, 2) + " min";
  return number(s / 3600, 2) + " h";
}

}  // namespace

RunCost estimate_run_cost(const scene::Scene& s, const proto::SceneRules& rules, double particles) {
  RunCost cost;
  double stable = 0;
  if (s.solid().model_case() != scene::Solid::MODEL_NOT_SET && rules.solid.stable_step) {
    if (s.solid().has_mpm() && rules.solid.size) {
      const auto size = rules.solid.size(s);
      cost.particles = particles > 0 ? particles : size.particles;
      cost.nodes = size.nodes;
    }
    const auto step = rules.solid.stable_step(s);
    stable = step.dt_s;
    cost.dt_from = step.source;
  }
  if (s.has_fluid() && s.fluid().model_case() != scene::Fluid::MODEL_NOT_SET && rules.fluid.stable_step) {
    const auto step = rules.fluid.stable_step(s);
    const double f = step.dt_s;
    if (step.known && f > 0 && (!(stable > 0) || f < stable)) {
      stable = f;
      cost.dt_from = step.source;
    }
  }
  if (!(stable > 0) || !std::isfinite(stable)) return cost;
  cost.dt = s.time().safety_factor() * stable;
  cost.steps = std::ceil(s.time().end_s() / cost.dt);
  double per_step = 0;
  std::string basis;
  if (s.solid().has_mpm()) {
    per_step += cost.particles / kSolidParticleStepsPerS;
    basis = "MPM solid " + number(kSolidParticleStepsPerS / 1e6, 2) + " M particle-steps/s";
  } else {
    per_step += kStandInStepS;
    basis = "stand-in solid " + number(kStandInStepS * 1e6, 2) + " us/step";
  }
  if (s.has_fluid() && s.fluid().has_mpm()) {
    const bool implicit = s.coupling().scheme() == scene::Coupling::IMPLICIT;
    per_step += implicit ? kImplicitFluidStepS : kExplicitFluidStepS;
    basis += std::string(", MPM fluid and exchange ") +
             number((implicit ? kImplicitFluidStepS : kExplicitFluidStepS) * 1e3, 2) + " ms/step (" +
             (implicit ? "implicit interface" : "explicit") + ")";
  } else if (s.has_fluid()) {
    per_step += kStandInStepS;
    basis += ", stand-in fluid " + number(kStandInStepS * 1e6, 2) + " us/step";
  }
  cost.wall_s = cost.steps * per_step;
  cost.basis = basis + "; measured on kgd-viscosity, quiet 2-core machine (docs/performance.md)";
  return cost;
}

std::string describe(const RunCost& c) {
  std::string out;
  if (c.particles > 0) {
    out += "# cost: " + count(c.particles) + " solid particles, " + count(c.nodes) + " grid nodes\n";
  }
  if (!(c.dt > 0)) {
    out += "# cost: the step is known only once the sides run\n";
    return out;
  }
  out += "# cost: step " + number(c.dt) + " s (time.safety_factor x " + c.dt_from +
         "; a side may report a smaller one as it runs), " + count(c.steps) + " steps to time.end_s\n";
  out += "# cost: about " + duration(c.wall_s) + " of wall time (" + c.basis + ")\n";
  return out;
}

}  // namespace hfmpm::coupling
