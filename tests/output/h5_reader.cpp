// Test helper: HDF5 read-back with the C API (see h5_reader.hpp).
#include "h5_reader.hpp"

#include <hdf5.h>

#include <stdexcept>

namespace hfmpm::test {
namespace {

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::runtime_error("H5Reader " + file + ": " + what);
}

// Closes an HDF5 id on scope exit.
struct Id {
  hid_t id;
  herr_t (*close)(hid_t);
  Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~Id() {
    if (id >= 0) close(id);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
};

}  // namespace

H5Reader::H5Reader(const std::string& path) : path_(path) {
  id_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id_ < 0) fail(path_, "H5Fopen failed");
}

H5Reader::~H5Reader() {
  if (id_ >= 0) H5Fclose(id_);
}

bool H5Reader::exists(const std::string& object) const {
  if (object.empty() || object[0] != '/') fail(path_, "not an absolute path: " + object);
  for (std::size_t slash = object.find('/', 1);; slash = object.find('/', slash + 1)) {
    const std::string prefix = object.substr(0, slash);
    const htri_t e = H5Lexists(id_, prefix.c_str(), H5P_DEFAULT);
    if (e < 0) fail(path_, "H5Lexists " + prefix);
    if (e == 0) return false;
    if (slash == std::string::npos) return true;
  }
}

std::vector<std::string> H5Reader::children(const std::string& group) const {
  Id g(H5Gopen2(id_, group.c_str(), H5P_DEFAULT), H5Gclose);
  if (g.id < 0) fail(path_, "H5Gopen2 " + group);
  H5G_info_t info;
  if (H5Gget_info(g.id, &info) < 0) fail(path_, "H5Gget_info " + group);
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[256];
    if (H5Lget_name_by_idx(g.id, ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT) < 0) {
      fail(path_, "H5Lget_name_by_idx " + group);
    }
    names.emplace_back(name);
  }
  return names;
}

