// Test helper: XDMF-against-HDF5 consistency check (see xdmf_check.hpp).
#include "xdmf_check.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "h5_reader.hpp"
#include "xml_lite.hpp"

namespace hfmpm::test {
namespace {

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error("XDMF check: " + what); }

void expect(bool ok, const std::string& what) {
  if (!ok) fail(what);
}

std::vector<std::uint64_t> numbers(const std::string& text, const std::string& context) {
  std::istringstream in(text);
  std::vector<std::uint64_t> out;
  std::string word;
  while (in >> word) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(word.c_str(), &end, 10);
    expect(!word.empty() && *end == '\0' && word[0] != '-', "not a count '" + word + "' in " + context);
    out.push_back(v);
  }
  return out;
}

double real(const std::string& text, const std::string& context) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  expect(!text.empty() && *end == '\0', "not a number '" + text + "' in " + context);
  return v;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

struct Checker {
  const H5Reader& h5;
  std::string h5_name;
  std::size_t items = 0;

  // An HDF DataItem: returns its dataset path after checking it against the file.
  std::string hdf(const xml::Element& item, const std::vector<std::uint64_t>& want_dims) {
    expect(item.name == "DataItem" && item.attribute("Format") == "HDF", "expected an HDF DataItem");
    expect(item.children.empty(), "HDF DataItem with children");
    const std::string ref = trim(item.text);
    const auto colon = ref.find(':');
    expect(colon != std::string::npos, "DataItem text without file: '" + ref + "'");
    expect(ref.substr(0, colon) == h5_name, "DataItem refers to '" + ref.substr(0, colon) + "', not " + h5_name);
    const std::string path = ref.substr(colon + 1);
    const auto dims = numbers(item.attribute("Dimensions"), path);
    expect(dims == want_dims, "Dimensions of " + path + " are not what the grid needs");
    expect(h5.exists(path), "dataset " + path + " is not in the HDF5 file");
    expect(h5.dims(path) == dims, "dataset " + path + " has other dimensions than its DataItem states");
    const std::string type = item.attribute("NumberType"), precision = item.attribute("Precision");
    if (type == "Float") {
      expect(precision == "8" && h5.is_f64(path), path + " is not float64 as stated");
    } else {
      expect(type == "Int" && precision == "4" && h5.is_i32(path), path + " is not int32 as stated");
    }
    ++items;
    return path;
  }

  // The DataItem of a Scalar attribute stored as one column of an N x 4 dataset.
  std::string hyperslab(const xml::Element& item, std::uint64_t n) {
    expect(item.attribute("ItemType") == "HyperSlab", "expected a HyperSlab DataItem");
    expect(numbers(item.attribute("Dimensions"), "HyperSlab") == std::vector<std::uint64_t>{n, 1},
           "HyperSlab Dimensions");
    expect(item.children.size() == 2, "HyperSlab needs a selection and a source");
    const xml::Element& selection = item.children[0];
    expect(selection.attribute("Format") == "XML" && selection.attribute("Dimensions") == "3 2", "HyperSlab rows");
    const auto s = numbers(selection.text, "HyperSlab selection");
    expect(s.size() == 6 && s[0] == 0 && s[1] < 4 && s[2] == 1 && s[3] == 1 && s[4] == n && s[5] == 1,
           "HyperSlab must select one whole column: '" + selection.text + "'");
    return hdf(item.children[1], {n, 4}) + "[" + std::to_string(s[1]) + "]";
  }

