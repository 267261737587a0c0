// Test helper: parses an XDMF file written by FrameWriter (strictly, with xml_lite) and checks it against
// the HDF5 file beside it: every HDF DataItem names that file by its base name and a dataset that exists with
// exactly the stated Dimensions and number type, every array has one row per point of its grid, HyperSlabs
// select one column inside their source, times increase. Throws std::runtime_error on the first problem.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace hfmpm::test {

struct XdmfGrid {
  double time = 0;
  std::uint64_t count = 0;
  std::string positions;                          // HDF5 path of the geometry
  std::map<std::string, std::string> attributes;  // name -> AttributeType
  std::map<std::string, std::string> sources;     // name -> HDF5 path (for a HyperSlab, its source + "[c]")
};

struct XdmfSummary {
  std::map<std::string, std::string> information;      // <Information Name= Value=> of the Domain
  std::vector<std::string> sets;                       // temporal collections, in document order
  std::map<std::string, std::vector<XdmfGrid>> grids;  // per set, in document order
  std::vector<double> times;                           // distinct times of all grids, ascending
  std::size_t hdf_items = 0;                           // HDF DataItems checked
};

XdmfSummary check_xdmf(const std::string& xmf_path, const std::string& h5_path);

}  // namespace hfmpm::test
