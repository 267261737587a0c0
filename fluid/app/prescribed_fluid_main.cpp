// hfmpm-prescribed-fluid: the stand-in fluid as a process (see docs/protocol.md).
#include "prescribed_fluid_side.hpp"

int main(int argc, char** argv) {
  return hfmpm::coupling::side_main(argc, argv, hfmpm::protocol::FLUID, hfmpm::fluid::kPrescribedFluidName, {},
                                    hfmpm::fluid::make_prescribed_fluid_side);
}
