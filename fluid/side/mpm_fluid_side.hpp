// Protocol adapter for the 1D MPM fluid (hfmpm-fluid): one FluidSolver per
// fluid-filled crack, built from the solid's CrackState at the step-0 exchange.
#pragma once

#include <memory>

#include "hfmpm/fluid/mpm/config.hpp"
#include "hfmpm/runtime/side_runtime.hpp"

namespace hfmpm::fluid {

inline const char* kMpmFluidName = "hfmpm-fluid";
std::unique_ptr<coupling::SideModel> make_mpm_fluid_side();

// The solver configuration a validated scene's fluid.mpm block (and its
// coupling.scheme) describes. Every member a scene key stands for is set
// from the scene, so an omitted key gives the schema's default, never
// FluidConfig's (docs/architecture.md, "Defaults"; tests/unit/config_defaults_test.cpp).
mpm::FluidConfig to_fluid_config(const scene::Scene& scene);

}  // namespace hfmpm::fluid
