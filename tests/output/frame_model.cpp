// Test helper: sample frames and the exact read-back check (see frame_model.hpp).
#include "frame_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "h5_reader.hpp"
#include "test_support.hpp"
#include "xdmf_check.hpp"

namespace hfmpm::test {
namespace {

std::string frame_group(std::size_t f) {
  char text[32];
  std::snprintf(text, sizeof text, "/frames/%06zu", f);
  return text;
}

SetData particles(int frame, int n) {
  SetData s{"particles", {}, {}, {}, {}, {}};
  auto& mass = s.scalars["mass"];
  auto& id = s.integers["id"];
  auto& velocity = s.vectors["velocity"];
  auto& stress = s.tensors["stress"];
  for (int i = 0; i < n; ++i) {
    s.positions.emplace_back(0.1 * i + frame / 3.0, -std::sqrt(i + 1.0) * 1e-3);
    mass.push_back(1.0 / (i + 7) + frame);
    id.push_back(i * 1000 - 5 + frame);
    velocity.emplace_back(std::sin(i + frame), std::cos(i * 0.7) * 1e-9);
    stress.emplace_back(1e6 * i + 0.25, -2e6 / 3.0, 3.3e5 * frame, std::acos(-1.0) * (i - 2));
  }
  return s;
}

SetData crack(int frame, int n) {
  SetData s{"crack", {}, {}, {}, {}, {}};
  auto& width = s.scalars["width"];
  auto& tip = s.integers["tip"];
  for (int i = 0; i < n; ++i) {
    s.positions.emplace_back(1.0 + i * 0.01, 1e-300 * i);
    width.push_back(std::exp(-i) * 1e-4 + frame * 1e-7);
    tip.push_back(i == n - 1 ? 1 : 0);
  }
  return s;
}

std::vector<double> flat(const std::vector<Vec2>& v, bool with_zero) {
  std::vector<double> out;
  for (const Vec2& p : v) {
    out.push_back(p.x());
    out.push_back(p.y());
    if (with_zero) out.push_back(0.0);
  }
  return out;
}

void verify_h5(const std::string& h5_path, const std::vector<FrameData>& frames,
               const std::map<std::string, std::string>& root) {
  H5Reader h5(h5_path);
  for (const auto& [key, value] : root) EXPECT_EQ(h5.attribute_string("/", key), value) << key;
  EXPECT_EQ(h5.attribute_u64("/frames", "frame_count"), frames.size());
  std::vector<std::string> groups;
  for (std::size_t f = 0; f < frames.size(); ++f) groups.push_back(frame_group(f).substr(8));
  EXPECT_EQ(h5.children("/frames"), groups);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const FrameData& frame = frames[f];
    const std::string g = frame_group(f);
    EXPECT_EQ(h5.attribute_f64(g, "time_s"), frame.time_s) << g;
    EXPECT_EQ(h5.attribute_u64(g, "step"), frame.step) << g;
    std::vector<std::string> set_names;
    for (const SetData& s : frame.sets) set_names.push_back(s.name);
    std::sort(set_names.begin(), set_names.end());
    EXPECT_EQ(h5.children(g), set_names) << g;
    for (const SetData& s : frame.sets) {
      const std::string sg = g + "/" + s.name;
      const std::uint64_t n = s.positions.size();
      std::vector<std::string> names{"positions"};
      EXPECT_EQ(h5.dims(sg + "/positions"), (std::vector<std::uint64_t>{n, 2}));
      EXPECT_EQ(h5.f64(sg + "/positions"), flat(s.positions, false)) << sg;
      for (const auto& [name, values] : s.scalars) {
        names.push_back(name);
        EXPECT_EQ(h5.dims(sg + "/" + name), (std::vector<std::uint64_t>{n}));
        EXPECT_EQ(h5.f64(sg + "/" + name), values) << sg << "/" << name;
      }
      for (const auto& [name, values] : s.integers) {
        names.push_back(name);
        EXPECT_EQ(h5.dims(sg + "/" + name), (std::vector<std::uint64_t>{n}));
        EXPECT_EQ(h5.i32(sg + "/" + name), values) << sg << "/" << name;
      }
      for (const auto& [name, values] : s.vectors) {
        names.push_back(name);
        EXPECT_EQ(h5.dims(sg + "/" + name), (std::vector<std::uint64_t>{n, 3}));
        EXPECT_EQ(h5.f64(sg + "/" + name), flat(values, true)) << sg << "/" << name;
      }
      for (const auto& [name, values] : s.tensors) {
        names.push_back(name);
        std::vector<double> expected;
        for (const auto& t : values) expected.insert(expected.end(), {t[0], t[1], t[2], t[3]});
        EXPECT_EQ(h5.dims(sg + "/" + name), (std::vector<std::uint64_t>{n, 4}));
        EXPECT_EQ(h5.f64(sg + "/" + name), expected) << sg << "/" << name;
        EXPECT_EQ(h5.attribute_string(sg + "/" + name, "components"), "xx yy xy zz");
      }
      std::sort(names.begin(), names.end());
      EXPECT_EQ(h5.children(sg), names) << sg;
    }
  }
}

void verify_xdmf(const std::string& h5_path, const std::string& xmf_path, const std::vector<FrameData>& frames,
                 const std::map<std::string, std::string>& root) {
  XdmfSummary x;
  try {
    x = check_xdmf(xmf_path, h5_path);
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what();
    return;
  }
  EXPECT_EQ(x.information, root);
  // Expected: one collection per set, in order of first non-empty appearance; empty sets left out.
  std::vector<std::string> sets;
  std::map<std::string, std::vector<XdmfGrid>> grids;
  std::vector<double> times;
  std::size_t items = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    for (const SetData& s : frames[f].sets) {
      if (s.positions.empty()) continue;
      if (times.empty() || times.back() != frames[f].time_s) times.push_back(frames[f].time_s);
      if (!grids.count(s.name)) sets.push_back(s.name);
      const std::string sg = frame_group(f) + "/" + s.name + "/";
      XdmfGrid g;
      g.time = frames[f].time_s;
      g.count = s.positions.size();
      g.positions = sg + "positions";
      items += 1;
      auto shown = [&](const std::string& name, const char* type, const std::string& source) {
        g.attributes[name] = type;
        g.sources[name] = source;
      };
      for (const auto& kv : s.scalars) shown(kv.first, "Scalar", sg + kv.first);
      for (const auto& kv : s.integers) shown(kv.first, "Scalar", sg + kv.first);
      for (const auto& kv : s.vectors) shown(kv.first, "Vector", sg + kv.first);
      items += s.scalars.size() + s.integers.size() + s.vectors.size();
      for (const auto& kv : s.tensors) {
        const char* components[] = {"xx", "yy", "xy", "zz"};
        for (int c = 0; c < 4; ++c) {
          shown(kv.first + "_" + components[c], "Scalar", sg + kv.first + "[" + std::to_string(c) + "]");
          items += 1;
        }
      }
      grids[s.name].push_back(g);
    }
  }
  EXPECT_EQ(x.sets, sets);
  EXPECT_EQ(x.hdf_items, items);
  EXPECT_EQ(x.times, times);  // the times of frames with at least one non-empty set
  for (const auto& [name, want] : grids) {
    ASSERT_EQ(x.grids[name].size(), want.size()) << name;
    for (std::size_t i = 0; i < want.size(); ++i) {
      const XdmfGrid& got = x.grids[name][i];
      EXPECT_EQ(got.time, want[i].time) << name << " grid " << i;  // exact: shortest round-trip text
      EXPECT_EQ(got.count, want[i].count) << name << " grid " << i;
      EXPECT_EQ(got.positions, want[i].positions) << name << " grid " << i;
      EXPECT_EQ(got.attributes, want[i].attributes) << name << " grid " << i;
      EXPECT_EQ(got.sources, want[i].sources) << name << " grid " << i;
    }
  }
}

}  // namespace

