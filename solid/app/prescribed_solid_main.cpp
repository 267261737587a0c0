// hfmpm-prescribed-solid: the stand-in solid as a process (see docs/protocol.md).
#include "prescribed_solid_side.hpp"

int main(int argc, char** argv) {
  return hfmpm::coupling::side_main(argc, argv, hfmpm::protocol::SOLID, hfmpm::solid::kPrescribedSolidName,
                                    {"crack-growth"}, hfmpm::solid::make_prescribed_solid_side);
}