std::vector<std::uint64_t> H5Reader::dims(const std::string& dataset) const {
  Id d(H5Dopen2(id_, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) fail(path_, "H5Dopen2 " + dataset);
  Id space(H5Dget_space(d.id), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.id);
  if (rank < 0) fail(path_, "rank of " + dataset);
  std::vector<hsize_t> out(static_cast<std::size_t>(rank));
  if (H5Sget_simple_extent_dims(space.id, out.data(), nullptr) < 0) fail(path_, "dims of " + dataset);
  return {out.begin(), out.end()};
}

namespace {
bool has_type(hid_t file, const std::string& path, const std::string& dataset, H5T_class_t cls, std::size_t size) {
  Id d(H5Dopen2(file, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) fail(path, "H5Dopen2 " + dataset);
  Id type(H5Dget_type(d.id), H5Tclose);
  if (type.id < 0) fail(path, "H5Dget_type " + dataset);
  if (H5Tget_class(type.id) != cls || H5Tget_size(type.id) != size) return false;
  return cls != H5T_INTEGER || H5Tget_sign(type.id) == H5T_SGN_2;
}

template <class T>
std::vector<T> read(hid_t file, const std::string& path, const std::string& dataset, hid_t mem_type,
                    std::size_t count) {
  std::vector<T> values(count);
  if (count == 0) return values;
  Id d(H5Dopen2(file, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) fail(path, "H5Dopen2 " + dataset);
  if (H5Dread(d.id, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0) fail(path, "H5Dread " + dataset);
  return values;
}

std::size_t product(const std::vector<std::uint64_t>& dims) {
  std::size_t n = 1;
  for (auto d : dims) n *= d;
  return n;
}
}  // namespace

bool H5Reader::is_f64(const std::string& dataset) const { return has_type(id_, path_, dataset, H5T_FLOAT, 8); }
bool H5Reader::is_i32(const std::string& dataset) const { return has_type(id_, path_, dataset, H5T_INTEGER, 4); }

std::vector<double> H5Reader::f64(const std::string& dataset) const {
  if (!is_f64(dataset)) fail(path_, dataset + " is not float64");
  return read<double>(id_, path_, dataset, H5T_NATIVE_DOUBLE, product(dims(dataset)));
}

std::vector<std::int32_t> H5Reader::i32(const std::string& dataset) const {
  if (!is_i32(dataset)) fail(path_, dataset + " is not int32");
  return read<std::int32_t>(id_, path_, dataset, H5T_NATIVE_INT32, product(dims(dataset)));
}

namespace {
template <class T>
T read_attribute(hid_t file, const std::string& path, const std::string& object, const std::string& name,
                 hid_t mem_type) {
  Id a(H5Aopen_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.id < 0) fail(path, "H5Aopen_by_name " + object + " @" + name);
  T value{};
  if (H5Aread(a.id, mem_type, &value) < 0) fail(path, "H5Aread " + object + " @" + name);
  return value;
}
}  // namespace

double H5Reader::attribute_f64(const std::string& object, const std::string& name) const {
  return read_attribute<double>(id_, path_, object, name, H5T_NATIVE_DOUBLE);
}

std::uint64_t H5Reader::attribute_u64(const std::string& object, const std::string& name) const {
  return read_attribute<std::uint64_t>(id_, path_, object, name, H5T_NATIVE_UINT64);
}

std::string H5Reader::attribute_string(const std::string& object, const std::string& name) const {
  Id a(H5Aopen_by_name(id_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.id < 0) fail(path_, "H5Aopen_by_name " + object + " @" + name);
  Id type(H5Aget_type(a.id), H5Tclose);
  if (H5Tget_class(type.id) != H5T_STRING || H5Tis_variable_str(type.id) != 0) {
    fail(path_, object + " @" + name + " is not a fixed-length string");
  }
  std::string buffer(H5Tget_size(type.id), '\0');
  if (H5Aread(a.id, type.id, buffer.data()) < 0) fail(path_, "H5Aread " + object + " @" + name);
  return buffer.substr(0, buffer.find('\0'));
}

std::pair<std::uint64_t, std::uint64_t> H5Reader::data_extent(const std::string& dataset) const {
  Id d(H5Dopen2(id_, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) fail(path_, "H5Dopen2 " + dataset);
  const hsize_t size = H5Dget_storage_size(d.id);
  if (size == 0) return {0, 0};
  const haddr_t offset = H5Dget_offset(d.id);
  if (offset == HADDR_UNDEF) fail(path_, dataset + " is not contiguous (H5Dget_offset)");
  return {offset, size};
}

namespace {
// The file opened read-write and the object, for an attribute edit.
struct Target {
  Id file, object;
  explicit Target(const std::string& path, const std::string& name)
      : file(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose),
        object(file.id < 0 ? -1 : H5Oopen(file.id, name.c_str(), H5P_DEFAULT), H5Oclose) {
    if (file.id < 0) fail(path, "H5Fopen read-write");
    if (object.id < 0) fail(path, "H5Oopen " + name);
  }
};
}  // namespace

void set_string_attribute(const std::string& file, const std::string& object, const std::string& name,
                          const std::string& value) {
  Target target(file, object);
  if (H5Aexists(target.object.id, name.c_str()) > 0 && H5Adelete(target.object.id, name.c_str()) < 0) {
    fail(file, "H5Adelete " + object + " @" + name);
  }
  Id type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id, value.size() + 1);
  H5Tset_strpad(type.id, H5T_STR_NULLTERM);
  Id space(H5Screate(H5S_SCALAR), H5Sclose);
  Id a(H5Acreate2(target.object.id, name.c_str(), type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.id < 0 || H5Awrite(a.id, type.id, value.c_str()) < 0) fail(file, "writing " + object + " @" + name);
}

void delete_attribute(const std::string& file, const std::string& object, const std::string& name) {
  Target target(file, object);
  if (H5Adelete(target.object.id, name.c_str()) < 0) fail(file, "H5Adelete " + object + " @" + name);
}

}  // namespace hfmpm::test
