// Test helper: the frames the output tests write, kept in memory so that what comes back from the HDF5 and
// XDMF files can be compared with what went in.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/output/frame_writer.hpp"

namespace hfmpm::test {

struct SetData {
  std::string name;
  std::vector<Vec2> positions;
  std::map<std::string, std::vector<double>> scalars;
  std::map<std::string, std::vector<std::int32_t>> integers;
  std::map<std::string, std::vector<Vec2>> vectors;
  std::map<std::string, std::vector<Eigen::Vector4d>> tensors;
};

struct FrameData {
  double time_s = 0;
  std::uint64_t step = 0;
  std::vector<SetData> sets;
};

// A fresh directory under /tmp, removed on destruction unless the test failed.
class Scratch {
 public:
  explicit Scratch(const std::string& name);
  ~Scratch();
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
};

// Three frames with sets "particles" (3, 4, then 6 points: scalar, integer, vector and tensor data) and
// "crack" (2, 0, then 5 points: a scalar and an integer).
std::vector<FrameData> sample_frames();

// begin_frame, points and every array of every set, end_frame.
void write_frame(output::FrameWriter& writer, const FrameData& frame);

// Checks with gtest assertions that the files hold exactly `frames` (and nothing more): every dataset and
// frame attribute of the HDF5 file, compared exactly, and the XDMF checked against the HDF5 file (check_xdmf)
// with the right sets, times, point counts, attributes and dataset paths, or, while no set has had a point,
// that there is no XDMF file. root holds the expected root string attributes (title included), also expected
// as <Information> in the XDMF.
void verify_files(const std::string& h5_path, const std::string& xmf_path, const std::vector<FrameData>& frames,
                  const std::map<std::string, std::string>& root);

}  // namespace hfmpm::test
