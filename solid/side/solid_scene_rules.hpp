// The solid side's scene rules: everything `solid { ... }` must satisfy,
// for solid.mpm (scene_rules_mpm.cpp, scene_rules_geometry.cpp, sizes and
// stable step in scene_size.cpp) and solid.prescribed_crack
// (scene_rules.cpp). The coupler's validation gets them from the program
// that links this library (app/); the MPM side runs them again on the scene
// its Welcome brings.
#pragma once

#include <string>

#include "hfmpm/proto/scene_rules.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::solid {

// The rules, the stable step and the size of the scene's solid model.
proto::SideSceneRules scene_rules();

// Rough memory the MPM solid needs for its grid and particles (bytes, from
// the solver's per-node and per-particle arrays), and the most a scene may
// ask for: 3/4 of this machine's physical memory (0 if unknown: no check).
double mpm_solid_memory_bytes(const scene::MpmSolid& m);
double memory_limit_bytes();

// The parts (keys from the scene root).
void check_mpm_solid(proto::Checker& c, const scene::MpmSolid& m);       // scene_rules_mpm.cpp
void check_crack_geometry(proto::Checker& c, const scene::MpmSolid& m);  // scene_rules_geometry.cpp
void check_regions_in_grid(proto::Checker& c, const scene::MpmSolid& m);
// The MPM solid's stable step, cfl h / c_p of its fastest material (density
// scaled) as the solid computes it; NaN if the values needed are invalid.
double mpm_solid_stable_dt(const scene::MpmSolid& m);
// Grid nodes and (an upper bound on) the particles the MPM solid makes.
double mpm_solid_nodes(const scene::MpmSolid& m);
double mpm_solid_particles(const scene::MpmSolid& m);

}  // namespace hfmpm::solid
