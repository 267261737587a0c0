// What the restart tests share (restart_test.cpp: continued runs;
// restart_checkpoint_test.cpp: damaged, refused and stopped checkpoints): the
// shortened kgd-viscosity-ci run, its checkpoints and its history.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "coupled_support.hpp"
#include "h5_reader.hpp"

namespace hfmpm::test {

// kgd-viscosity-ci to 0.4 s at the 5-s run's step (kKgdViscosityCiMethod):
// frames every 0.05 s, checkpoints at 0.15 and 0.3 s (about 760 coupled steps of
// the MPM solid and fluid), the data crossing the data plane logged with 17
// digits.
inline const std::vector<std::string> kSets =
    with_kgd_viscosity_ci_method({"--set", "time.end_s=0.4", "--set", "output.interval_s=0.05", "--set",
                                  "output.checkpoint_interval_s=0.15", "--set", "output.exchange_log=true"});

inline std::vector<std::string> run_args(const std::string& out) {
  std::vector<std::string> argv{bin("hfmpm"), "run", source("scenarios/kgd-viscosity-ci.scene"),
                                "--out",      out,   "--quiet"};
  argv.insert(argv.end(), kSets.begin(), kSets.end());
  return argv;
}

// Steps of the complete checkpoints (those with the coupler's file).
inline std::vector<std::uint64_t> complete_checkpoints(const std::string& out) {
  std::vector<std::uint64_t> steps;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(out + "/checkpoints", error)) {
    if (std::filesystem::exists(entry.path() / "coupler.pb"))
      steps.push_back(std::stoull(entry.path().filename().string().substr(5)));
  }
  std::sort(steps.begin(), steps.end());
  return steps;
}

// The uninterrupted run of the tests that restart from a chosen checkpoint:
// 0.2 s with a checkpoint every `interval` s (two kept); the steps of its
// complete checkpoints (none if the run failed).
inline std::vector<std::uint64_t> run_with_two_checkpoints(const std::string& out,
                                                           const std::string& interval = "0.06") {
  auto argv = run_args(out);
  argv[std::find(argv.begin(), argv.end(), "time.end_s=0.4") - argv.begin()] = "time.end_s=0.2";
  argv[std::find(argv.begin(), argv.end(), "output.checkpoint_interval_s=0.15") - argv.begin()] =
      "output.checkpoint_interval_s=" + interval;
  const auto whole = run(argv, 120);
  EXPECT_EQ(whole.exit_code, 0) << whole.err;
  return whole.exit_code == 0 ? complete_checkpoints(out) : std::vector<std::uint64_t>{};
}

// A checkpoint's directory: DIR/checkpoints/step-<12 digits>.
inline std::string step_directory(const std::string& out, std::uint64_t step) {
  std::ostringstream s;
  s << out << "/checkpoints/step-" << std::setw(12) << std::setfill('0') << step;
  return s.str();
}

// The steps of a history's rows, in order.
inline std::vector<double> history_steps(const std::string& out) {
  return read_csv(out + "/history.csv").values("step");
}

// Every frame of two frame files: the same groups, attributes and datasets, bit for bit.
inline void expect_same_frames(const std::string& a_path, const std::string& b_path, std::size_t& datasets) {
  const H5Reader a(a_path), b(b_path);
  ASSERT_EQ(a.children("/frames"), b.children("/frames")) << b_path;
  EXPECT_EQ(a.attribute_u64("/frames", "frame_count"), b.attribute_u64("/frames", "frame_count"));
  for (const auto& frame : a.children("/frames")) {
    const std::string group = "/frames/" + frame;
    const double ta = a.attribute_f64(group, "time_s"), tb = b.attribute_f64(group, "time_s");
    EXPECT_EQ(std::bit_cast<std::uint64_t>(ta), std::bit_cast<std::uint64_t>(tb)) << group;  // bit for bit
    EXPECT_EQ(a.attribute_u64(group, "step"), b.attribute_u64(group, "step")) << group;
    ASSERT_EQ(a.children(group), b.children(group)) << group;
    for (const auto& set : a.children(group)) {
      ASSERT_EQ(a.children(group + "/" + set), b.children(group + "/" + set));
      for (const auto& name : a.children(group + "/" + set)) {
        const std::string d = group + "/" + set + "/" + name;
        ++datasets;
        if (a.is_f64(d)) {
          const auto x = a.f64(d), y = b.f64(d);
          ASSERT_EQ(x.size(), y.size()) << d;
          EXPECT_EQ(std::memcmp(x.data(), y.data(), x.size() * sizeof(double)), 0) << b_path << " " << d;
        } else {
          EXPECT_EQ(a.i32(d), b.i32(d)) << b_path << " " << d;
        }
      }
    }
  }
  EXPECT_EQ(read_file(std::filesystem::path(a_path).replace_extension(".xmf").string()),
            read_file(std::filesystem::path(b_path).replace_extension(".xmf").string()));
}

}  // namespace hfmpm::test
