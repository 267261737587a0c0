// Unit tests of --set through repeated fields (issue 47, item 4;
// coupler/src/scene_loader.cpp, apply_override): an element selected by index
// (solid.mpm.cracks[1].x_m) or, where the elements have a `name`, by name
// (solid.mpm.materials[rock], materials["rock"]); a bracket on the last
// component replaces that one element (a message in braces, or one value of a
// repeated scalar). Refused with a SceneError that names the key and what is
// allowed: an index out of range (no element is added), an unknown or
// repeated name, brackets on a field that is not a list, a name where the
// elements have none, malformed brackets, a path past a value. A value that
// breaks a rule is reported as "--set KEY" with the key as written. Odd keys
// give a SceneError and nothing else.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "hfmpm/coupling/scene_loader.hpp"
#include "scene_test_support.hpp"

namespace {

using hfmpm::coupling::apply_override;
using hfmpm::coupling::SceneError;
using hfmpm::test::scene_error;
using hfmpm::test::side_rules;
using hfmpm::test::with_overrides;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
namespace scene = hfmpm::scene;

const std::string kTwoCracks =
    "  cracks { x_m: [0, 0.3] y_m: [0.05, 0.05] start_is_tip: false }\n"
    "  cracks { x_m: [0.35, 0.5, 0.7] y_m: [0.2, 0.25, 0.25] start_is_tip: true }\n";
const std::string kOneCrack = "  cracks { x_m: [0, 0.3] y_m: [0.05, 0.05] start_is_tip: false }\n";

// A valid dry MPM scene: two materials (rock, shale), two regions, three
// tractions (RIGHT, BOTTOM, TOP) and `cracks`.
std::string mpm_text(const std::string& cracks = kTwoCracks) {
  return "name: \"mpm\"\ntime { end_s: 0.001 }\nsolid { mpm {\n"
         "  grid { x_min_m: 0 y_min_m: -1.1 x_max_m: 1.2 y_max_m: 1.1 }\n"
         "  cell_size_m: 0.1\n"
         "  materials { name: \"rock\" youngs_modulus_pa: 1e10 poisson_ratio: 0.25 density_kg_m3: 2500 }\n"
         "  materials { name: \"shale\" youngs_modulus_pa: 5e9 poisson_ratio: 0.3 density_kg_m3: 2400 }\n"
         "  regions { material: \"rock\" rectangle { x_min_m: 0 y_min_m: -1 x_max_m: 1 y_max_m: 0 } }\n"
         "  regions { material: \"shale\" rectangle { x_min_m: 0 y_min_m: 0 x_max_m: 1 y_max_m: 1 } }\n"
         "  constraints { symmetry_x_m: 0 }\n"
         "  tractions { edge: RIGHT normal_pa { constant: -1e5 } }\n"
         "  tractions { edge: BOTTOM normal_pa { constant: -1e5 } }\n"
         "  tractions { edge: TOP normal_pa { constant: -1e5 } }\n" +
         cracks + "} }\n";
}

// The MPM scene with `overrides` applied, validated.
scene::Scene mpm(const std::vector<std::string>& overrides, const std::string& cracks = kTwoCracks) {
  return hfmpm::coupling::parse_scene(mpm_text(cracks), "mpm.scene", side_rules(), overrides);
}

// The one problem of the SceneError `overrides` give the MPM scene.
std::string refusal(const std::vector<std::string>& overrides, const std::string& cracks = kTwoCracks) {
  const auto e = scene_error([&] { mpm(overrides, cracks); });
  EXPECT_EQ(e.problems().size(), 1u) << e.what();
  return e.problems().empty() ? std::string() : e.problems().front();
}

TEST(OverrideElement, TheBaseSceneIsValid) { EXPECT_NO_THROW(mpm({})); }

// ------------------------------------------------------------ by index

TEST(OverrideElement, KeyInsideAnElementByIndex) {
  const auto s = mpm({"solid.mpm.cracks[1].x_m=[0.35, 0.5, 0.8]"});
  EXPECT_THAT(s.solid().mpm().cracks(1).x_m(), ElementsAre(0.35, 0.5, 0.8));
  EXPECT_THAT(s.solid().mpm().cracks(0).x_m(), ElementsAre(0, 0.3));  // the other crack as it was
  EXPECT_THAT(s.solid().mpm().cracks(1).y_m(), ElementsAre(0.2, 0.25, 0.25));
}

TEST(OverrideElement, CreatesAnAbsentBlockInsideAnElement) {
  const auto s = mpm({"solid.mpm.regions[0].initial_stress.xx_pa=-2e6"});
  ASSERT_TRUE(s.solid().mpm().regions(0).has_initial_stress());
  EXPECT_EQ(s.solid().mpm().regions(0).initial_stress().xx_pa(), -2e6);
  EXPECT_FALSE(s.solid().mpm().regions(1).has_initial_stress());
}

TEST(OverrideElement, BlockInsideAnElementIsReplaced) {
  const auto s = mpm({"solid.mpm.tractions[2].normal_pa={ramp {t1: 1 v1: -2e6}}",
                      "solid.mpm.tractions[2].normal_pa={constant: -1e6}"});
  const auto& f = s.solid().mpm().tractions(2).normal_pa();
  EXPECT_EQ(f.kind_case(), scene::TimeFunction::kConstant);
  EXPECT_EQ(f.constant(), -1e6);
  EXPECT_EQ(s.solid().mpm().tractions(2).edge(), scene::TOP);
  EXPECT_EQ(s.solid().mpm().tractions(1).normal_pa().constant(), -1e5);
}

TEST(OverrideElement, LeadingZerosAreTheSameIndex) {
  EXPECT_EQ(mpm({"solid.mpm.materials[001].poisson_ratio=0.2"}).solid().mpm().materials(1).poisson_ratio(), 0.2);
}

// ------------------------------------------------------------ by name

TEST(OverrideElement, KeyInsideAnElementByName) {
  const auto s = mpm({"solid.mpm.materials[shale].youngs_modulus_pa=2e10"});
  EXPECT_EQ(s.solid().mpm().materials(1).youngs_modulus_pa(), 2e10);
  EXPECT_EQ(s.solid().mpm().materials(0).youngs_modulus_pa(), 1e10);
  EXPECT_EQ(
      mpm({"solid.mpm.materials[\"rock\"].youngs_modulus_pa=3e10"}).solid().mpm().materials(0).youngs_modulus_pa(),
      3e10);
  EXPECT_EQ(mpm({"solid.mpm.materials['rock'].density_kg_m3=2600"}).solid().mpm().materials(0).density_kg_m3(), 2600);
}

TEST(OverrideElement, NamesThatNeedQuotes) {
  // A name that starts with a digit, or holds ']' or a quote, is written in quotes (\" and \\ escape).
  auto s = mpm({"solid.mpm.materials[shale].name=\"2b]\\\"\"", "solid.mpm.regions[1].material=\"2b]\\\"\""});
  ASSERT_EQ(s.solid().mpm().materials(1).name(), "2b]\"");
  apply_override(s, "solid.mpm.materials[\"2b]\\\"\"].poisson_ratio=0.1");
  EXPECT_EQ(s.solid().mpm().materials(1).poisson_ratio(), 0.1);
  const auto e = scene_error([&] { apply_override(s, "solid.mpm.materials[2b].poisson_ratio=0.1"); });
  EXPECT_EQ(e.problems().at(0),
            "--set solid.mpm.materials[2b].poisson_ratio: '2b' is not an index (a whole number from 0); a name that "
            "starts with a digit or a sign is written in quotes, materials[\"2b\"]; solid.mpm.materials has 2 "
            "elements; allowed: [0] to [1] or by name [rock], [\"2b]\\\"\"]");
}

TEST(OverrideElement, RenamedElementIsFoundByItsNewName) {
  const auto s = mpm({"solid.mpm.materials[shale].name=clay", "solid.mpm.regions[1].material=clay",
                      "solid.mpm.materials[clay].poisson_ratio=0.35"});
  EXPECT_EQ(s.solid().mpm().materials(1).name(), "clay");
  EXPECT_EQ(s.solid().mpm().materials(1).poisson_ratio(), 0.35);
}

// ------------------------------------------------------------ one element replaced

TEST(OverrideElement, MessageElementIsReplacedNotMerged) {
  const auto s = mpm({"solid.mpm.cracks[0].friction_coefficient=0.6",
                      "solid.mpm.cracks[0]={x_m: [0, 0.2] y_m: [0.05, 0.05] start_is_tip: false}"});
  const auto& c = s.solid().mpm().cracks(0);
  EXPECT_THAT(c.x_m(), ElementsAre(0, 0.2));
  EXPECT_FALSE(c.has_friction_coefficient());  // replaced, not merged
  ASSERT_EQ(s.solid().mpm().cracks_size(), 2);
  EXPECT_THAT(s.solid().mpm().cracks(1).x_m(), ElementsAre(0.35, 0.5, 0.7));
  // By name too, and the element's key path then continues from the new content.
  const auto m =
      mpm({"solid.mpm.materials[rock]={name: \"rock\" youngs_modulus_pa: 4e10 poisson_ratio: 0.2 "
           "density_kg_m3: 2700}"});
  EXPECT_EQ(m.solid().mpm().materials(0).youngs_modulus_pa(), 4e10);
  EXPECT_EQ(m.solid().mpm().materials(0).density_kg_m3(), 2700);
  EXPECT_EQ(m.solid().mpm().materials_size(), 2);
}

TEST(OverrideElement, OneValueOfARepeatedScalar) {
  const auto s = mpm({"solid.mpm.cracks[0].x_m[1]=0.25"});
  EXPECT_THAT(s.solid().mpm().cracks(0).x_m(), ElementsAre(0, 0.25));
  // One value in list brackets is one value too.
  EXPECT_THAT(mpm({"solid.mpm.cracks[1].y_m[2]=[0.3]"}).solid().mpm().cracks(1).y_m(), ElementsAre(0.2, 0.25, 0.3));
  // Strings (quotes optional) and enums.
  auto m = with_overrides({"coupling.solid_args=[\"--a\", \"--b\"]"});
  apply_override(m, "coupling.solid_args[1]=--threads=4");
  EXPECT_THAT(m.coupling().solid_args(), ElementsAre("--a", "--threads=4"));
  apply_override(m, "coupling.solid_args[0]=\"--c\"");
  EXPECT_THAT(m.coupling().solid_args(), ElementsAre("--c", "--threads=4"));
  auto e = mpm({});
  e.mutable_solid()->mutable_mpm()->add_silent_edges(scene::RIGHT);
  apply_override(e, "solid.mpm.silent_edges[0]=TOP");
  EXPECT_THAT(e.solid().mpm().silent_edges(), ElementsAre(scene::TOP));
}

TEST(OverrideElement, OneElementTakesOneValue) {
  const auto two = refusal({"solid.mpm.cracks[0].x_m[1]=[0.2, 0.3]"});
  EXPECT_EQ(two,
            "--set solid.mpm.cracks[0].x_m[1]=[0.2, 0.3]: 2 values for one element (solid.mpm.cracks[0].x_m[1]); "
            "give one");
  const auto messages = refusal({"solid.mpm.cracks[0]=[{x_m: [0, 1]}, {x_m: [0, 2]}]"});
  EXPECT_EQ(messages,
            "--set solid.mpm.cracks[0]=[{x_m: [0, 1]}, {x_m: [0, 2]}]: 2 values for one element "
            "(solid.mpm.cracks[0]); give one message in braces, {...}");
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].x_m[1]=abc"}),
            "--set solid.mpm.cracks[0].x_m[1]=abc: not a valid double value for solid.mpm.cracks[0].x_m[1]");
  EXPECT_EQ(refusal({"solid.mpm.cracks[0]={x_m: [0, q]}"}),
            "--set solid.mpm.cracks[0]={x_m: [0, q]}: not a valid CrackSpecScene value for solid.mpm.cracks[0]");
  // The value cannot reach past its element into the next key.
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].x_m[1]=0.2 y_m: 7"}),
            "--set solid.mpm.cracks[0].x_m[1]=0.2 y_m: 7: not a valid double value for solid.mpm.cracks[0].x_m[1]");
}

