// Test helper: reads back an HDF5 file with the HDF5 C API, independently of hfmpm_output's own code.
// Every failure throws std::runtime_error naming the file and the object.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hfmpm::test {

class H5Reader {
 public:
  explicit H5Reader(const std::string& path);  // opens read-only
  ~H5Reader();
  H5Reader(const H5Reader&) = delete;
  H5Reader& operator=(const H5Reader&) = delete;

  bool exists(const std::string& object) const;                       // every link on the absolute path exists
  std::vector<std::string> children(const std::string& group) const;  // link names, sorted
  std::vector<std::uint64_t> dims(const std::string& dataset) const;
  bool is_f64(const std::string& dataset) const;                    // IEEE float, 8 bytes
  bool is_i32(const std::string& dataset) const;                    // signed integer, 4 bytes
  std::vector<double> f64(const std::string& dataset) const;        // must be f64; row-major
  std::vector<std::int32_t> i32(const std::string& dataset) const;  // must be i32
  double attribute_f64(const std::string& object, const std::string& name) const;
  std::uint64_t attribute_u64(const std::string& object, const std::string& name) const;
  std::string attribute_string(const std::string& object, const std::string& name) const;
  // Where a contiguous dataset's elements lie in the file: byte offset and byte count ({0, 0} if it has none).
  std::pair<std::uint64_t, std::uint64_t> data_extent(const std::string& dataset) const;

 private:
  std::string path_;
  std::int64_t id_ = -1;
};

// Edits of a file's attributes, for tests that make a file of an older format or a damaged one:
// a fixed-length string attribute set (replaced if it exists), or one removed.
void set_string_attribute(const std::string& file, const std::string& object, const std::string& name,
                          const std::string& value);
void delete_attribute(const std::string& file, const std::string& object, const std::string& name);

}  // namespace hfmpm::test
