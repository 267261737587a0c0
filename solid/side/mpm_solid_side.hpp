// Protocol adapter for the MPM solid (hfmpm-solid).
#pragma once

#include <memory>

#include "hfmpm/runtime/side_runtime.hpp"
#include "hfmpm/solid/mpm/config.hpp"

namespace hfmpm::solid {

inline const char* kMpmSolidName = "hfmpm-solid";
std::unique_ptr<coupling::SideModel> make_mpm_solid_side();

// The solver configuration a validated scene describes (exposed for tests).
mpm::SolidConfig to_solid_config(const scene::MpmSolid& scene);

}  // namespace hfmpm::solid