// ------------------------------------------------------------ refused

TEST(OverrideElement, IndexOutOfRangeSaysHowManyThereAre) {
  EXPECT_EQ(refusal({"solid.mpm.cracks[1].x_m=[0, 0.5]"}, kOneCrack),
            "--set solid.mpm.cracks[1].x_m: solid.mpm.cracks has 1 element; allowed: [0] (--set does not add "
            "elements: to add one, set the whole list, --set 'solid.mpm.cracks=[{...}, {...}]')");
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].x_m[2]=1"}),
            "--set solid.mpm.cracks[0].x_m[2]: solid.mpm.cracks[0].x_m has 2 elements; allowed: [0] to [1] (--set "
            "does not add elements: to add one, set the whole list, --set 'solid.mpm.cracks[0].x_m=[a, b]')");
  EXPECT_EQ(refusal({"solid.mpm.materials[7].poisson_ratio=0.2"}),
            "--set solid.mpm.materials[7].poisson_ratio: solid.mpm.materials has 2 elements; allowed: [0] to [1] or "
            "by name [rock], [shale] (--set does not add elements: to add one, set the whole list, --set "
            "'solid.mpm.materials=[{...}, {...}]')");
  for (const char* huge : {"4294967296", "99999999999999999999999999999999", "2147483648"}) {
    EXPECT_THAT(refusal({std::string("solid.mpm.cracks[") + huge + "].x_m=[0, 1]"}),
                HasSubstr("solid.mpm.cracks has 2 elements; allowed: [0] to [1]"))
        << huge;
  }
  const auto empty = scene_error([] { with_overrides({"coupling.solid_args[0]=--a"}); });
  EXPECT_EQ(empty.problems().at(0),
            "--set coupling.solid_args[0]: coupling.solid_args has no elements; allowed: none (--set does not add "
            "elements: to add one, set the whole list, --set 'coupling.solid_args=[a, b]')");
}

