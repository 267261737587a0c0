// Run cost before a run: sizes, the step and the wall time per coupled step
// from the scene alone, each side's from its own rules (SideSceneRules'
// stable_step and size, e.g. solid/side/scene_size.cpp and scene_rules.cpp,
// with the throughputs measured on this project's reference machine:
// docs/performance.md). The coupler adds them up; it knows no side's kind.
#include "hfmpm/coupling/run_cost.hpp"

#include <cmath>
#include <cstdio>

namespace hfmpm::coupling {
namespace {

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
  proto::SceneSize solid_size, fluid_size;
  const bool fluid = s.has_fluid() && s.fluid().model_case() != scene::Fluid::MODEL_NOT_SET;
  if (s.solid().model_case() != scene::Solid::MODEL_NOT_SET && rules.solid.stable_step) {
    if (rules.solid.size) {
      solid_size = rules.solid.size(s);
      if (solid_size.particles > 0) cost.particles = particles > 0 ? particles : solid_size.particles;
      cost.nodes = solid_size.nodes;
    }
    const auto step = rules.solid.stable_step(s);
    stable = step.dt_s;
    cost.dt_from = step.source;
  }
  if (fluid && rules.fluid.size) fluid_size = rules.fluid.size(s);
  if (fluid && rules.fluid.stable_step) {
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
  // Each side's wall time per step: its own figure, for its particles (the
  // solid's: the caller's count if given).
  auto add = [&](const proto::SceneSize& size, double side_particles) {
    per_step += size.step_s;
    if (size.particle_steps_per_s > 0) per_step += side_particles / size.particle_steps_per_s;
    if (!size.throughput.empty()) basis += (basis.empty() ? "" : ", ") + size.throughput;
  };
  add(solid_size, cost.particles);
  add(fluid_size, fluid_size.particles);
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
