// Unit tests of scene files (coupler/include/hfmpm/coupling/scene_loader.hpp):
// parse_scene, load_scene, apply_override and validate.
// Checks: tests/data/minimal.scene and every scenarios/*.scene load; each file in
// tests/data/bad_scenes/ (minimal.scene with exactly one thing wrong) is refused
// with a SceneError whose text names the file, the line where the offending key
// is written (counted by hand in each file; none for a missing key), the key
// path, the bad value and what is allowed; --set overrides of scalars, enums,
// strings, repeated fields and messages take effect, and bad ones are refused
// with the key named ("--set KEY" instead of a file line).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "hfmpm/coupling/scene_loader.hpp"
#include "scene_test_support.hpp"
#include "test_support.hpp"

namespace {

using hfmpm::coupling::SceneError;
using hfmpm::test::data_path;
using hfmpm::test::minimal_text;
using hfmpm::test::scene_error;
using hfmpm::test::side_rules;
using hfmpm::test::with_overrides;
using ::testing::HasSubstr;
using ::testing::Not;
namespace scene = hfmpm::scene;

// ------------------------------------------------------------ valid scenes
TEST(SceneLoad, MinimalSceneLoadsWithSchemaDefaults) {
  const auto s = hfmpm::coupling::load_scene(data_path("minimal.scene"), side_rules());
  EXPECT_EQ(s.name(), "minimal");
  EXPECT_EQ(s.time().end_s(), 1.0);
  EXPECT_EQ(s.coupling().transport(), scene::Coupling::IPC);
  EXPECT_EQ(s.coupling().scheme(), scene::Coupling::JACOBI);  // default
  EXPECT_EQ(s.solid().prescribed_crack().spacing_m(), 0.01);
  EXPECT_EQ(s.solid().prescribed_crack().profile(), scene::PrescribedCrack::ELLIPTIC);  // default
  EXPECT_EQ(s.fluid().prescribed_pressure().front_fraction(), 0.9);
  EXPECT_TRUE(hfmpm::coupling::validate(s, side_rules()).empty());
  EXPECT_DOUBLE_EQ(hfmpm::coupling::output_interval(s), 0.01);  // interval_s 0: end_s / 100
}

TEST(SceneLoad, EveryShippedScenarioLoads) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(hfmpm::test::source("scenarios"))) {
    if (entry.path().extension() != ".scene") continue;
    ++count;
    EXPECT_NO_THROW({
      const auto s = hfmpm::coupling::load_scene(entry.path().string(), side_rules());
      EXPECT_NE(s.solid().model_case(), hfmpm::scene::Solid::MODEL_NOT_SET) << entry.path();
    }) << entry.path();
  }
  EXPECT_GE(count, 1);
}

TEST(SceneLoad, MissingFileNamesThePath) {
  const std::string path = data_path("no_such_file.scene");
  const auto e = scene_error([&] { hfmpm::coupling::load_scene(path, side_rules()); });
  EXPECT_THAT(e.what(), HasSubstr(path));
  EXPECT_THAT(e.what(), HasSubstr("cannot read"));
}

TEST(SceneLoad, DryRunWithoutFluidIsValid) {
  std::string text = minimal_text();
  text = text.substr(0, text.find("fluid {"));
  const auto s = hfmpm::coupling::parse_scene(text, "dry.scene", side_rules());
  EXPECT_FALSE(s.has_fluid());
}

// ------------------------------------------------------------ bad scenes

struct BadScene {
  const char* file;  // in tests/data/bad_scenes/
  // Line the message names: where the offending key is written or, for a missing
  // key, where its innermost enclosing block is written; 0: no line at all.
  int line;
  const char* key;                   // key path as the message writes it (nullptr: a syntax error names none)
  const char* value;                 // the bad value as written in the message ("is missing" if absent)
  std::vector<const char*> allowed;  // words of the allowed range (or of the parser's complaint)
};

void PrintTo(const BadScene& b, std::ostream* os) { *os << b.file; }