TEST(OverrideElement, UnknownNameListsTheNames) {
  EXPECT_EQ(refusal({"solid.mpm.materials[granite].youngs_modulus_pa=2e10"}),
            "--set solid.mpm.materials[granite].youngs_modulus_pa: solid.mpm.materials has no element named "
            "\"granite\"; solid.mpm.materials has 2 elements; allowed: [0] to [1] or by name [rock], [shale]");
  EXPECT_THAT(refusal({"solid.mpm.materials[\"Rock\"].youngs_modulus_pa=2e10"}),
              HasSubstr("no element named \"Rock\""));
}

TEST(OverrideElement, NameTwiceIsRefused) {
  auto s = mpm({});
  s.mutable_solid()->mutable_mpm()->mutable_materials(1)->set_name("rock");
  const auto e = scene_error([&] { apply_override(s, "solid.mpm.materials[rock].poisson_ratio=0.2"); });
  EXPECT_EQ(e.problems().at(0),
            "--set solid.mpm.materials[rock].poisson_ratio: solid.mpm.materials has 2 elements named \"rock\" ([0], "
            "[1]); select one by index");
}

TEST(OverrideElement, BracketsOnAFieldThatIsNotAList) {
  EXPECT_EQ(refusal({"time[0].end_s=2"}),
            "--set time[0].end_s: 'time' is not a list; brackets select one element of a repeated key");
  EXPECT_EQ(refusal({"solid.mpm.cell_size_m[0]=0.2"}),
            "--set solid.mpm.cell_size_m[0]: 'solid.mpm.cell_size_m' is not a list; brackets select one element of "
            "a repeated key");
  EXPECT_EQ(refusal({"solid.mpm.regions[0].initial_stress[xx].xx_pa=1"}),
            "--set solid.mpm.regions[0].initial_stress[xx].xx_pa: 'solid.mpm.regions[0].initial_stress' is not a "
            "list; brackets select one element of a repeated key");
}

