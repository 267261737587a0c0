// HDF5 constants whose macros expand to C-style casts (H5S_ALL, and H5P_DEFAULT / H5E_DEFAULT in some HDF5
// versions), wrapped in functions. Only h5_macros.cpp, compiled with -Wno-old-style-cast, expands them.
#pragma once

#include <hdf5.h>

namespace hfmpm::output::h5 {

hid_t default_plist();  // H5P_DEFAULT
hid_t all_space();      // H5S_ALL
hid_t default_stack();  // H5E_DEFAULT

}  // namespace hfmpm::output::h5
