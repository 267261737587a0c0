// hfmpm::output::FrameWriter: call-order and size checks, the frame buffered in memory, and end_frame(),
// which writes it to HDF5 (h5.hpp) and rewrites the XDMF sidecar (xdmf.hpp).
#include "hfmpm/output/frame_writer.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "h5.hpp"
#include "xdmf.hpp"

namespace hfmpm::output {
namespace {

bool valid_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

void check_name(const char* what, const std::string& name) {
  if (!valid_name(name)) {
    throw std::invalid_argument(std::string("FrameWriter: invalid ") + what + " name '" + name +
                                "' (allowed: one or more of A-Z a-z 0-9 _)");
  }
}

struct PendingArray {
  std::string name;
  xdmf::Kind kind;
  std::vector<double> reals;       // scalar (N), vector (N x 3), tensor (N x 4), row-major
  std::vector<std::int32_t> ints;  // integer (N)
};

struct PendingSet {
  std::string name;
  std::vector<double> positions;  // N x 2, row-major
  std::vector<PendingArray> arrays;
  std::vector<std::string> xdmf_names;  // attribute names as the XDMF shows them (tensors give four)
  std::size_t count() const { return positions.size() / 2; }
};

struct PendingFrame {
  double time_s = 0;
  std::uint64_t step = 0;
  std::vector<PendingSet> sets;
};

}  // namespace

struct FrameWriter::Impl {
  Impl(const std::string& h5, const std::string& xmf) : h5_path(h5), xdmf_path(xmf), file(h5) {}
  Impl(const std::string& h5, const std::string& xmf, h5::File::OpenExisting open)
      : h5_path(h5), xdmf_path(xmf), file(h5, open) {}

  std::string h5_path, xdmf_path, h5_name;
  h5::File file;
  std::vector<std::pair<std::string, std::string>> information;  // root string attributes, in the order first set
  std::vector<xdmf::Collection> collections;
  std::optional<PendingFrame> frame;
  std::optional<double> last_time;
  std::size_t next_index = 0;  // HDF5 group number of the next frame (also counts frames that failed to write)
  std::size_t written = 0;

  // The set of the open frame an attribute refers to, after checking order, names and size.
  PendingSet& attribute_target(const char* call, const std::string& set, const std::string& name, std::size_t size) {
    if (!frame) throw std::logic_error(std::string("FrameWriter::") + call + ": no frame begun (call begin_frame)");
    check_name("set", set);
    check_name("attribute", name);
    auto it = std::find_if(frame->sets.begin(), frame->sets.end(), [&](const PendingSet& s) { return s.name == set; });
    if (it == frame->sets.end()) {
      throw std::logic_error(std::string("FrameWriter::") + call + ": attribute '" + name + "' of set '" + set +
                             "' before points() of that set in this frame");
    }
    if (name == "positions") {
      throw std::invalid_argument(std::string("FrameWriter::") + call + ": set '" + set +
                                  "': 'positions' is reserved for the points");
    }
    for (const PendingArray& a : it->arrays) {
      if (a.name == name) {
        throw std::logic_error(std::string("FrameWriter::") + call + ": set '" + set + "' already has '" + name +
                               "' in this frame");
      }
    }
    if (size != it->count()) {
      throw std::invalid_argument(std::string("FrameWriter::") + call + ": set '" + set + "', array '" + name +
                                  "' has " + std::to_string(size) + " values but the set has " +
                                  std::to_string(it->count()) + " points");
    }
    return *it;
  }

  // Adds an array after checking that its XDMF attribute names are free in the set.
  void add(PendingSet& set, PendingArray array, std::vector<std::string> shown_as) {
    for (const std::string& shown : shown_as) {
      if (std::find(set.xdmf_names.begin(), set.xdmf_names.end(), shown) != set.xdmf_names.end()) {
        throw std::logic_error("FrameWriter: set '" + set.name + "': '" + array.name + "' would show as '" + shown +
                               "', which another array of this frame already shows as");
      }
    }
    set.xdmf_names.insert(set.xdmf_names.end(), shown_as.begin(), shown_as.end());
    set.arrays.push_back(std::move(array));
  }