TEST(OverrideElement, NameWhereTheElementsHaveNone) {
  EXPECT_EQ(refusal({"solid.mpm.cracks[main].x_m=[0, 1]"}, kOneCrack),
            "--set solid.mpm.cracks[main].x_m: the elements of solid.mpm.cracks (CrackSpecScene) have no name: "
            "select one by index, not by \"main\"; solid.mpm.cracks has 1 element; allowed: [0]");
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].x_m[first]=0"}),
            "--set solid.mpm.cracks[0].x_m[first]: solid.mpm.cracks[0].x_m holds values, not named elements: select "
            "one by index, not by \"first\"; solid.mpm.cracks[0].x_m has 2 elements; allowed: [0] to [1]");
  EXPECT_THAT(refusal({"solid.mpm.cracks[\"0\"].x_m=[0, 1]"}), HasSubstr("have no name: select one by index"));
}

TEST(OverrideElement, MalformedBrackets) {
  const std::string form =
      "; a key is NAME.NAME..., with [INDEX] or [NAME] after the name of a list, e.g. solid.mpm.cracks[0].x_m or "
      "solid.mpm.materials[rock].youngs_modulus_pa";
  EXPECT_EQ(refusal({"solid.mpm.cracks[=1"}), "--set solid.mpm.cracks[: '[' after 'cracks' is not closed" + form);
  EXPECT_EQ(refusal({"solid.mpm.cracks[0.x_m=1"}),
            "--set solid.mpm.cracks[0.x_m: '[' after 'cracks' is not closed" + form);
  EXPECT_EQ(refusal({"solid.mpm.cracks[]=1"}),
            "--set solid.mpm.cracks[]: nothing between the brackets of 'cracks[]'" + form);
  EXPECT_EQ(refusal({"solid.mpm.cracks[0]x_m=1"}),
            "--set solid.mpm.cracks[0]x_m: '.' or the end expected after 'cracks[0]', not 'x'" + form);
  EXPECT_EQ(refusal({"solid.mpm.cracks[0][1]=1"}),
            "--set solid.mpm.cracks[0][1]: '.' or the end expected after 'cracks[0]', not '['" + form);
  EXPECT_EQ(refusal({"solid.mpm.materials[\"rock].poisson_ratio=0.2"}),
            "--set solid.mpm.materials[\"rock].poisson_ratio: the quote after 'materials[' is not closed" + form);
  EXPECT_EQ(
      refusal({"solid.mpm.materials[\"rock\"x].poisson_ratio=0.2"}),
      "--set solid.mpm.materials[\"rock\"x].poisson_ratio: ']' expected after the quoted name in 'materials['" + form);
  EXPECT_EQ(refusal({"solid.mpm.cracks[-1].x_m=[0, 1]"}),
            "--set solid.mpm.cracks[-1].x_m: '-1' is not an index (a whole number from 0); solid.mpm.cracks has 2 "
            "elements; allowed: [0] to [1]");
  EXPECT_EQ(refusal({"solid.mpm.cracks[1x].x_m=[0, 1]"}),
            "--set solid.mpm.cracks[1x].x_m: '1x' is not an index (a whole number from 0); solid.mpm.cracks has 2 "
            "elements; allowed: [0] to [1]");
  EXPECT_THAT(refusal({"solid.mpm.cracks[+1].x_m=[0, 1]"}), HasSubstr("'+1' is not an index"));
  EXPECT_THAT(refusal({"solid.mpm.cracks[ 1].x_m=[0, 1]"}), HasSubstr("have no name: select one by index"));
  // An empty component (a trailing or doubled dot) is not a key.
  EXPECT_THAT(refusal({"solid.mpm.cracks[0].=1"}), HasSubstr("'' is not a key of CrackSpecScene"));
  EXPECT_THAT(refusal({"solid..mpm=1"}), HasSubstr("'' is not a key of Solid"));
  EXPECT_THAT(refusal({"[0]=1"}), HasSubstr("'' is not a key of the scene"));
}

