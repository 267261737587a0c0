// What a scene rule is and how one is written, shared by everything that
// checks a scene: the coupler (time, output, coupling, and the rules across
// both sides) and each side's library (its own block: solid.*, fluid.*).
//
// A side's rules reach the coupler's validation as a SideSceneRules value:
// the `hfmpm` command (app/), which links both sides, hands the coupler a
// SceneRules {solid, fluid} made by solid::scene_rules() and
// fluid::scene_rules(); the coupler library itself sees no side. Each side
// also runs its own rules on the scene its Welcome brings.
#pragma once

#include <google/protobuf/message.h>

#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "hfmpm/scene.pb.h"

namespace hfmpm::proto {

// One value that breaks a rule: key path ("coupling.exchange_interval",
// "solid.prescribed_crack.mouth_opening_m.table.t[2]"), its value as text
// ("" if missing), and what is allowed.
struct SceneProblem {
  std::string key;
  std::string value;
  std::string allowed;
};

inline constexpr double kInf = std::numeric_limits<double>::infinity();

inline std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// v with `significant` digits, as printf's %.*g.
inline std::string text(double v, int significant) {
  std::ostringstream out;
  out << std::setprecision(significant) << v;
  return out.str();
}

// Collects rule violations with their key, value and allowed range. The
// scene loader adds file and line.
class Checker {
 public:
  void missing(const std::string& key, const std::string& what) { problems_.push_back({key, "", what}); }
  void bad(const std::string& key, const std::string& value, const std::string& allowed) {
    problems_.push_back({key, value, allowed});
  }
  // lo < v (or lo <= v) and v <= hi, finite.
  void range(const std::string& key, double v, double lo, double hi, bool lo_open, const std::string& unit) {
    const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
    if (!ok) {
      std::string allowed = std::string("a finite value ") + (lo_open ? "> " : ">= ") + text(lo);
      if (std::isfinite(hi)) allowed += " and <= " + text(hi);
      if (!unit.empty()) allowed += " (" + unit + ")";
      bad(key, text(v), allowed);
    }
  }
  void positive(const std::string& key, double v, const std::string& unit) { range(key, v, 0, kInf, true, unit); }
  void non_negative(const std::string& key, double v, const std::string& unit) { range(key, v, 0, kInf, false, unit); }
  std::vector<SceneProblem> take() { return std::move(problems_); }

 private:
  std::vector<SceneProblem> problems_;
};

// Rules for a TimeFunction; `min_value` is the smallest value it may take.
void check_time_function(Checker& c, const std::string& key, const scene::TimeFunction& f, double min_value,
                         const std::string& unit);

// A NaN or an infinity anywhere makes every rule that uses it meaningless:
// if `message` holds any, only those numbers are reported (by the rule of
// their key among `problems` if it speaks of finiteness, else as not
// finite); otherwise `problems` is returned as it is.
std::vector<SceneProblem> finite_first(std::vector<SceneProblem> problems, const google::protobuf::Message& message);

// "KEY = VALUE is not allowed; expected ALLOWED" or "KEY is missing; expected ALLOWED".
std::string problem_text(const SceneProblem& p);

// A side's stable step as far as the scene alone tells (before any process starts).
struct SceneStep {
  bool known = false;  // false: known only once the side runs, or its value is invalid (its rules say so)
  double dt_s = 0;     // NaN: the values it needs are invalid (its rules report them; no step-count check)
  std::string source;  // what it is: "solid.prescribed_crack.stable_dt_s", "the MPM solid's stable step cfl h / c_p"
  std::string hint;    // what to check if dt_s is not a positive finite number: " (check the ...)"
};

// What a side's model costs, from the scene alone (0: nothing to count):
// its size, and its wall time per coupled step on the project's reference
// machine (a quiet 2-core machine, docs/performance.md): step_s, plus one
// particle step at particle_steps_per_s for each of its particles.
struct SceneSize {
  double particles = 0;             // an upper bound on the particles it makes
  double nodes = 0;                 // grid nodes
  double step_s = 0;                // s per coupled step (its own step and its exchange), apart from its particles
  double particle_steps_per_s = 0;  // its throughput per particle (0: none)
  std::string throughput;           // the figure in words: "MPM solid 8.6 M particle-steps/s"
};

// One side's rules for its block of the scene (solid.* or fluid.*), given a
// scene that has that side's model set. Keys are paths from the scene root.
struct SideSceneRules {
  std::function<void(Checker&, const scene::Scene&)> check;
  std::function<SceneStep(const scene::Scene&)> stable_step;
  std::function<SceneSize(const scene::Scene&)> size;
  // Whether the side's model in this scene writes checkpoints and restarts
  // from them (output.checkpoint_interval_s > 0 needs both sides to): "" if
  // it does, else what does not and what would, naming its block
  // ("solid.prescribed_crack does not write checkpoints (solid.mpm does)").
  // Unset: the scene does not tell; the side's Hello (the capability
  // "checkpoint") decides when it joins.
  std::function<std::string(const scene::Scene&)> checkpoint_refusal;
};

// The rules of both sides, for the coupler's validation.
struct SceneRules {
  SideSceneRules solid;
  SideSceneRules fluid;
};

// A side's own check of the scene it is given (e.g. in Welcome): its rules,
// numbers not finite first (finite_first); one line of problem_text() each.
std::vector<std::string> side_scene_problems(const scene::Scene& scene, const SideSceneRules& rules);

}  // namespace hfmpm::proto
