// Scene files: Protobuf text format of hfmpm.scene.Scene (proto/hfmpm/scene.proto).
// Load, apply command-line overrides, validate every value; a bad scene
// throws SceneError whose text names the file, line, key, value and what is
// allowed, before any process starts.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "hfmpm/coupling/method.hpp"
#include "hfmpm/proto/scene_rules.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

class SceneError : public std::runtime_error {
 public:
  explicit SceneError(const std::vector<std::string>& problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// One value that breaks a rule (key path, value as text, what is allowed).
using proto::SceneProblem;
// Each side's rules for its block of the scene (solid.*, fluid.*): the
// coupler sees no side, so the program that links them hands them over
// (app/: SceneRules{solid::scene_rules(), fluid::scene_rules()}).
using proto::SceneRules;

// Reads `path`, applies `overrides` ("key.path=value", in order), validates
// with the coupler's rules and the sides' `rules`.
// The scene's method keys it leaves unset are derived from its physics
// (hfmpm/coupling/method.hpp) before validation; `derived` gets them, with
// their rules.
scene::Scene load_scene(const std::string& path, const SceneRules& rules,
                        const std::vector<std::string>& overrides = {},
                        std::vector<method::Setting>* derived = nullptr);
// Same from text; `name` stands for the file in messages.
scene::Scene parse_scene(const std::string& text, const std::string& name, const SceneRules& rules,
                         const std::vector<std::string>& overrides = {},
                         std::vector<method::Setting>* derived = nullptr);

// Sets one value by its dotted key path; throws SceneError for an unknown key
// or a value of the wrong type. Repeated fields take "[a, b]" and are replaced.
// Brackets select one existing element of a repeated field, by index
// (solid.mpm.cracks[1].x_m, solid.mpm.cracks[0].x_m[1]) or, where its messages
// have a string `name`, by name (solid.mpm.materials[rock], materials["rock"]);
// none is added. A refused override leaves `scene` as it was.
void apply_override(scene::Scene& scene, const std::string& assignment);

// Every rule the scene breaks (empty if valid): the coupler's (name, time,
// output, coupling, across both sides) and, in their place, the sides'.
std::vector<SceneProblem> validate(const scene::Scene& scene, const SceneRules& rules);

// Most steps a run may need to reach time.end_s (validation and the coupler).
inline constexpr double kMaxRunSteps = 1e9;

// The shortest output.interval_s and output.checkpoint_interval_s allowed:
// end_s / kMaxRunSteps, the step of a run of the most steps allowed (a shorter
// interval gives no more than a row, or a checkpoint, per step).
inline double min_time_interval(double end_s) { return end_s / kMaxRunSteps; }

// Effective values used by the coupler.
double output_interval(const scene::Scene& scene);

// The next time of a schedule (output rows, checkpoints) after the time t:
// `next` advanced by whole intervals until it lies beyond t (t (1 + 1e-12),
// the step loop's tolerance). One interval is added at a time as long as a
// few reach past t (the sums a run has always made: rows at the same times
// as before); more are taken at once, counted with floor; and the time
// returned is past t whatever the interval (one below t's precision, 0 or
// NaN gives the next double above t): no loop that cannot progress.
double next_time_after(double next, double interval, double t);

// The scene with every unset scalar that has a default set to it, in every
// block present (and time, output and coupling, whose every key has one):
// what `hfmpm validate` prints and what the run writes to scene.json.
scene::Scene with_defaults(const scene::Scene& scene);

}  // namespace hfmpm::coupling
