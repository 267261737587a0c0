// Protocol adapter for the prescribed-crack stand-in solid.
#pragma once

#include <memory>

#include "hfmpm/runtime/side_runtime.hpp"

namespace hfmpm::solid {

inline const char* kPrescribedSolidName = "hfmpm-prescribed-solid";
std::unique_ptr<coupling::SideModel> make_prescribed_solid_side();

}  // namespace hfmpm::solid