TEST(OverrideElement, PathPastAValueOrThroughAWholeList) {
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].x_m[1].y=2"}),
            "--set solid.mpm.cracks[0].x_m[1].y: 'solid.mpm.cracks[0].x_m[1]' holds a value, not further keys");
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].x_m.y=2"}),
            "--set solid.mpm.cracks[0].x_m.y: 'solid.mpm.cracks[0].x_m' holds a value, not further keys");
  EXPECT_EQ(refusal({"solid.mpm.materials[rock].name.x=2"}),
            "--set solid.mpm.materials[rock].name.x: 'solid.mpm.materials[rock].name' holds a value, not further "
            "keys");
  EXPECT_EQ(refusal({"solid.mpm.cracks.x_m=[0, 1]"}, kOneCrack),
            "--set solid.mpm.cracks.x_m: 'solid.mpm.cracks' is a list; select one element, solid.mpm.cracks[0].x_m; "
            "solid.mpm.cracks has 1 element; allowed: [0]");
  EXPECT_EQ(refusal({"solid.mpm.cracks[0].nope=1"}),
            "--set solid.mpm.cracks[0].nope: 'nope' is not a key of CrackSpecScene; allowed: x_m, y_m, spacing_m, "
            "start_is_tip, end_is_tip, pressure_pa, inlet_vertex, friction_coefficient");
}

