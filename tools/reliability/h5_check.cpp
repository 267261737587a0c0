// Is an HDF5 file readable? Opened read-only through the HDF5 C API (file
// locking off, as a viewer would), every dataset read in full. The only
// file of the tool that expands HDF5 macros (compiled with -Wno-old-style-cast).
#include <hdf5.h>

#include <map>
#include <string>
#include <vector>

#include "common.hpp"

namespace hfmpm::reliability {
namespace {

struct Visit {
  std::size_t datasets = 0;
  std::string failure;
};

herr_t visit_object(hid_t root, const char* name, const H5O_info_t* info, void* data) {
  auto* visit = static_cast<Visit*>(data);
  if (info->type != H5O_TYPE_DATASET) return 0;
  const hid_t dataset = H5Dopen2(root, name, H5P_DEFAULT);
  if (dataset < 0) {
    visit->failure = std::string("cannot open dataset ") + name;
    return -1;
  }
  const hid_t space = H5Dget_space(dataset);
  const hssize_t count = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
  const hid_t type = H5Dget_type(dataset);
  const H5T_class_t kind = type < 0 ? H5T_NO_CLASS : H5Tget_class(type);
  herr_t status = -1;
  if (count >= 0 && (kind == H5T_FLOAT || kind == H5T_INTEGER)) {
    std::vector<double> buffer(static_cast<std::size_t>(count) + 1);
    status = count == 0 ? 0 : H5Dread(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data());
  } else if (count >= 0) {
    status = 0;  // strings and others: opening is enough
  }
  if (type >= 0) H5Tclose(type);
  if (space >= 0) H5Sclose(space);
  H5Dclose(dataset);
  if (status < 0) {
    visit->failure = std::string("cannot read dataset ") + name;
    return -1;
  }
  ++visit->datasets;
  return 0;
}

// FNV-1a of every dataset's bytes in its native type, by path.
herr_t digest_object(hid_t root, const char* name, const H5O_info_t* info, void* data) {
  auto* digests = static_cast<std::map<std::string, std::uint64_t>*>(data);
  if (info->type != H5O_TYPE_DATASET) return 0;
  const hid_t dataset = H5Dopen2(root, name, H5P_DEFAULT);
  if (dataset < 0) return -1;
  const hid_t space = H5Dget_space(dataset);
  const hssize_t count = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
  const hid_t type = H5Dget_type(dataset);
  const hid_t native = type < 0 ? -1 : H5Tget_native_type(type, H5T_DIR_ASCEND);
  herr_t status = -1;
  std::uint64_t hash = 14695981039346656037ull;
  if (count >= 0 && native >= 0) {
    std::vector<unsigned char> bytes(static_cast<std::size_t>(count) * H5Tget_size(native) + 1);
    status = count == 0 ? 0 : H5Dread(dataset, native, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data());
    bytes.pop_back();
    for (unsigned char c : bytes) hash = (hash ^ c) * 1099511628211ull;
  }
  if (native >= 0) H5Tclose(native);
  if (type >= 0) H5Tclose(type);
  if (space >= 0) H5Sclose(space);
  H5Dclose(dataset);
  if (status < 0) return -1;
  (*digests)[name] = hash;
  return 0;
}

}  // namespace

bool h5_digests(const std::string& path, std::map<std::string, std::uint64_t>& digests, std::string& why) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_file_locking(access, false, true);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, access);
  H5Pclose(access);
  if (file < 0) {
    why = "H5Fopen failed";
    return false;
  }
  const herr_t status = H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_NATIVE, digest_object, &digests, H5O_INFO_BASIC);
  H5Fclose(file);
  if (status < 0) why = "a dataset could not be read";
  return status >= 0;
}

bool h5_readable(const std::string& path, std::string& why) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_file_locking(access, false, true);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, access);
  H5Pclose(access);
  if (file < 0) {
    why = "H5Fopen failed";
    return false;
  }
  Visit visit;
  const herr_t status = H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_NATIVE, visit_object, &visit, H5O_INFO_BASIC);
  H5Fclose(file);
  if (status < 0) {
    why = visit.failure.empty() ? "H5Ovisit failed" : visit.failure;
    return false;
  }
  return true;
}

}  // namespace hfmpm::reliability