  void write_frame(std::size_t index, const PendingFrame& f) {
    const std::string group = xdmf::frame_group(index);
    file.create_group(group);
    file.set_attribute(group, "time_s", f.time_s);
    file.set_attribute(group, "step", f.step);
    for (const PendingSet& set : f.sets) {
      const hsize_t n = set.count();
      file.create_group(xdmf::set_group(index, set.name));
      file.write_f64(xdmf::dataset(index, set.name, "positions"), {n, 2}, set.positions.data());
      for (const PendingArray& a : set.arrays) {
        const std::string object = xdmf::dataset(index, set.name, a.name);
        switch (a.kind) {
          case xdmf::Kind::scalar:
            file.write_f64(object, {n}, a.reals.data());
            break;
          case xdmf::Kind::integer:
            file.write_i32(object, {n}, a.ints.data());
            break;
          case xdmf::Kind::vector:
            file.write_f64(object, {n, 3}, a.reals.data());
            break;
          case xdmf::Kind::tensor:
            file.write_f64(object, {n, 4}, a.reals.data());
            file.set_attribute(object, "components", std::string("xx yy xy zz"));
            break;
        }
      }
    }
  }

  // No XDMF while no set has had a point: ParaView's XDMF readers crash on a Domain without grids.
  void write_xdmf() {
    if (!collections.empty()) xdmf::write_atomically(xdmf_path, xdmf::document(information, collections));
  }
};

FrameWriter::FrameWriter(const std::string& h5_path, const std::string& title) {
  namespace fs = std::filesystem;
  const fs::path h5(h5_path);
  const std::string name = h5.filename().string();
  if (name.empty()) throw std::invalid_argument("FrameWriter: HDF5 path '" + h5_path + "' names no file");
  // XDMF's "file:/dataset" syntax has no escape for a colon in the file name.
  if (name.find(':') != std::string::npos) {
    throw std::invalid_argument("FrameWriter: HDF5 file name '" + name + "' contains ':', which XDMF cannot refer to");
  }
  const std::string xmf = fs::path(h5).replace_extension(".xmf").string();
  if (xmf == h5_path) throw std::invalid_argument("FrameWriter: HDF5 path '" + h5_path + "' ends in .xmf");

  impl_ = std::make_unique<Impl>(h5_path, xmf);
  // The HDF5 file was just truncated: an XDMF left by an earlier run would refer to data that is gone.
  for (const std::string& stale : {xmf, xmf + ".tmp"}) {
    std::error_code error;
    fs::remove(stale, error);
    if (error) throw std::runtime_error("FrameWriter: cannot remove the old " + stale + ": " + error.message());
  }
  impl_->h5_name = name;
  impl_->file.create_group("/frames");
  impl_->file.set_attribute("/frames", "frame_count", std::uint64_t{0});
  attribute("title", title);  // also flushes
}

void FrameWriter::save(StateWriter& out) const {
  const Impl& m = *impl_;
  if (m.frame) throw std::logic_error("FrameWriter::save: a frame is open (call end_frame first)");
  out.put("next_index", m.next_index);
  out.put("written", m.written);
  out.put("has_last_time", m.last_time ? 1 : 0);
  out.put("last_time", m.last_time.value_or(0.0));
  // Strings as one blob each, with their lengths.
  auto strings = [&](const std::string& name, const std::vector<std::string>& list) {
    std::string blob;
    std::vector<std::uint64_t> lengths;
    for (const auto& text : list) {
      blob += text;
      lengths.push_back(text.size());
    }
    out.text(name + ".text", blob);
    out.put(name + ".lengths", lengths);
  };
  std::vector<std::string> information;
  for (const auto& [key, value] : m.information) {
    information.push_back(key);
    information.push_back(value);
  }
  strings("information", information);
  std::vector<std::string> sets;
  for (const auto& c : m.collections) sets.push_back(c.set);
  strings("sets", sets);
  for (std::size_t i = 0; i < m.collections.size(); ++i) strings("grids" + std::to_string(i), m.collections[i].grids);
}

namespace {
std::vector<std::string> saved_strings(const StateReader& in, const std::string& name) {
  const std::string blob = in.text(name + ".text");
  std::vector<std::uint64_t> lengths;
  in.get(name + ".lengths", lengths);
  std::vector<std::string> list;
  std::size_t at = 0;
  for (auto n : lengths) {
    if (n > blob.size() - at) throw std::runtime_error("FrameWriter: the saved " + name + " are cut short");
    list.push_back(blob.substr(at, n));
    at += n;
  }
  return list;
}
}  // namespace

FrameWriter::FrameWriter(const std::string& h5_path, const StateReader& saved) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_regular_file(h5_path, error)) {
    throw std::runtime_error("FrameWriter: cannot continue " + h5_path + ": the file is not there");
  }
  const std::string xmf = fs::path(h5_path).replace_extension(".xmf").string();
  impl_ = std::make_unique<Impl>(h5_path, xmf, h5::File::OpenExisting{});
  Impl& m = *impl_;
  m.h5_name = fs::path(h5_path).filename().string();
  saved.get("next_index", m.next_index);
  saved.get("written", m.written);
  int has_last = 0;
  saved.get("has_last_time", has_last);
  double last = 0;
  saved.get("last_time", last);
  if (has_last) m.last_time = last;
  const auto information = saved_strings(saved, "information");
  for (std::size_t i = 0; i + 1 < information.size(); i += 2)
    m.information.emplace_back(information[i], information[i + 1]);
  const auto sets = saved_strings(saved, "sets");
  for (std::size_t i = 0; i < sets.size(); ++i) {
    m.collections.push_back(xdmf::Collection{sets[i], saved_strings(saved, "grids" + std::to_string(i))});
  }
  // Frames numbered from next_index on were written after the saved state: they go.
  for (const std::string& name : m.file.children("/frames")) {
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::stoull(name) >= m.next_index) m.file.remove("/frames/" + name);
  }
  m.file.set_attribute("/frames", "frame_count", static_cast<std::uint64_t>(m.written));
  m.file.flush();
  m.write_xdmf();
}