TEST(OverrideElement, RefusedOverrideLeavesTheSceneAsItWas) {
  const auto before = mpm({});
  for (const char* assignment :
       {"solid.mpm.cracks[0].x_m[1].y=2", "solid.mpm.regions[0].initial_stress.nope=1",
        "solid.mpm.regions[1].initial_stress.xx_pa=abc", "solid.mpm.cracks[0]={x_m: [0, q]}", "fluid.mpm.cracks=1"}) {
    auto s = before;
    scene_error([&] { apply_override(s, assignment); });
    EXPECT_EQ(s.SerializeAsString(), before.SerializeAsString()) << assignment;
  }
}

// ------------------------------------------------------------ rules broken through an element

TEST(OverrideElement, InvalidValueNamesTheOverrideAsWritten) {
  EXPECT_EQ(refusal({"solid.mpm.materials[rock].youngs_modulus_pa=-1"}),
            "--set solid.mpm.materials[rock].youngs_modulus_pa: solid.mpm.materials[0].youngs_modulus_pa = -1 is not "
            "allowed; expected a finite value > 0 (Pa)");
  EXPECT_THAT(refusal({"solid.mpm.materials[\"shale\"].poisson_ratio=0.5"}),
              HasSubstr("--set solid.mpm.materials[\"shale\"].poisson_ratio: solid.mpm.materials[1].poisson_ratio = "
                        "0.5 is not allowed"));
  EXPECT_THAT(refusal({"solid.mpm.cracks[1].x_m=[0.35, nan, 0.7]"}),
              HasSubstr("--set solid.mpm.cracks[1].x_m: solid.mpm.cracks[1].x_m[1] = nan is not allowed"));
  EXPECT_THAT(refusal({"solid.mpm.cracks[1].x_m[1]=inf"}),
              HasSubstr("--set solid.mpm.cracks[1].x_m[1]: solid.mpm.cracks[1].x_m[1] = inf is not allowed"));
  EXPECT_THAT(refusal({"solid.mpm.materials[shale]={name: \"shale\" youngs_modulus_pa: 5e9 poisson_ratio: 0.3}"}),
              HasSubstr("--set solid.mpm.materials[shale]: solid.mpm.materials[1].density_kg_m3"));
  // A broken value elsewhere in the file keeps its file line; a later override of the whole list wins.
  const auto other =
      refusal({"solid.mpm.materials[shale].poisson_ratio=0.2"},
              "  cracks { x_m: [0, 0.3] y_m: [0.05, 0.05] start_is_tip: false friction_coefficient: -1 }\n");
  EXPECT_THAT(other, HasSubstr("mpm.scene:14: solid.mpm.cracks[0].friction_coefficient = -1"));
  EXPECT_THAT(refusal({"solid.mpm.cracks[1].spacing_m=-1",
                       "solid.mpm.cracks=[{x_m: [0, 0.3] y_m: [0.05, 0.05] "
                       "start_is_tip: false}, {x_m: [0.35, 0.5] y_m: [0.2, 0.2] "
                       "start_is_tip: true spacing_m: -2}]"}),
              HasSubstr("--set solid.mpm.cracks: solid.mpm.cracks[1].spacing_m = -2"));
}