// clang-format off
const std::vector<BadScene> kBadScenes = {
    // Text-format errors.
    {"syntax_error", 5, nullptr, "found \"0.5\"", {"Expected \":\""}},
    {"unknown_key", 9, "exchange_intervall", "Coupling",
     {"allowed:", "transport", "exchange_interval", "heartbeat_timeout_s", "fluid_args"}},
    {"unknown_nested_key", 15, "initial_length", "PrescribedCrack",
     {"allowed:", "initial_length_m", "spacing_m", "stable_dt_s"}},
    {"unknown_enum_value", 8, "transport", "UDP", {}},
    {"wrong_value_type", 4, nullptr, "\"soon\"", {"Expected double"}},
    // Validation errors.
    {"missing_end_s", 3, "time.end_s", "is missing", {"> 0"}},
    {"negative_end_s", 4, "time.end_s", "= -1 ", {"> 0", "(s)"}},
    {"infinite_end_s", 4, "time.end_s", "= inf ", {"finite", "> 0"}},
    {"nan_safety_factor", 5, "time.safety_factor", "= nan ", {"finite", "> 0 and <= 1"}},
    {"safety_factor_above_one", 5, "time.safety_factor", "= 1.5 ", {"> 0 and <= 1"}},
    {"transport_unspecified", 8, "coupling.transport", "= TRANSPORT_UNSPECIFIED ", {"IPC, TCP or INPROC"}},
    {"exchange_interval_zero", 9, "coupling.exchange_interval", "= 0 ", {"from 1 to 10000"}},
    {"heartbeat_timeout_too_short", 11, "coupling.heartbeat_timeout_s", "= 1 ",
     {"> 1 ", "more than twice coupling.heartbeat_interval_s"}},
    {"missing_solid", 0, "solid", "is missing", {"prescribed_crack"}},
    {"missing_spacing", 14, "solid.prescribed_crack.spacing_m", "is missing", {"spacing", "> 0"}},
    {"spacing_above_initial_length", 18, "solid.prescribed_crack.spacing_m", "= 0.5 ",
     {"> 0 and <= 0.1", "at most initial_length_m"}},
    {"negative_growth_speed", 16, "solid.prescribed_crack.growth_speed_m_per_s", "= -0.5 ", {">= 0", "m/s"}},
    {"growth_without_max_length", 14, "solid.prescribed_crack.max_length_m", "is missing",
     {">= initial_length_m", "growth_speed_m_per_s > 0"}},
    {"max_length_below_initial", 17, "solid.prescribed_crack.max_length_m", "= 0.05 ",
     {">= 0.1", "initial_length_m"}},
    {"missing_solid_stable_dt", 14, "solid.prescribed_crack.stable_dt_s", "is missing", {"> 0"}},
    {"negative_mouth_opening", 19, "solid.prescribed_crack.mouth_opening_m.constant", "= -0.001 ", {">= 0", "(m)"}},
    {"ramp_missing_t1", 19, "solid.prescribed_crack.mouth_opening_m.ramp.t1", "is missing", {"> t0"}},
    {"table_not_increasing", 23, "solid.prescribed_crack.mouth_opening_m.table.t[2]", "= 0.5 ",
     {"strictly increasing", "> 0.5"}},
    {"table_length_mismatch", 19, "solid.prescribed_crack.mouth_opening_m.table", "= 3 times, 2 values ",
     {"as many values 'v' as times 't'"}},
    {"fluid_without_model", 23, "fluid", "is missing", {"prescribed_pressure", "no fluid block"}},
    {"front_fraction_zero", 26, "fluid.prescribed_pressure.front_fraction", "= 0 ", {"> 0 and <= 1"}},
    {"front_fraction_above_one", 26, "fluid.prescribed_pressure.front_fraction", "= 1.5 ", {"> 0 and <= 1"}},
    {"missing_fluid_stable_dt", 24, "fluid.prescribed_pressure.stable_dt_s", "is missing", {"> 0"}},
    {"bad_name", 2, "name", "= \"my scene\" ", {"letters, digits", "'_', '.', '-'"}},
};
// clang-format on

