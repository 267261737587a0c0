// The rules a scene must satisfy before any process starts. Each rule names
// the key and what is allowed; the loader adds file and line. The coupler's
// own rules are here (name, time, output, coupling, and the rules across
// both sides: the implicit scheme's solid, the step count); each side's
// rules for its block come from its library as a SideSceneRules
// (hfmpm/proto/scene_rules.hpp), handed over by the program that links it.
#include <algorithm>
#include <cmath>

#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/proto/scene_rules.hpp"

namespace hfmpm::coupling {

namespace {

using proto::Checker;
using proto::kInf;
using proto::SideSceneRules;
using proto::text;

void check_time(Checker& c, const scene::Scene& s) {
  if (!s.has_time() || !s.time().has_end_s()) {
    c.missing("time.end_s", "the end time in seconds, > 0");
  } else {
    c.positive("time.end_s", s.time().end_s(), "s");
  }
  c.range("time.safety_factor", s.time().safety_factor(), 0, 1, true, "fraction of the smallest stable step");
  if (s.time().max_steps() == 0) c.bad("time.max_steps", "0", "an integer >= 1");
  const double end = s.time().end_s();
  const bool end_valid = s.time().has_end_s() && std::isfinite(end) && end > 0;
  // Each is a schedule of times a multiple of it apart, up to end_s. Its
  // floor is end_s / kMaxRunSteps (min_time_interval), the step of a run of
  // the most steps allowed: a shorter interval cannot give more than one row
  // (or checkpoint) per step, and one far below end_s vanishes against the
  // time it is added to (1 + 1e-300 is 1, which hung the coupler).
  auto interval = [&](const std::string& key, double v, const std::string& zero) {
    if (v == 0) return;
    if (!end_valid) {  // end_s's own rule reports it; the interval is checked once end_s is valid
      c.range(key, v, 0, kInf, false, "s, 0 for " + zero);
      return;
    }
    const double shortest = min_time_interval(end);
    if (std::isfinite(v) && v >= shortest && v <= end) return;
    c.bad(key, text(v),
          "0 (" + zero + ") or a finite value from " + text(shortest) + " to " + text(end) +
              " s (time.end_s; at least time.end_s / " + text(kMaxRunSteps) +
              ", the step of a run of the most steps allowed: a shorter interval gives no " +
              "more than one per step)");
  };
  interval("output.interval_s", s.output().interval_s(), "end_s / 100");
  interval("output.checkpoint_interval_s", s.output().checkpoint_interval_s(), "no checkpoints");
}

// Checkpoints need both sides to write them: each side's rules say whether
// its model in this scene does (SideSceneRules::checkpoint_refusal).
void check_checkpoints(Checker& c, const scene::Scene& s, const SceneRules& rules) {
  const double interval = s.output().checkpoint_interval_s(), end = s.time().end_s();
  if (!(interval > 0)) return;
  // An interval that check_time refuses is reported once, there.
  if (std::isfinite(end) && end > 0 && !(interval >= min_time_interval(end) && interval <= end)) return;
  std::string refusals;
  auto ask = [&](const SideSceneRules& side) {
    if (!side.checkpoint_refusal) return;
    const std::string why = side.checkpoint_refusal(s);
    if (!why.empty()) refusals += (refusals.empty() ? "" : "; ") + why;
  };
  if (s.has_solid() && s.solid().model_case() != scene::Solid::MODEL_NOT_SET) ask(rules.solid);
  if (s.has_fluid() && s.fluid().model_case() != scene::Fluid::MODEL_NOT_SET) ask(rules.fluid);
  if (!refusals.empty()) {
    c.bad("output.checkpoint_interval_s", text(s.output().checkpoint_interval_s()),
          "0 with this scene's sides, which must both write checkpoints: " + refusals);
  }
}

void check_coupling(Checker& c, const scene::Coupling& k) {
  if (k.transport() == scene::Coupling::TRANSPORT_UNSPECIFIED) {
    c.bad("coupling.transport", "TRANSPORT_UNSPECIFIED", "IPC, TCP or INPROC");
  }
  if (k.scheme() == scene::Coupling::SCHEME_UNSPECIFIED) {
    c.bad("coupling.scheme", "SCHEME_UNSPECIFIED", "JACOBI, GAUSS_SEIDEL or IMPLICIT");
  }
  if (k.scheme() == scene::Coupling::IMPLICIT && k.exchange_interval() != 1) {
    c.bad("coupling.exchange_interval", std::to_string(k.exchange_interval()),
          "1 with coupling.scheme = IMPLICIT (the fluid needs the solid's response over every step)");
  }
  if (k.exchange_interval() < 1 || k.exchange_interval() > 10000) {
    c.bad("coupling.exchange_interval", std::to_string(k.exchange_interval()), "an integer from 1 to 10000 (steps)");
  }
  if (k.control_interval() < 1 || k.control_interval() > 1000000) {
    c.bad("coupling.control_interval", std::to_string(k.control_interval()), "an integer from 1 to 1000000 (steps)");
  }
  c.range("coupling.heartbeat_interval_s", k.heartbeat_interval_s(), 0.01, 60, false, "s");
  c.range("coupling.heartbeat_timeout_s", k.heartbeat_timeout_s(), 2 * k.heartbeat_interval_s(), 3600, true,
          "s, more than twice coupling.heartbeat_interval_s");
  if (k.heartbeat_timeout_s() < 0.5) {
    c.bad("coupling.heartbeat_timeout_s", text(k.heartbeat_timeout_s()),
          "at least 0.5 s (sides send heartbeats every 0.1 s before they know the scene)");
  }
  c.range("coupling.setup_timeout_s", k.setup_timeout_s(), 0, 86400, true, "s");
  c.range("coupling.step_timeout_s", k.step_timeout_s(), 0, 86400, true, "s");
  c.range("coupling.join_timeout_s", k.join_timeout_s(), 0, 86400, true, "s");
  if (k.tcp_host().empty()) c.bad("coupling.tcp_host", "\"\"", "a host name or address to bind, e.g. 127.0.0.1");
  if (k.spin_us() > 1000000) c.bad("coupling.spin_us", std::to_string(k.spin_us()), "0 to 1000000 (us)");
  c.range("coupling.energy_bound", k.energy_bound(), 0, 1e12, false,
          "0 (no check) or a factor: the solid's kinetic energy may reach it x the fluid's inlet work plus p0 V0");
}

// The name is used as a directory and file name: letters, digits, '_', '.',
// '-', at most kMaxNameLength of them, and not "." or "..". Plain scanning
// (no std::regex: its recursion overflows the stack on long input).
constexpr std::size_t kMaxNameLength = 100;

void check_name(Checker& c, const scene::Scene& s) {
  if (!s.has_name()) return;
  const std::string& name = s.name();
  const bool chars_ok = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
    return (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '.' ||
           ch == '-';
  });
  const std::string shown = name.size() > 60
                                ? "\"" + name.substr(0, 40) + "...\" (" + std::to_string(name.size()) + " characters)"
                                : "\"" + name + "\"";
  if (!chars_ok) {
    c.bad("name", shown, "letters, digits, '_', '.', '-' (it is used in file names)");
  } else if (name.size() > kMaxNameLength) {
    c.bad("name", shown, "at most " + std::to_string(kMaxNameLength) + " characters (it is used in file names)");
  } else if (name == "." || name == "..") {
    c.bad("name", shown, "a name that is not \".\" or \"..\" (it is used as the output directory under hfmpm-out/)");
  }
}

// The number of steps to time.end_s, from the stable steps known before any
// process starts (each side's SceneStep: the MPM solid's cfl h / c_p, the
// stand-ins' stable_dt_s; the MPM fluid's step is known only once it runs,
// and can only be smaller). A rule across both sides: the run's step is the
// smaller of theirs. Refused: more than kMaxRunSteps, or not finite (E =
// 1e300 gives a step of 1e-150 s); and, when every side's step is known, a
// single step that is longer than end_s (the run would end at that step's
// end, not at end_s).
void check_step_count(Checker& c, const scene::Scene& s, const SceneRules& rules) {
  const double end = s.time().end_s(), safety = s.time().safety_factor();
  if (!s.time().has_end_s() || !(std::isfinite(end) && end > 0) || !(safety > 0 && safety <= 1)) return;
  if (!s.has_solid() || s.solid().model_case() == scene::Solid::MODEL_NOT_SET) return;
  double stable = kInf;
  std::string source;
  bool complete = true;
  // false: stop here (the values the step needs are invalid, or the step is).
  auto take = [&](const SideSceneRules& side) {
    const proto::SceneStep step = side.stable_step ? side.stable_step(s) : proto::SceneStep{};
    if (!step.known) {
      complete = false;
      return true;
    }
    const double dt = step.dt_s;
    if (std::isnan(dt)) return false;  // invalid materials or grid: reported by their own rules
    if (!(dt > 0) || !std::isfinite(dt)) {
      c.bad("time.end_s", text(end),
            "a run of finitely many steps: " + step.source + " is " + text(dt) + " s" + step.hint);
      return false;
    }
    if (dt < stable) stable = dt, source = step.source;
    return true;
  };
  if (!take(rules.solid)) return;
  if (s.has_fluid() && s.fluid().model_case() != scene::Fluid::MODEL_NOT_SET && !take(rules.fluid)) return;
  if (s.has_fluid() && s.fluid().model_case() == scene::Fluid::MODEL_NOT_SET) complete = false;
  if (!std::isfinite(stable)) return;
  const double dt = safety * stable;
  const double steps = end / dt;
  if (!std::isfinite(steps) || steps > kMaxRunSteps) {
    c.bad("time.end_s", text(end),
          "at most " + text(kMaxRunSteps) + " steps to reach it: " + source + " is " + text(stable) +
              " s, dt = time.safety_factor x that = " + text(dt) + " s, so the run needs " + text(steps) +
              " steps (check the moduli, densities and cell size, or shorten end_s)");
  } else if (complete && dt > end) {
    c.bad("time.end_s", text(end),
          "at least one step: " + source + " is " + text(stable) + " s, dt = time.safety_factor x that = " + text(dt) +
              " s, longer than end_s, so the run would be one step ending at t = " + text(dt) +
              " s, not at end_s (check the moduli, densities and cell size, or lengthen end_s)");
  }
}

}  // namespace