FrameWriter::~FrameWriter() = default;
FrameWriter::FrameWriter(FrameWriter&&) noexcept = default;
FrameWriter& FrameWriter::operator=(FrameWriter&&) noexcept = default;

namespace {
template <class I>
I& live(const std::unique_ptr<I>& impl) {
  if (!impl) throw std::logic_error("FrameWriter: used after being moved from");
  return *impl;
}
}  // namespace

void FrameWriter::begin_frame(double time_s, std::uint64_t step) {
  Impl& m = live(impl_);
  if (m.frame) throw std::logic_error("FrameWriter::begin_frame: the previous frame was not ended (call end_frame)");
  if (!std::isfinite(time_s)) throw std::invalid_argument("FrameWriter::begin_frame: time is not finite");
  if (m.last_time && !(time_s > *m.last_time)) {
    throw std::invalid_argument("FrameWriter::begin_frame: time " + xdmf::format_number(time_s) +
                                " s is not after the previous frame's " + xdmf::format_number(*m.last_time) + " s");
  }
  m.frame.emplace();
  m.frame->time_s = time_s;
  m.frame->step = step;
}

void FrameWriter::points(const std::string& set, const std::vector<Vec2>& positions) {
  Impl& m = live(impl_);
  if (!m.frame) throw std::logic_error("FrameWriter::points: no frame begun (call begin_frame)");
  check_name("set", set);
  for (const PendingSet& s : m.frame->sets) {
    if (s.name == set) throw std::logic_error("FrameWriter::points: set '" + set + "' already given in this frame");
  }
  PendingSet s;
  s.name = set;
  s.positions.reserve(2 * positions.size());
  for (const Vec2& p : positions) {
    s.positions.push_back(p.x());
    s.positions.push_back(p.y());
  }
  m.frame->sets.push_back(std::move(s));
}

