// XDMF 2 text for FrameWriter (see xdmf.hpp and the layout notes in frame_writer.hpp).
#include "xdmf.hpp"

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace hfmpm::output::xdmf {
namespace {

// Indentation of a Uniform grid's children: Xdmf > Domain > Grid(temporal) > Grid(uniform) > child.
constexpr const char* k_in = "        ";

std::string data_item(const std::string& h5_name, const std::string& object, const std::string& dims, bool integer) {
  const char* type = integer ? R"(NumberType="Int" Precision="4")" : R"(NumberType="Float" Precision="8")";
  return R"(<DataItem Format="HDF" Dimensions=")" + dims + "\" " + type + ">" + escape(h5_name) + ":" + object +
         "</DataItem>";
}

}  // namespace

std::string frame_group(std::size_t frame) {
  char text[32];
  std::snprintf(text, sizeof text, "/frames/%06zu", frame);
  return text;
}

std::string set_group(std::size_t frame, const std::string& set) { return frame_group(frame) + "/" + set; }

std::string dataset(std::size_t frame, const std::string& set, const std::string& name) {
  return set_group(frame, set) + "/" + name;
}

std::string format_number(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof text, value);
  if (result.ec != std::errc()) throw std::logic_error("xdmf::format_number: to_chars failed");
  return std::string(text, result.ptr);
}

std::string escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string uniform_grid(const std::string& h5_name, std::size_t frame, double time_s, const Set& set) {
  const std::string n = std::to_string(set.count);
  const std::string in = k_in;
  std::string s;
  s += "      <Grid Name=\"" + set.name + "\" GridType=\"Uniform\">\n";
  s += in + "<Time Value=\"" + format_number(time_s) + "\"/>\n";
  s += in + "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" + n + "\" NodesPerElement=\"1\"/>\n";
  s += in + "<Geometry GeometryType=\"XY\">\n";
  s += in + "  " + data_item(h5_name, dataset(frame, set.name, "positions"), n + " 2", false) + "\n";
  s += in + "</Geometry>\n";
  auto attribute = [&](const std::string& name, const char* type, const std::string& item) {
    s += in + "<Attribute Name=\"" + name + "\" AttributeType=\"" + type + "\" Center=\"Node\">\n";
    s += item;
    s += in + "</Attribute>\n";
  };
  for (const Array& array : set.arrays) {
    const std::string object = dataset(frame, set.name, array.name);
    switch (array.kind) {
      case Kind::scalar:
        attribute(array.name, "Scalar", in + "  " + data_item(h5_name, object, n, false) + "\n");
        break;
      case Kind::integer:
        attribute(array.name, "Scalar", in + "  " + data_item(h5_name, object, n, true) + "\n");
        break;
      case Kind::vector:
        attribute(array.name, "Vector", in + "  " + data_item(h5_name, object, n + " 3", false) + "\n");
        break;
      case Kind::tensor:
        // Column c of the N x 4 dataset: HyperSlab rows are start, stride and count per dimension.
        for (int c = 0; c < 4; ++c) {
          std::string item;
          item += in + "  <DataItem ItemType=\"HyperSlab\" Type=\"HyperSlab\" Dimensions=\"" + n + " 1\">\n";
          item += in + "    <DataItem Format=\"XML\" Dimensions=\"3 2\">0 " + std::to_string(c) + " 1 1 " + n +
                  " 1</DataItem>\n";
          item += in + "    " + data_item(h5_name, object, n + " 4", false) + "\n";
          item += in + "  </DataItem>\n";
          attribute(array.name + "_" + tensor_components[c], "Scalar", item);
        }
        break;
    }
  }
  s += "      </Grid>\n";
  return s;
}

std::string document(const std::vector<std::pair<std::string, std::string>>& information,
                     const std::vector<Collection>& collections) {
  std::size_t size = 256;
  for (const Collection& c : collections) {
    for (const std::string& g : c.grids) size += g.size();
  }
  std::string s;
  s.reserve(size);
  s += "<?xml version=\"1.0\" ?>\n";
  s += "<Xdmf Version=\"2.0\">\n";
  s += "  <Domain>\n";
  for (const auto& [name, value] : information) {
    s += "    <Information Name=\"" + escape(name) + "\" Value=\"" + escape(value) + "\"/>\n";
  }
  for (const Collection& c : collections) {
    s += "    <Grid Name=\"" + c.set + "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const std::string& g : c.grids) s += g;
    s += "    </Grid>\n";
  }
  s += "  </Domain>\n";
  s += "</Xdmf>\n";
  return s;
}

void write_atomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("XDMF: cannot create " + temporary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw std::runtime_error("XDMF: cannot write " + temporary);
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw std::runtime_error("XDMF: cannot rename " + temporary + " to " + path + ": " + error.message());
  }
}

}  // namespace hfmpm::output::xdmf
