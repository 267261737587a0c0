// Checked HDF5 C API calls for FrameWriter (see h5.hpp).
#include "h5.hpp"

#include <stdexcept>
#include <utility>

#include "h5_macros.hpp"

namespace hfmpm::output::h5 {
namespace {

// Innermost message on HDF5's error stack, e.g. "unable to open file: ... errno = 2 ...".
herr_t remember_message(unsigned /*n*/, const H5E_error2_t* error, void* client_data) {
  auto* message = static_cast<std::string*>(client_data);
  message->assign(error->func_name ? error->func_name : "?");
  if (error->desc) message->append(": ").append(error->desc);
  return 0;
}

std::string hdf5_message() {
  std::string message;
  if (H5Ewalk2(default_stack(), H5E_WALK_DOWNWARD, remember_message, &message) < 0 || message.empty()) {
    return "no HDF5 error message";
  }
  return message;
}

[[noreturn]] void fail(const std::string& file, const std::string& what, const std::string& object) {
  throw std::runtime_error("HDF5 file " + file + ": " + what + (object.empty() ? "" : " " + object) + " failed (" +
                           hdf5_message() + ")");
}

// Mutes HDF5's automatic error printing for its lifetime (the message goes into the exception instead).
class Quiet {
 public:
  Quiet() {
    saved_ = H5Eget_auto2(default_stack(), &function_, &data_) >= 0;
    if (saved_) H5Eset_auto2(default_stack(), nullptr, nullptr);
  }
  ~Quiet() {
    if (saved_) H5Eset_auto2(default_stack(), function_, data_);
  }
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
  bool saved_ = false;
};

// An HDF5 identifier closed on destruction; close() closes it with a check.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() {
    if (id_ >= 0) closer_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Returns false if HDF5 reports an error while closing.
  bool close() { return closer_(std::exchange(id_, -1)) >= 0; }

 private:
  hid_t id_;
  Closer closer_;
};

}  // namespace

File::File(const std::string& path) : path_(path) {
  Quiet quiet;
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid()) fail(path_, "creating a file-access property list for", "");
#if (H5_VERSION_GE(1, 10, 7) && !H5_VERSION_GE(1, 12, 0)) || H5_VERSION_GE(1, 12, 1)
  // No advisory lock on our handle, so that a viewer can open the file while the run writes it.
  if (H5Pset_file_locking(access.get(), false, true) < 0) fail(path_, "disabling file locking for", "");
#endif
  id_ = H5Fcreate(path_.c_str(), H5F_ACC_TRUNC, default_plist(), access.get());
  if (id_ < 0) fail(path_, "creating (H5Fcreate)", "");
  if (!access.close()) fail(path_, "closing the file-access property list of", "");
}

File::File(const std::string& path, OpenExisting) : path_(path) {
  Quiet quiet;
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid()) fail(path_, "creating a file-access property list for", "");
#if (H5_VERSION_GE(1, 10, 7) && !H5_VERSION_GE(1, 12, 0)) || H5_VERSION_GE(1, 12, 1)
  if (H5Pset_file_locking(access.get(), false, true) < 0) fail(path_, "disabling file locking for", "");
#endif
  id_ = H5Fopen(path_.c_str(), H5F_ACC_RDWR, access.get());
  if (id_ < 0) fail(path_, "opening for writing (H5Fopen)", "");
  if (!access.close()) fail(path_, "closing the file-access property list of", "");
}

namespace {
herr_t collect_name(hid_t /*group*/, const char* name, const H5L_info_t* /*info*/, void* data) {
  static_cast<std::vector<std::string>*>(data)->emplace_back(name);
  return 0;
}
}  // namespace

std::vector<std::string> File::children(const std::string& group) {
  Quiet quiet;
  std::vector<std::string> names;
  Handle g(H5Gopen2(id_, group.c_str(), default_plist()), H5Gclose);
  if (!g.valid()) fail(path_, "opening group", group);
  if (H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_name, &names) < 0) {
    fail(path_, "listing group", group);
  }
  return names;
}

void File::remove(const std::string& object) {
  Quiet quiet;
  if (H5Ldelete(id_, object.c_str(), default_plist()) < 0) fail(path_, "removing", object);
}

void File::write_u8(const std::string& object, const std::vector<hsize_t>& dims, const std::uint8_t* data) {
  write_dataset(object, dims, H5T_STD_U8LE, H5T_NATIVE_UINT8, data);
}

File::~File() {
  if (id_ >= 0) {
    Quiet quiet;
    H5Fclose(id_);
  }
}

void File::create_group(const std::string& object) {
  Quiet quiet;
  Handle group(H5Gcreate2(id_, object.c_str(), default_plist(), default_plist(), default_plist()), H5Gclose);
  if (!group.valid()) fail(path_, "creating group", object);
  if (!group.close()) fail(path_, "closing group", object);
}

void File::write_f64(const std::string& object, const std::vector<hsize_t>& dims, const double* data) {
  write_dataset(object, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data);
}

void File::write_i32(const std::string& object, const std::vector<hsize_t>& dims, const std::int32_t* data) {
  write_dataset(object, dims, H5T_STD_I32LE, H5T_NATIVE_INT32, data);
}