void FrameWriter::scalar(const std::string& set, const std::string& name, const std::vector<double>& values) {
  Impl& m = live(impl_);
  PendingSet& s = m.attribute_target("scalar", set, name, values.size());
  m.add(s, PendingArray{name, xdmf::Kind::scalar, values, {}}, {name});
}

void FrameWriter::integer(const std::string& set, const std::string& name, const std::vector<std::int32_t>& values) {
  Impl& m = live(impl_);
  PendingSet& s = m.attribute_target("integer", set, name, values.size());
  m.add(s, PendingArray{name, xdmf::Kind::integer, {}, values}, {name});
}

void FrameWriter::vector(const std::string& set, const std::string& name, const std::vector<Vec2>& values) {
  Impl& m = live(impl_);
  PendingSet& s = m.attribute_target("vector", set, name, values.size());
  PendingArray a{name, xdmf::Kind::vector, {}, {}};
  a.reals.reserve(3 * values.size());
  for (const Vec2& v : values) a.reals.insert(a.reals.end(), {v.x(), v.y(), 0.0});
  m.add(s, std::move(a), {name});
}

void FrameWriter::tensor(const std::string& set, const std::string& name,
                         const std::vector<Eigen::Vector4d>& xx_yy_xy_zz) {
  Impl& m = live(impl_);
  PendingSet& s = m.attribute_target("tensor", set, name, xx_yy_xy_zz.size());
  PendingArray a{name, xdmf::Kind::tensor, {}, {}};
  a.reals.reserve(4 * xx_yy_xy_zz.size());
  for (const Eigen::Vector4d& t : xx_yy_xy_zz) a.reals.insert(a.reals.end(), {t[0], t[1], t[2], t[3]});
  std::vector<std::string> shown;
  for (const char* c : xdmf::tensor_components) shown.push_back(name + "_" + c);
  m.add(s, std::move(a), std::move(shown));
}

void FrameWriter::end_frame() {
  Impl& m = live(impl_);
  if (!m.frame) throw std::logic_error("FrameWriter::end_frame: no frame begun (call begin_frame)");
  // The frame leaves the writer whatever happens below; a frame that fails to write still uses up its group
  // number so that the next frame does not collide with a half-written group.
  const PendingFrame frame = std::move(*m.frame);
  m.frame.reset();
  const std::size_t index = m.next_index++;

  m.write_frame(index, frame);
  m.file.set_attribute("/frames", "frame_count", static_cast<std::uint64_t>(m.written + 1));
  m.file.flush();
  m.written += 1;
  m.last_time = frame.time_s;

  // Only after the data is on disk does the XDMF refer to it.
  for (const PendingSet& set : frame.sets) {
    if (set.count() == 0) continue;  // empty sets are left out of the XDMF (see frame_writer.hpp)
    xdmf::Set record{set.name, set.count(), {}};
    for (const PendingArray& a : set.arrays) record.arrays.push_back({a.name, a.kind});
    auto it = std::find_if(m.collections.begin(), m.collections.end(),
                           [&](const xdmf::Collection& c) { return c.set == set.name; });
    if (it == m.collections.end()) it = m.collections.insert(m.collections.end(), xdmf::Collection{set.name, {}});
    it->grids.push_back(xdmf::uniform_grid(m.h5_name, index, frame.time_s, record));
  }
  m.write_xdmf();
}

void FrameWriter::attribute(const std::string& key, const std::string& value) {
  Impl& m = live(impl_);
  check_name("attribute key", key);
  m.file.set_attribute("/", key, value);
  m.file.flush();
  auto it = std::find_if(m.information.begin(), m.information.end(), [&](const auto& kv) { return kv.first == key; });
  if (it == m.information.end()) {
    m.information.emplace_back(key, value);
  } else {
    it->second = value;
  }
  m.write_xdmf();
}

const std::string& FrameWriter::h5_path() const { return live(impl_).h5_path; }
const std::string& FrameWriter::xdmf_path() const { return live(impl_).xdmf_path; }
std::size_t FrameWriter::frames_written() const { return live(impl_).written; }
bool FrameWriter::in_frame() const { return live(impl_).frame.has_value(); }

}  // namespace hfmpm::output
