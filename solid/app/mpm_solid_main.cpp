// hfmpm-solid: the MPM solid as a process (see docs/protocol.md).
#include "mpm_solid_side.hpp"

int main(int argc, char** argv) {
  return hfmpm::coupling::side_main(argc, argv, hfmpm::protocol::SOLID, hfmpm::solid::kMpmSolidName, {},
                                    hfmpm::solid::make_mpm_solid_side);
}
