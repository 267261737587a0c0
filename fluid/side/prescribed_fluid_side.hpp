// Protocol adapter for the prescribed-pressure stand-in fluid.
#pragma once

#include <memory>

#include "hfmpm/runtime/side_runtime.hpp"

namespace hfmpm::fluid {

inline const char* kPrescribedFluidName = "hfmpm-prescribed-fluid";
std::unique_ptr<coupling::SideModel> make_prescribed_fluid_side();

}  // namespace hfmpm::fluid
