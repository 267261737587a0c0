// The only translation unit that expands HDF5's cast-carrying macros (see h5_macros.hpp); it is compiled
// with -Wno-old-style-cast (output/CMakeLists.txt).
#include "h5_macros.hpp"

namespace hfmpm::output::h5 {

hid_t default_plist() { return H5P_DEFAULT; }
hid_t all_space() { return H5S_ALL; }
hid_t default_stack() { return H5E_DEFAULT; }

}  // namespace hfmpm::output::h5
