// The fluid side's scene rules: everything `fluid { ... }` must satisfy, for
// fluid.mpm (scene_rules_mpm.cpp) and fluid.prescribed_pressure
// (scene_rules.cpp). The coupler's validation gets them from the program
// that links this library (app/); the MPM side runs them again on the scene
// its Welcome brings.
#pragma once

#include "hfmpm/proto/scene_rules.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::fluid {

// The rules and the stable step of the scene's fluid model.
proto::SideSceneRules scene_rules();

// Rules for fluid.mpm, including how it fits the solid's cracks: the crack
// ids it fills and its initial fill against the cracks of the scene's solid
// block (the one rule that reads the other side's block; the fluid owns it
// because crack_ids and initial_fill are its keys).
void check_mpm_fluid(proto::Checker& c, const scene::Scene& s);

}  // namespace hfmpm::fluid
