// Helpers shared by the scene unit tests (scene_test.cpp, scene_hardening_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "solid_scene_rules.hpp"
#include "test_support.hpp"

namespace hfmpm::test {

// Both sides' scene rules, as the hfmpm command hands them to the coupler.
inline const hfmpm::coupling::SceneRules& side_rules() {
  static const hfmpm::coupling::SceneRules rules{hfmpm::solid::scene_rules(), hfmpm::fluid::scene_rules()};
  return rules;
}

inline std::string data_path(const std::string& relative) { return hfmpm::test::source("tests/data/" + relative); }
inline std::string minimal_text() { return hfmpm::test::read_file(data_path("minimal.scene")); }

// Expects `f` to throw SceneError; returns it (problems() and what()).
template <class F>
hfmpm::coupling::SceneError scene_error(F&& f) {
  try {
    f();
  } catch (const hfmpm::coupling::SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "no SceneError";
  return hfmpm::coupling::SceneError(std::vector<std::string>{});
}

// The minimal scene with --set overrides applied, validated.
inline hfmpm::scene::Scene with_overrides(const std::vector<std::string>& overrides) {
  return hfmpm::coupling::parse_scene(minimal_text(), "minimal.scene", side_rules(), overrides);
}

}  // namespace hfmpm::test