void File::write_u64(const std::string& object, const std::vector<hsize_t>& dims, const std::uint64_t* data) {
  write_dataset(object, dims, H5T_STD_U64LE, H5T_NATIVE_UINT64, data);
}

void File::write_dataset(const std::string& object, const std::vector<hsize_t>& dims, hid_t file_type, hid_t mem_type,
                         const void* data) {
  Quiet quiet;
  hsize_t elements = 1;
  for (hsize_t d : dims) elements *= d;
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  if (!space.valid()) fail(path_, "creating the dataspace of dataset", object);
  Handle dataset(
      H5Dcreate2(id_, object.c_str(), file_type, space.get(), default_plist(), default_plist(), default_plist()),
      H5Dclose);
  if (!dataset.valid()) fail(path_, "creating dataset", object);
  if (elements > 0) {
    if (data == nullptr) throw std::logic_error("h5::File: no data for dataset " + object);
    if (H5Dwrite(dataset.get(), mem_type, all_space(), all_space(), default_plist(), data) < 0) {
      fail(path_, "writing dataset", object);
    }
  }
  if (!dataset.close()) fail(path_, "closing dataset", object);
  if (!space.close()) fail(path_, "closing the dataspace of dataset", object);
}

void File::set_attribute(const std::string& object, const std::string& name, double value) {
  Quiet quiet;
  write_attribute(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

void File::set_attribute(const std::string& object, const std::string& name, std::uint64_t value) {
  Quiet quiet;
  write_attribute(object, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value);
}

void File::set_attribute(const std::string& object, const std::string& name, const std::string& value) {
  Quiet quiet;
  // Fixed-length, null-terminated UTF-8 string holding the value and its terminator.
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), value.size() + 1) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLTERM) < 0 || H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0) {
    fail(path_, "making the string type of attribute " + name + " on", object);
  }
  write_attribute(object, name, type.get(), type.get(), value.c_str());
  if (!type.close()) fail(path_, "closing the string type of attribute " + name + " on", object);
}

// Called with errors muted.
void File::write_attribute(const std::string& object, const std::string& name, hid_t file_type, hid_t mem_type,
                           const void* data) {
  const std::string what = "attribute " + name + " on";
  Handle target(H5Oopen(id_, object.c_str(), default_plist()), H5Oclose);
  if (!target.valid()) fail(path_, "opening object for " + what, object);
  const htri_t exists = H5Aexists(target.get(), name.c_str());
  if (exists < 0) fail(path_, "looking up " + what, object);
  if (exists > 0 && H5Adelete(target.get(), name.c_str()) < 0) fail(path_, "replacing " + what, object);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  if (!space.valid()) fail(path_, "creating the dataspace of " + what, object);
  Handle attribute(H5Acreate2(target.get(), name.c_str(), file_type, space.get(), default_plist(), default_plist()),
                   H5Aclose);
  if (!attribute.valid()) fail(path_, "creating " + what, object);
  if (H5Awrite(attribute.get(), mem_type, data) < 0) fail(path_, "writing " + what, object);
  if (!attribute.close()) fail(path_, "closing " + what, object);
  if (!space.close()) fail(path_, "closing the dataspace of " + what, object);
  if (!target.close()) fail(path_, "closing object after " + what, object);
}

void File::flush() {
  Quiet quiet;
  if (H5Fflush(id_, H5F_SCOPE_GLOBAL) < 0) fail(path_, "flushing (H5Fflush)", "");
}

ReadFile::ReadFile(const std::string& path) : path_(path) {
  Quiet quiet;
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid()) fail(path_, "creating a file-access property list for", "");
#if (H5_VERSION_GE(1, 10, 7) && !H5_VERSION_GE(1, 12, 0)) || H5_VERSION_GE(1, 12, 1)
  if (H5Pset_file_locking(access.get(), false, true) < 0) fail(path_, "disabling file locking for", "");
#endif
  id_ = H5Fopen(path_.c_str(), H5F_ACC_RDONLY, access.get());
  if (id_ < 0) fail(path_, "opening (H5Fopen)", "");
}

ReadFile::~ReadFile() {
  if (id_ >= 0) {
    Quiet quiet;
    H5Fclose(id_);
  }
}

bool ReadFile::has(const std::string& object) const {
  Quiet quiet;
  return H5Lexists(id_, object.c_str(), default_plist()) > 0;
}

std::size_t ReadFile::elements(const std::string& object) const {
  Quiet quiet;
  if (!has(object)) throw std::runtime_error("checkpoint " + path_ + " has no array " + object);
  Handle dataset(H5Dopen2(id_, object.c_str(), default_plist()), H5Dclose);
  if (!dataset.valid()) fail(path_, "opening dataset", object);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  if (!space.valid()) fail(path_, "reading the dataspace of dataset", object);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) fail(path_, "counting the elements of dataset", object);
  return static_cast<std::size_t>(n);
}