std::vector<SceneProblem> validate(const scene::Scene& s, const SceneRules& rules) {
  Checker c;
  check_name(c, s);
  // Cautions are text for run.json and the log: a few lines of bounded length.
  if (s.cautions_size() > 20) {
    c.bad("cautions", std::to_string(s.cautions_size()) + " entries", "at most 20");
  }
  for (int i = 0; i < s.cautions_size(); ++i) {
    if (s.cautions(i).size() > 2000) {
      c.bad("cautions[" + std::to_string(i) + "]", std::to_string(s.cautions(i).size()) + " characters",
            "at most 2000");
    }
  }
  check_time(c, s);
  check_checkpoints(c, s, rules);
  check_coupling(c, s.coupling());
  if (!s.has_solid() || s.solid().model_case() == scene::Solid::MODEL_NOT_SET) {
    c.missing("solid", "a solid model: solid { mpm { ... } } or solid { prescribed_crack { ... } }");
  } else if (rules.solid.check) {
    rules.solid.check(c, s);
  }
  if (s.has_fluid()) {
    if (s.fluid().model_case() == scene::Fluid::MODEL_NOT_SET) {
      c.missing("fluid",
                "a fluid model: fluid { mpm { ... } } or fluid { prescribed_pressure { ... } }, or no fluid "
                "block for a dry run");
    } else if (rules.fluid.check) {
      rules.fluid.check(c, s);
    }
  }
  // Across both sides: the implicit interface scheme needs the face response
  // only the MPM solid gives.
  if (s.coupling().scheme() == scene::Coupling::IMPLICIT && s.has_fluid() && s.fluid().has_mpm() && s.has_solid() &&
      !s.solid().has_mpm()) {
    c.bad("coupling.scheme", "IMPLICIT",
          "JACOBI or GAUSS_SEIDEL with this solid: the implicit scheme needs solid.mpm (the prescribed crack "
          "reports no face response for the fluid's interface solve)");
  }
  check_step_count(c, s, rules);
  // A NaN or an infinity anywhere makes every rule that uses it meaningless:
  // then only those numbers are reported, and the other rules are checked
  // once they are finite.
  return proto::finite_first(c.take(), s);
}

double output_interval(const scene::Scene& scene) {
  const double interval = scene.output().interval_s();
  return interval > 0 ? interval : scene.time().end_s() / 100.0;
}

}  // namespace hfmpm::coupling
