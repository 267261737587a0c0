// Scene files: Protobuf text format of hfmpm.scene.Scene (proto/hfmpm/scene.proto).
// Load, apply command-line overrides, validate every value; a bad scene
// throws SceneError whose text names the file, line, key, value and what is
// allowed, before any process starts.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

class SceneError : public std::runtime_error {
 public:
  explicit SceneError(const std::vector<std::string>& problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// One value that breaks a rule: key path ("coupling.exchange_interval",
// "solid.prescribed_crack.mouth_opening_m.table.t[2]"), its value as text
// ("" if missing), and what is allowed.
struct SceneProblem {
  std::string key;
  std::string value;
  std::string allowed;
};

// Reads `path`, applies `overrides` ("key.path=value", in order), validates.
scene::Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});
// Same from text; `name` stands for the file in messages.
scene::Scene parse_scene(const std::string& text, const std::string& name,
                         const std::vector<std::string>& overrides = {});

// Sets one value by its dotted key path; throws SceneError for an unknown key
// or a value of the wrong type. Repeated fields take "[a, b]" and are replaced.
void apply_override(scene::Scene& scene, const std::string& assignment);

// Every rule the scene breaks (empty if valid).
std::vector<SceneProblem> validate(const scene::Scene& scene);

// Rough memory the MPM solid needs for its grid and particles (bytes, from
// the solver's per-node and per-particle arrays), and the most a scene may
// ask for: 3/4 of this machine's physical memory (0 if unknown: no check).
double mpm_solid_memory_bytes(const scene::MpmSolid& m);
double memory_limit_bytes();

// Most steps a run may need to reach time.end_s (validation and the coupler).
inline constexpr double kMaxRunSteps = 1e9;

// Effective values used by the coupler.
double output_interval(const scene::Scene& scene);

// The scene with every unset scalar that has a default set to it, in every
// block present (and time, output and coupling, whose every key has one):
// what `hfmpm validate` prints and what the run writes to scene.json.
scene::Scene with_defaults(const scene::Scene& scene);

}  // namespace hfmpm::coupling