void ReadFile::read(const std::string& object, hid_t mem_type, hid_t want_class, void* data, std::size_t n) const {
  Quiet quiet;
  Handle dataset(H5Dopen2(id_, object.c_str(), default_plist()), H5Dclose);
  if (!dataset.valid()) fail(path_, "opening dataset", object);
  Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) fail(path_, "reading the type of dataset", object);
  if (H5Tget_class(type.get()) != static_cast<H5T_class_t>(want_class)) {
    throw std::runtime_error("checkpoint " + path_ + ": array " + object + " has another type than expected");
  }
  if (n > 0 && H5Dread(dataset.get(), mem_type, all_space(), all_space(), default_plist(), data) < 0) {
    fail(path_, "reading dataset", object);
  }
}

std::vector<double> ReadFile::read_f64(const std::string& object) const {
  std::vector<double> values(elements(object));
  read(object, H5T_NATIVE_DOUBLE, H5T_FLOAT, values.data(), values.size());
  return values;
}

std::vector<std::uint64_t> ReadFile::read_u64(const std::string& object) const {
  std::vector<std::uint64_t> values(elements(object));
  read(object, H5T_NATIVE_UINT64, H5T_INTEGER, values.data(), values.size());
  return values;
}

std::string ReadFile::read_text(const std::string& object) const {
  std::string bytes(elements(object), '\0');
  read(object, H5T_NATIVE_UINT8, H5T_INTEGER, bytes.data(), bytes.size());
  return bytes;
}

std::vector<std::string> ReadFile::root_names() const {
  Quiet quiet;
  std::vector<std::string> names;
  if (H5Literate(id_, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_name, &names) < 0) fail(path_, "listing group", "/");
  return names;
}

bool ReadFile::is_dataset(const std::string& object) const {
  Quiet quiet;
  Handle target(H5Oopen(id_, object.c_str(), default_plist()), H5Oclose);
  if (!target.valid()) fail(path_, "opening object", object);
  return H5Iget_type(target.get()) == H5I_DATASET;
}

std::string ReadFile::array_type(const std::string& object) const {
  Quiet quiet;
  Handle dataset(H5Dopen2(id_, object.c_str(), default_plist()), H5Dclose);
  if (!dataset.valid()) fail(path_, "opening dataset", object);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  if (!space.valid()) fail(path_, "reading the dataspace of dataset", object);
  if (H5Sget_simple_extent_ndims(space.get()) != 1) return {};
  Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) fail(path_, "reading the type of dataset", object);
  if (H5Tequal(type.get(), H5T_IEEE_F64LE) > 0) return "f64";
  if (H5Tequal(type.get(), H5T_STD_U64LE) > 0) return "u64";
  if (H5Tequal(type.get(), H5T_STD_U8LE) > 0) return "u8";
  return {};
}

std::string ReadFile::raw_bytes(const std::string& object) const {
  Quiet quiet;
  Handle dataset(H5Dopen2(id_, object.c_str(), default_plist()), H5Dclose);
  if (!dataset.valid()) fail(path_, "opening dataset", object);
  Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) fail(path_, "reading the type of dataset", object);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  if (!space.valid()) fail(path_, "reading the dataspace of dataset", object);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  const std::size_t size = H5Tget_size(type.get());
  if (n < 0 || size == 0) fail(path_, "counting the bytes of dataset", object);
  // A damaged dataspace can claim any size: no more than the file holds is read.
  hsize_t file_size = 0;
  if (H5Fget_filesize(id_, &file_size) < 0) fail(path_, "reading the size of", "");
  if (static_cast<hsize_t>(n) > file_size / size) {
    throw std::runtime_error("HDF5 file " + path_ + ": dataset " + object + " claims " + std::to_string(n) +
                             " elements of " + std::to_string(size) + " bytes, more than the whole file (" +
                             std::to_string(file_size) + " bytes)");
  }
  // The file type as the memory type: HDF5 converts nothing.
  std::string bytes(static_cast<std::size_t>(n) * size, '\0');
  if (n > 0 && H5Dread(dataset.get(), type.get(), all_space(), all_space(), default_plist(), bytes.data()) < 0) {
    fail(path_, "reading dataset", object);
  }
  return bytes;
}

std::string ReadFile::attribute(const std::string& object, const std::string& name) const {
  Quiet quiet;
  Handle target(H5Oopen(id_, object.c_str(), default_plist()), H5Oclose);
  if (!target.valid()) fail(path_, "opening object for attribute " + name + " on", object);
  const htri_t exists = H5Aexists(target.get(), name.c_str());
  if (exists < 0) fail(path_, "looking up attribute " + name + " on", object);
  if (exists == 0) return {};
  Handle attribute(H5Aopen(target.get(), name.c_str(), default_plist()), H5Aclose);
  if (!attribute.valid()) fail(path_, "opening attribute", name);
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0) return {};
  const std::size_t size = H5Tget_size(type.get());
  std::string value(size, '\0');
  if (size > 0 && H5Aread(attribute.get(), type.get(), value.data()) < 0) fail(path_, "reading attribute", name);
  value.resize(value.find('\0') == std::string::npos ? size : value.find('\0'));
  return value;
}

}  // namespace hfmpm::output::h5