  XdmfGrid grid(const xml::Element& g, const std::string& set) {
    expect(g.name == "Grid" && g.attribute("GridType") == "Uniform" && g.attribute("Name") == set,
           "collection " + set + " holds something other than its Uniform grids");
    expect(g.children.size() >= 3, "grid of " + set + " lacks Time, Topology or Geometry");
    const xml::Element& time = g.children[0];
    const xml::Element& topology = g.children[1];
    const xml::Element& geometry = g.children[2];
    XdmfGrid out;
    expect(time.name == "Time", "first child of a grid must be Time");
    out.time = real(time.attribute("Value"), "Time");
    expect(topology.name == "Topology" && topology.attribute("TopologyType") == "Polyvertex" &&
               topology.attribute("NodesPerElement") == "1",
           "Topology must be Polyvertex with one node per element");
    const auto count = numbers(topology.attribute("NumberOfElements"), "NumberOfElements");
    expect(count.size() == 1 && count[0] > 0, "NumberOfElements must be one positive count");
    out.count = count[0];
    expect(geometry.name == "Geometry" && geometry.attribute("GeometryType") == "XY" && geometry.children.size() == 1,
           "Geometry must be XY with one DataItem");
    out.positions = hdf(geometry.children[0], {out.count, 2});
    for (std::size_t i = 3; i < g.children.size(); ++i) {
      const xml::Element& a = g.children[i];
      expect(a.name == "Attribute" && a.attribute("Center") == "Node" && a.children.size() == 1,
             "grid children after Geometry must be node Attributes with one DataItem");
      const std::string name = a.attribute("Name"), type = a.attribute("AttributeType");
      expect(!out.attributes.count(name), "attribute " + name + " twice in one grid");
      const xml::Element& item = a.children[0];
      std::string source;
      if (type == "Vector") {
        source = hdf(item, {out.count, 3});
      } else {
        expect(type == "Scalar", "AttributeType " + type);
        source = item.attributes.count("ItemType") ? hyperslab(item, out.count) : hdf(item, {out.count});
      }
      out.attributes[name] = type;
      out.sources[name] = source;
    }
    return out;
  }
};

}  // namespace

XdmfSummary check_xdmf(const std::string& xmf_path, const std::string& h5_path) {
  std::ifstream in(xmf_path, std::ios::binary);
  expect(static_cast<bool>(in), "cannot open " + xmf_path);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  const xml::Element root = xml::parse(text);
  expect(root.name == "Xdmf" && root.attribute("Version") == "2.0", "root must be <Xdmf Version=\"2.0\">");
  expect(root.children.size() == 1 && root.children[0].name == "Domain", "Xdmf must hold exactly one Domain");

  H5Reader h5(h5_path);
  Checker checker{h5, std::filesystem::path(h5_path).filename().string()};
  XdmfSummary summary;
  for (const xml::Element& e : root.children[0].children) {
    if (e.name == "Information") {
      summary.information[e.attribute("Name")] = e.attribute("Value");
      continue;
    }
    expect(e.name == "Grid" && e.attribute("GridType") == "Collection" && e.attribute("CollectionType") == "Temporal",
           "Domain children must be Information or temporal collections");
    const std::string set = e.attribute("Name");
    expect(!summary.grids.count(set), "two collections for set " + set);
    summary.sets.push_back(set);
    auto& grids = summary.grids[set];
    for (const xml::Element& g : e.children) {
      grids.push_back(checker.grid(g, set));
      expect(grids.size() == 1 || grids.back().time > grids[grids.size() - 2].time,
             "times of " + set + " do not increase");
      summary.times.push_back(grids.back().time);
    }
    expect(!grids.empty(), "empty collection " + set);
  }
  std::sort(summary.times.begin(), summary.times.end());
  summary.times.erase(std::unique(summary.times.begin(), summary.times.end()), summary.times.end());
  summary.hdf_items = checker.items;

  // Cross-check with a plain text search: every "file.h5:/..." reference was seen by the structural check.
  const std::regex reference(std::regex_replace(checker.h5_name, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)") +
                             ":/[A-Za-z0-9_/]+");
  const auto found = std::distance(std::sregex_iterator(text.begin(), text.end(), reference), std::sregex_iterator());
  expect(static_cast<std::size_t>(found) == summary.hdf_items, "text references and checked DataItems differ");
  return summary;
}

}  // namespace hfmpm::test
