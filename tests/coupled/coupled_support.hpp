// Shared pieces of the coupled and failure tests: the stand-in scene, running
// `hfmpm run`, comparing histories.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "test_support.hpp"

namespace hfmpm::test {

// scenarios/prescribed.scene shortened to 0.2 s (4000 steps of 5e-5 s).
inline std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("scene text has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

inline std::string prescribed_scene(double end_s = 0.2, double interval_s = 0.01) {
  std::string text = read_file(source("scenarios/prescribed.scene"));
  text = replace_once(text, "end_s: 1.0", "end_s: " + std::to_string(end_s));
  return replace_once(text, "interval_s: 0.05", "interval_s: " + std::to_string(interval_s));
}

// The keys of scenarios/kgd-viscosity-ci.scene's 5-s run whose derived value
// depends on time.end_s, as `hfmpm validate` lists them for that run. A run
// cut short derives its own for its shorter injection (docs/scenes.md, "The
// derived method"): at 0.4 s a density scaling of 1.6 and 2.5 times the
// 5-s run's steps, at 0.2 s 1.1 and 3 times. The tests that cut the scene
// short (restart, transport) set these, and so run the start of the 5-s run
// at its step; coupled.MemoryTransport.ShortKgdRunsSetThe5sRunsDerivedMethod
// checks that they are what the 5-s run derives.
inline const std::vector<std::string> kKgdViscosityCiMethod{
    "solid.mpm.density_scaling=8.3", "solid.mpm.damping.grid_alpha_per_s=10", "fluid.mpm.virtual_opening_m=1.4e-05"};

// `argv` with kKgdViscosityCiMethod appended as `--set KEY=VALUE` arguments.
inline std::vector<std::string> with_kgd_viscosity_ci_method(std::vector<std::string> argv) {
  for (const auto& assignment : kKgdViscosityCiMethod) argv.insert(argv.end(), {"--set", assignment});
  return argv;
}

inline RunResult run_scene(const std::string& scene_text, const std::string& out, const std::vector<std::string>& extra,
                           double timeout_s = 120) {
  const std::string scene = out + "/scene.scene";
  write_file(scene, scene_text);
  std::vector<std::string> argv{bin("hfmpm"), "run", scene, "--out", out, "--quiet"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return run(argv, timeout_s);
}

// Same rows and values in every column but the wall clock.
inline void expect_same_history(const Csv& a, const Csv& b) {
  ASSERT_EQ(a.header, b.header);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  const std::size_t wall = a.column("wall_s");
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    for (std::size_t c = 0; c < a.header.size(); ++c) {
      if (c != wall) {
        EXPECT_EQ(a.rows[i][c], b.rows[i][c]) << a.header[c] << " row " << i;
      }
    }
  }
}

// `hfmpm keygen DIR/keys`: the coupler's and the sides' CURVE key files.
struct KeyFiles {
  std::string coupler, side;
};
inline KeyFiles make_keys(const std::string& dir) {
  const auto result = run({bin("hfmpm"), "keygen", dir + "/keys"}, 20);
  if (result.exit_code != 0) throw std::runtime_error("hfmpm keygen failed: " + result.err);
  return {dir + "/keys/coupler.keys", dir + "/keys/side.keys"};
}

// Polls a run.json until the coupler has written its bound control endpoint.
inline std::string wait_for_endpoint(const std::string& manifest, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    const std::string endpoint = json_string(read_file(manifest), "control_endpoint");
    if (!endpoint.empty()) return endpoint;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return "";
}

}  // namespace hfmpm::test
