// Protocol adapter for the MPM solid (hfmpm-solid).
#pragma once

#include <memory>

#include "hfmpm/runtime/side_runtime.hpp"
#include "hfmpm/solid/mpm/config.hpp"

namespace hfmpm::solid {

inline const char* kMpmSolidName = "hfmpm-solid";
std::unique_ptr<coupling::SideModel> make_mpm_solid_side();

// The solver configuration a validated solid.mpm block describes. Every
// member a scene key stands for is set from the scene, so an omitted key
// gives the schema's default, never SolidConfig's (threads: 2, not 1;
// docs/architecture.md, "Defaults"; tests/unit/config_defaults_test.cpp).
mpm::SolidConfig to_solid_config(const scene::MpmSolid& scene);

}  // namespace hfmpm::solid