Scratch::Scratch(const std::string& name) : dir_(scratch_dir(name)) {}

Scratch::~Scratch() {
  if (!::testing::Test::HasFailure()) {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
}

std::vector<FrameData> sample_frames() {
  std::vector<FrameData> frames(3);
  const double times[3] = {0.0, 1e-3 / 3.0, 0.1 + 0.2};
  const int particle_counts[3] = {3, 4, 6};
  const int crack_counts[3] = {2, 0, 5};
  for (int f = 0; f < 3; ++f) {
    frames[f].time_s = times[f];
    frames[f].step = 150u * static_cast<unsigned>(f) + (f == 2 ? 0x1'0000'0000ull : 0);  // beyond 32 bits
    frames[f].sets = {particles(f, particle_counts[f]), crack(f, crack_counts[f])};
  }
  return frames;
}

void write_frame(output::FrameWriter& writer, const FrameData& frame) {
  writer.begin_frame(frame.time_s, frame.step);
  for (const SetData& s : frame.sets) {
    writer.points(s.name, s.positions);
    for (const auto& [name, values] : s.scalars) writer.scalar(s.name, name, values);
    for (const auto& [name, values] : s.integers) writer.integer(s.name, name, values);
    for (const auto& [name, values] : s.vectors) writer.vector(s.name, name, values);
    for (const auto& [name, values] : s.tensors) writer.tensor(s.name, name, values);
  }
  writer.end_frame();
}

void verify_files(const std::string& h5_path, const std::string& xmf_path, const std::vector<FrameData>& frames,
                  const std::map<std::string, std::string>& root) {
  try {
    verify_h5(h5_path, frames, root);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "reading " << h5_path << ": " << e.what();
  }
  bool any_points = false;
  for (const FrameData& f : frames) {
    for (const SetData& s : f.sets) any_points = any_points || !s.positions.empty();
  }
  if (any_points) {
    verify_xdmf(h5_path, xmf_path, frames, root);
  } else {
    EXPECT_FALSE(std::filesystem::exists(xmf_path)) << "no set has points yet, so there must be no " << xmf_path;
  }
}

}  // namespace hfmpm::test
