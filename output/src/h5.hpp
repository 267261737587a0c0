// A thin checked layer over the HDF5 C API for FrameWriter: one writable file, objects addressed by absolute
// path. Every HDF5 call is checked; a failure throws std::runtime_error naming the file, the object, what
// failed and HDF5's innermost error message. HDF5's automatic error printing is muted during these calls.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

namespace hfmpm::output::h5 {

class File {
 public:
  // Creates the file, truncating an existing one.
  explicit File(const std::string& path);
  // Opens an existing file for writing (FrameWriter's resume after a restart).
  struct OpenExisting {};
  File(const std::string& path, OpenExisting);
  ~File();
  File(const File&) = delete;
  File& operator=(const File&) = delete;

  void create_group(const std::string& object);
  // Datasets of the given dimensions (row-major); data may be null when a dimension is 0.
  void write_f64(const std::string& object, const std::vector<hsize_t>& dims, const double* data);
  void write_i32(const std::string& object, const std::vector<hsize_t>& dims, const std::int32_t* data);
  void write_u64(const std::string& object, const std::vector<hsize_t>& dims, const std::uint64_t* data);
  void write_u8(const std::string& object, const std::vector<hsize_t>& dims, const std::uint8_t* data);
  // Names of the links in a group, and removing one (with what hangs below it).
  std::vector<std::string> children(const std::string& group);
  void remove(const std::string&
                  object);  // Scalar attributes on a group or dataset; an existing attribute of that name is replaced.
  void set_attribute(const std::string& object, const std::string& name, double value);
  void set_attribute(const std::string& object, const std::string& name, std::uint64_t value);
  void set_attribute(const std::string& object, const std::string& name, const std::string& value);
  // Writes everything buffered by HDF5 to the file.
  void flush();
  const std::string& path() const { return path_; }

 private:
  void write_dataset(const std::string& object, const std::vector<hsize_t>& dims, hid_t file_type, hid_t mem_type,
                     const void* data);
  void write_attribute(const std::string& object, const std::string& name, hid_t file_type, hid_t mem_type,
                       const void* data);

  std::string path_;
  hid_t id_ = -1;
};

// A file opened read-only (checkpoints): whole datasets and string attributes of the root group.
class ReadFile {
 public:
  explicit ReadFile(const std::string& path);
  ~ReadFile();
  ReadFile(const ReadFile&) = delete;
  ReadFile& operator=(const ReadFile&) = delete;

  bool has(const std::string& object) const;
  // The whole dataset, converted by HDF5 to the memory type; throws if it is missing.
  std::vector<double> read_f64(const std::string& object) const;
  std::vector<std::uint64_t> read_u64(const std::string& object) const;
  std::string read_text(const std::string& object) const;  // a uint8 dataset as bytes
  // The names of the root group's links, in name order.
  std::vector<std::string> root_names() const;
  // Whether the object is a dataset (false for a group or anything else).
  bool is_dataset(const std::string& object) const;
  // "f64", "u64" or "u8" for a one-dimensional dataset of the little-endian type File writes for it
  // (IEEE float64, unsigned 64-bit or 8-bit integers); empty for any other type or shape.
  std::string array_type(const std::string& object) const;
  // Every element of a dataset in its file type, unconverted: the bytes the file holds for it.
  std::string raw_bytes(const std::string& object) const;
  // A string attribute of the root group, or of an object; empty if there is none.
  std::string root_attribute(const std::string& name) const { return attribute("/", name); }
  std::string attribute(const std::string& object, const std::string& name) const;
  const std::string& path() const { return path_; }

 private:
  void read(const std::string& object, hid_t mem_type, hid_t want_class, void* data, std::size_t n) const;
  std::size_t elements(const std::string& object) const;
  std::string path_;
  hid_t id_ = -1;
};

}  // namespace hfmpm::output::h5
