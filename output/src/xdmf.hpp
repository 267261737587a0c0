// The XDMF 2 text FrameWriter writes beside its HDF5 file (layout described in frame_writer.hpp), and the
// HDF5 paths both sides agree on.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace hfmpm::output::xdmf {

enum class Kind { scalar, integer, vector, tensor };

struct Array {
  std::string name;
  Kind kind;
};

// One point set of one frame, as the XDMF needs it (the data itself is in the HDF5 file).
struct Set {
  std::string name;
  std::size_t count = 0;
  std::vector<Array> arrays;
};

// The temporal collection of one set: one <Grid GridType="Uniform"> text per frame in which it was non-empty.
struct Collection {
  std::string set;
  std::vector<std::string> grids;
};

inline constexpr const char* tensor_components[4] = {"xx", "yy", "xy", "zz"};

std::string frame_group(std::size_t frame);  // "/frames/000042"
std::string set_group(std::size_t frame, const std::string& set);
std::string dataset(std::size_t frame, const std::string& set, const std::string& name);
// Shortest decimal text that reads back as the same double.
std::string format_number(double value);
// Escapes & < > " ' for XML text and attribute values.
std::string escape(const std::string& text);

// The Uniform grid of a non-empty set in one frame; h5_name is the HDF5 file's name relative to the XDMF.
std::string uniform_grid(const std::string& h5_name, std::size_t frame, double time_s, const Set& set);
// The whole document: <Information Name=... Value=.../> entries, then one temporal collection per set.
std::string document(const std::vector<std::pair<std::string, std::string>>& information,
                     const std::vector<Collection>& collections);
// Writes path.tmp, then renames it over path, so readers see either the old or the new file whole.
void write_atomically(const std::string& path, const std::string& text);

}  // namespace hfmpm::output::xdmf