class BadSceneFile : public ::testing::TestWithParam<BadScene> {};

TEST_P(BadSceneFile, IsRefusedWithFileLineKeyValueAndAllowedRange) {
  const BadScene& b = GetParam();
  const std::string path = data_path(std::string("bad_scenes/") + b.file + ".scene");
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  const auto e = scene_error([&] { hfmpm::coupling::load_scene(path, side_rules()); });
  const std::string text = e.what();
  ASSERT_FALSE(e.problems().empty());
  if (b.line > 0) {
    EXPECT_THAT(text, HasSubstr(path + ":" + std::to_string(b.line) + ":"));
  } else {
    EXPECT_THAT(text, HasSubstr(path + ": "));
  }
  if (b.key != nullptr) {
    EXPECT_THAT(text, HasSubstr(b.key));
  }
  EXPECT_THAT(text, HasSubstr(b.value));
  for (const char* word : b.allowed) EXPECT_THAT(text, HasSubstr(word));
}

TEST_P(BadSceneFile, ReportsExactlyOneProblem) {
  // Each file breaks one rule; a second message would be about a value the user did not get wrong.
  const BadScene& b = GetParam();
  const auto e = scene_error(
      [&] { hfmpm::coupling::load_scene(data_path(std::string("bad_scenes/") + b.file + ".scene"), side_rules()); });
  EXPECT_EQ(e.problems().size(), 1u) << e.what();
}

std::string bad_scene_name(const ::testing::TestParamInfo<BadScene>& param_info) { return param_info.param.file; }
INSTANTIATE_TEST_SUITE_P(Table, BadSceneFile, ::testing::ValuesIn(kBadScenes), bad_scene_name);

// The expectation a bad scene file states in its first line, "# expect: TEXT"
// (TEXT: a substring of the error); empty if it has none (then it is in kBadScenes).
std::string expectation(const std::string& path) {
  const std::string text = hfmpm::test::read_file(path);
  const std::string prefix = "# expect: ";
  if (text.rfind(prefix, 0) != 0) return {};
  std::string line = text.substr(prefix.size(), text.find('\n') - prefix.size());
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line;
}

TEST(BadScenes, EveryFileInTheDirectoryIsInTheTable) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data_path("bad_scenes"))) {
    if (!expectation(entry.path().string()).empty()) continue;  // BadScenes.EveryExpectationFileIsRefused
    ++count;
    const std::string stem = entry.path().stem().string();
    EXPECT_TRUE(std::any_of(kBadScenes.begin(), kBadScenes.end(), [&](const BadScene& b) { return stem == b.file; }))
        << entry.path() << " has no row in kBadScenes";
  }
  EXPECT_EQ(count, static_cast<int>(kBadScenes.size()));
  EXPECT_GE(count, 15);
}

// Each file in bad_scenes/ whose first line is "# expect: TEXT" is loaded and
// validated through the library (no process) and must be refused with exactly
// one problem whose text contains TEXT. They cover the hardening of the scene
// input: non-finite numbers anywhere (found by reflection), crack geometry
// (zero length, self-crossing, outside the grid or body, a mouth inside the
// body, two cracks within a cell), regions outside the grid, the memory
// estimate (grid_too_big_for_memory: 1e8 cells with 16 particles each, about
// 330 GB, beyond any machine this runs on), the step count (too many steps;
// a single step past end_s, refused when every side's step is known), names.
TEST(BadScenes, EveryExpectationFileIsRefused) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data_path("bad_scenes"))) {
    const std::string path = entry.path().string();
    const std::string expected = expectation(path);
    if (expected.empty()) continue;
    ++count;
    SCOPED_TRACE(path);
    const auto e = scene_error([&] { hfmpm::coupling::load_scene(path, side_rules()); });
    EXPECT_THAT(e.what(), HasSubstr(expected));
    EXPECT_EQ(e.problems().size(), 1u) << e.what();
    EXPECT_THAT(e.what(), HasSubstr(path + ":")) << "names the file";
  }
  EXPECT_GE(count, 50);
}

