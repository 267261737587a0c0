// hfmpm-fluid: the 1D MPM fluid as a process (see docs/protocol.md).
#include "mpm_fluid_side.hpp"

int main(int argc, char** argv) {
  return hfmpm::coupling::side_main(argc, argv, hfmpm::protocol::FLUID, hfmpm::fluid::kMpmFluidName, {},
                                    hfmpm::fluid::make_mpm_fluid_side);
}