// ------------------------------------------------------------ odd input

TEST(OverrideElement, OddKeysGiveASceneErrorAndNothingElse) {
  const auto base = mpm({});
  std::vector<std::string> keys = {"solid.mpm.cracks[",
                                   "solid.mpm.cracks]",
                                   "solid.mpm.cracks[[0]]",
                                   "solid.mpm.cracks[0]]",
                                   "solid.mpm.cracks[\"",
                                   "solid.mpm.cracks[\"\\",
                                   "solid.mpm.cracks['']",
                                   "solid.mpm.materials[\"\"]",
                                   "solid.mpm.materials[]",
                                   "solid.mpm.materials[.]",
                                   "[",
                                   "]",
                                   ".",
                                   "..",
                                   "[]",
                                   "solid.mpm.cracks[0].x_m[1][",
                                   "solid.mpm.cracks[0x1]",
                                   "solid.mpm.cracks[1e3]",
                                   "solid.mpm.cracks[-0]",
                                   "solid.mpm.cracks[\xff]",
                                   std::string("solid.mpm.cracks[\0]", 20),
                                   std::string(5000, '['),
                                   std::string(5000, '.'),
                                   "solid" + std::string(3000, '.') + "mpm",
                                   "solid.mpm.cracks[" + std::string(5000, '9') + "]"};
  std::mt19937 random(47);
  const std::string alphabet = "[].\"'\\0123456789-+ xrock_";
  const std::vector<std::string> prefixes = {
      "", "solid.mpm.cracks", "solid.mpm.materials", "solid.mpm.cracks[0].x_m", "coupling.solid_args", "time"};
  for (int n = 0; n < 3000; ++n) {
    std::string key = prefixes[random() % prefixes.size()];
    for (int k = static_cast<int>(random() % 8); k > 0; --k) key += alphabet[random() % alphabet.size()];
    keys.push_back(key);
  }
  int refused = 0;
  for (const auto& key : keys) {
    for (const char* value : {"1", "[0, 1]", "{x_m: [0, 1]}", "\"a\"", "{"}) {
      auto s = base;
      try {
        apply_override(s, key + "=" + value);
      } catch (const SceneError& e) {
        ++refused;
        EXPECT_FALSE(e.problems().empty());
        EXPECT_THAT(e.problems().front(), HasSubstr("--set ")) << key;
      }
      // Anything else than a SceneError fails the test (gtest reports the exception).
    }
  }
  EXPECT_GT(refused, 10000);
}

}  // namespace