TEST(Validate, ReportsEveryProblemNotOnlyTheFirst) {
  scene::Scene s;
  s.mutable_time()->set_end_s(-1);
  s.mutable_coupling()->set_exchange_interval(0);
  const auto problems = hfmpm::coupling::validate(s, side_rules());
  std::vector<std::string> keys;
  for (const auto& p : problems) keys.push_back(p.key);
  EXPECT_THAT(keys, ::testing::IsSupersetOf({"time.end_s", "coupling.exchange_interval", "solid"}));
  for (const auto& p : problems) EXPECT_FALSE(p.allowed.empty()) << p.key;
}

// ------------------------------------------------------------ overrides

TEST(Override, NestedScalar) {
  EXPECT_EQ(with_overrides({"time.end_s=2"}).time().end_s(), 2.0);
  EXPECT_EQ(with_overrides({"solid.prescribed_crack.spacing_m=0.02"}).solid().prescribed_crack().spacing_m(), 0.02);
}

TEST(Override, LaterOverrideWins) { EXPECT_EQ(with_overrides({"time.end_s=2", "time.end_s=3"}).time().end_s(), 3.0); }

TEST(Override, CreatesAnAbsentBlock) {
  const auto s = with_overrides({"output.exchange_log=true"});
  EXPECT_TRUE(s.has_output());
  EXPECT_TRUE(s.output().exchange_log());
}

TEST(Override, Enum) {
  EXPECT_EQ(with_overrides({"coupling.transport=TCP"}).coupling().transport(), scene::Coupling::TCP);
  EXPECT_EQ(with_overrides({"coupling.scheme=GAUSS_SEIDEL"}).coupling().scheme(), scene::Coupling::GAUSS_SEIDEL);
}

TEST(Override, UnquotedAndQuotedString) {
  EXPECT_EQ(with_overrides({"name=abc"}).name(), "abc");
  EXPECT_EQ(with_overrides({"name=\"abc\""}).name(), "abc");
  EXPECT_EQ(with_overrides({"coupling.tcp_host=0.0.0.0"}).coupling().tcp_host(), "0.0.0.0");
}

TEST(Override, RepeatedFieldIsReplaced) {
  scene::Scene s = with_overrides({});
  s.mutable_coupling()->add_solid_args("--old");
  hfmpm::coupling::apply_override(s, "coupling.solid_args=[\"--a\", \"--b\"]");
  EXPECT_THAT(s.coupling().solid_args(), ::testing::ElementsAre("--a", "--b"));
  // A single unbracketed value replaces too, and may itself contain '='.
  hfmpm::coupling::apply_override(s, "coupling.solid_args=--threads=4");
  EXPECT_THAT(s.coupling().solid_args(), ::testing::ElementsAre("--threads=4"));
  EXPECT_TRUE(s.coupling().fluid_args().empty());
}

TEST(Override, MessageIsReplacedNotMerged) {
  scene::Scene s = with_overrides({});
  auto* ramp = s.mutable_solid()->mutable_prescribed_crack()->mutable_mouth_opening_m()->mutable_ramp();
  ramp->set_t1(1);
  ramp->set_v1(1e-3);
  hfmpm::coupling::apply_override(s, "solid.prescribed_crack.mouth_opening_m={constant: 0.002}");
  const auto& f = s.solid().prescribed_crack().mouth_opening_m();
  EXPECT_EQ(f.kind_case(), scene::TimeFunction::kConstant);
  EXPECT_EQ(f.constant(), 0.002);
  EXPECT_TRUE(hfmpm::coupling::validate(s, side_rules()).empty());
}

TEST(Override, UnknownKeyListsTheAllowedKeys) {
  const auto e = scene_error([] { with_overrides({"time.end=2"}); });
  EXPECT_THAT(e.what(), HasSubstr("--set time.end"));
  EXPECT_THAT(e.what(), HasSubstr("'end'"));
  EXPECT_THAT(e.what(), HasSubstr("allowed: end_s, safety_factor, max_steps"));
  const auto top = scene_error([] { with_overrides({"tiem.end_s=2"}); });
  EXPECT_THAT(top.what(), HasSubstr("'tiem'"));
  EXPECT_THAT(top.what(), HasSubstr("allowed: name, description, time, output, coupling, solid, fluid"));
}

TEST(Override, ValueOfTheWrongTypeNamesTheKey) {
  for (const char* assignment :
       {"time.end_s=abc", "coupling.exchange_interval=-3", "coupling.transport=UDP", "output.hdf5=perhaps",
        "solid.prescribed_crack.mouth_opening_m={constant: x}", "solid.prescribed_crack.mouth_opening_m="}) {
    const std::string key = std::string(assignment).substr(0, std::string(assignment).find('='));
    const auto e = scene_error([&] { with_overrides({assignment}); });
    EXPECT_THAT(e.what(), HasSubstr("--set " + key)) << assignment;
  }
}

TEST(Override, MalformedAssignmentIsRefused) {
  for (const char* assignment : {"time.end_s", "=2"}) {
    const auto e = scene_error([&] { with_overrides({assignment}); });
    EXPECT_THAT(e.what(), HasSubstr("KEY=VALUE")) << assignment;
  }
}

TEST(Override, PathThroughAScalarIsRefused) {
  const auto e = scene_error([] { with_overrides({"time.end_s.x=2"}); });
  EXPECT_THAT(e.what(), HasSubstr("--set time.end_s.x"));
  EXPECT_THAT(e.what(), HasSubstr("'time.end_s' holds a value"));
}

TEST(Override, InvalidResultNamesTheOverrideNotTheFileLine) {
  // minimal.scene writes safety_factor on line 5; the override, not that line, is to blame.
  const auto e = scene_error([] { with_overrides({"time.safety_factor=2"}); });
  EXPECT_THAT(e.what(), HasSubstr("--set time.safety_factor: time.safety_factor = 2 is not allowed"));
  EXPECT_THAT(e.what(), Not(HasSubstr("minimal.scene:5")));
  EXPECT_EQ(e.problems().size(), 1u) << e.what();
}

TEST(Override, InvalidValueInsideAnOverriddenMessageNamesTheOverride) {
  const auto e = scene_error([] { with_overrides({"solid.prescribed_crack.mouth_opening_m={constant: -1}"}); });
  EXPECT_THAT(e.what(), HasSubstr("--set solid.prescribed_crack.mouth_opening_m: "
                                  "solid.prescribed_crack.mouth_opening_m.constant = -1"));
  EXPECT_THAT(e.what(), Not(HasSubstr("minimal.scene:19")));
}

TEST(Override, ProblemsElsewhereStillNameTheFileLine) {
  // Override one key; a different bad key written in the file keeps its file:line.
  std::string text = minimal_text();
  text.replace(text.find("front_fraction: 0.9"), 19, "front_fraction: 2.0");
  const auto e =
      scene_error([&] { hfmpm::coupling::parse_scene(text, "edited.scene", side_rules(), {"time.end_s=2"}); });
  EXPECT_THAT(e.what(), HasSubstr("edited.scene:26: fluid.prescribed_pressure.front_fraction = 2"));
  EXPECT_THAT(e.what(), Not(HasSubstr("--set")));
}

TEST(Override, CanRepairAnInvalidFile) {
  const std::string text = hfmpm::test::read_file(data_path("bad_scenes/front_fraction_zero.scene"));
  const auto s =
      hfmpm::coupling::parse_scene(text, "x.scene", side_rules(), {"fluid.prescribed_pressure.front_fraction=0.5"});
  EXPECT_EQ(s.fluid().prescribed_pressure().front_fraction(), 0.5);
}

}  // namespace
