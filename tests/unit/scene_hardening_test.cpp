// Unit tests of the scene loader against hostile input: long tokens (no
// regex on user input), names that escape the output directory, byte-order
// marks, oversized input, every number finite, the crack geometry allowed,
// the memory estimate (issue 22), the MPM sides' own check of the scene in
// their Welcome (issue 21).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/proto/scene_rules.hpp"
#include "mpm_fluid_side.hpp"
#include "mpm_solid_side.hpp"
#include "scene_test_support.hpp"

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

// A small valid dry MPM scene; `crack` and `region` replace its crack and region lines.
std::string mpm_scene(const std::string& crack = "cracks { x_m: [0, 0.3] y_m: [0.05, 0.05] start_is_tip: false }",
                      const std::string& region =
                          "regions { material: \"rock\" rectangle { x_min_m: 0 y_min_m: -1 x_max_m: 1 y_max_m: 1 } }",
                      const std::string& constraints = "constraints { symmetry_x_m: 0 }") {
  return "name: \"mpm\"\ntime { end_s: 0.001 }\nsolid { mpm {\n"
         "  grid { x_min_m: 0 y_min_m: -1.1 x_max_m: 1.2 y_max_m: 1.1 }\n  cell_size_m: 0.1\n"
         "  materials { name: \"rock\" youngs_modulus_pa: 1e10 poisson_ratio: 0.25 density_kg_m3: 2500 }\n  " +
         region + "\n  " + constraints + "\n  " + crack + "\n} }\n";
}

TEST(Hardening, LongNameIsRefusedWithoutCrashing) {
  // std::regex recursed once per character and overflowed the stack (rc 139) on 50000.
  const std::string name(50000, 'n');
  const auto e = scene_error([&] { with_overrides({"name=" + name}); });
  EXPECT_THAT(e.what(), HasSubstr("at most 100 characters"));
  EXPECT_THAT(e.what(), HasSubstr("(50000 characters)"));
  EXPECT_LT(std::string(e.what()).size(), 1000u);
  const auto bad = scene_error([&] { with_overrides({"name=" + name + "/"}); });
  EXPECT_THAT(bad.what(), HasSubstr("letters, digits"));
}

TEST(Hardening, LongUnknownKeyAndEnumValueInParserMessages) {
  // The parser's messages quote the user's text; they are scanned, not matched by std::regex.
  const std::string key(50000, 'k');
  std::string text = minimal_text();
  text.replace(text.find("exchange_interval: 1"), 20, key + ": 1");
  const auto e = scene_error([&] { hfmpm::coupling::parse_scene(text, "long.scene", side_rules()); });
  EXPECT_THAT(e.what(), HasSubstr("long.scene:9: unknown key '" + key + "' in Coupling; allowed: transport"));
  const std::string value(50000, 'U');
  std::string enum_text = minimal_text();
  enum_text.replace(enum_text.find("transport: IPC"), 14, "transport: " + value);
  const auto f = scene_error([&] { hfmpm::coupling::parse_scene(enum_text, "enum.scene", side_rules()); });
  EXPECT_THAT(f.what(), HasSubstr("enum.scene:8:"));
  EXPECT_THAT(f.what(), HasSubstr(value));
}

TEST(Hardening, DotNamesAreRefused) {
  for (const char* name : {".", ".."}) {
    const auto e = scene_error([&] { with_overrides({std::string("name=") + name}); });
    EXPECT_THAT(e.what(), HasSubstr("not \".\" or \"..\"")) << name;
  }
  EXPECT_EQ(with_overrides({"name=a..b"}).name(), "a..b");  // dots inside a name are fine
}

TEST(Hardening, Utf8ByteOrderMarkIsSkipped) {
  const auto s = hfmpm::coupling::parse_scene("\xEF\xBB\xBF" + minimal_text(), "bom.scene", side_rules());
  EXPECT_EQ(s.name(), "minimal");
  const auto e = scene_error([] { hfmpm::coupling::parse_scene("\xFF\xFEn\0a\0", "utf16.scene", side_rules()); });
  EXPECT_THAT(e.what(), HasSubstr("utf16.scene: the file is UTF-16"));
}

TEST(Hardening, OversizedInputIsRefused) {
  const auto e = scene_error([] { with_overrides({"description=" + std::string(100000, 'd')}); });
  EXPECT_THAT(e.what(), HasSubstr("an override may have at most 65536"));
  const auto f =
      scene_error([] { hfmpm::coupling::parse_scene(std::string(17 << 20, ' '), "huge.scene", side_rules()); });
  EXPECT_THAT(f.what(), HasSubstr("huge.scene: 17825792 bytes; a scene file may have at most"));
  const auto g = scene_error([] { hfmpm::coupling::load_scene(data_path("bad_scenes"), side_rules()); });
  EXPECT_THAT(g.what(), HasSubstr("is a directory"));
}

// Sets every double field reachable in the schema, one at a time, to NaN in an
// otherwise empty scene: each must be reported under its own path, and alone
// (the other rules wait until every number is finite). New fields are covered
// by the reflection walk without code; this test finds them by the same schema.
void for_each_double_path(const google::protobuf::Descriptor* type,
                          std::vector<const google::protobuf::FieldDescriptor*>& path,
                          const std::function<void(const std::vector<const google::protobuf::FieldDescriptor*>&)>& f) {
  for (int i = 0; i < type->field_count(); ++i) {
    const auto* field = type->field(i);
    path.push_back(field);
    if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_DOUBLE) f(path);
    if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE && path.size() < 8) {
      for_each_double_path(field->message_type(), path, f);
    }
    path.pop_back();
  }
}

TEST(Hardening, EveryDoubleFieldMustBeFinite) {
  int fields = 0;
  std::vector<const google::protobuf::FieldDescriptor*> path;
  for_each_double_path(scene::Scene::descriptor(), path, [&](const auto& p) {
    for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
      scene::Scene s;
      google::protobuf::Message* m = &s;
      std::string key;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const auto* field = p[i];
        const auto* r = m->GetReflection();
        key += (i ? "." : "") + field->name() + (field->is_repeated() ? "[0]" : "");
        if (i + 1 < p.size()) {
          m = field->is_repeated() ? r->AddMessage(m, field) : r->MutableMessage(m, field);
        } else if (field->is_repeated()) {
          r->AddDouble(m, field, bad);
        } else {
          r->SetDouble(m, field, bad);
        }
      }
      const auto problems = hfmpm::coupling::validate(s, side_rules());
      ASSERT_EQ(problems.size(), 1u) << key;
      EXPECT_EQ(problems[0].key, key);
      EXPECT_THAT(problems[0].allowed, HasSubstr("finite")) << key;
    }
    ++fields;
  });
  EXPECT_GE(fields, 90);
}

TEST(Hardening, NonFiniteNumbersHideTheRulesTheyBreak) {
  // A NaN crack coordinate would also fail the geometry rules; only the NaN is reported.
  const auto e = scene_error([] {
    hfmpm::coupling::parse_scene(mpm_scene("cracks { x_m: [0, nan] y_m: [0.05, 0.05] start_is_tip: false }"),
                                 "nan.scene", side_rules());
  });
  EXPECT_EQ(e.problems().size(), 1u) << e.what();
  EXPECT_THAT(e.what(), HasSubstr("solid.mpm.cracks[0].x_m[1] = nan is not allowed; expected a finite number: every "
                                  "number in a scene must be finite"));
}

TEST(Hardening, CrackGeometryThatIsAllowed) {
  // The base: an edge crack with its mouth on the body's edge and a symmetry line.
  EXPECT_NO_THROW(hfmpm::coupling::parse_scene(mpm_scene(), "base.scene", side_rules()));
  // Two cracks a cell and a half apart; the second interior with two tips.
  EXPECT_NO_THROW(hfmpm::coupling::parse_scene(
      mpm_scene("cracks { x_m: [0, 0.3] y_m: [0.05, 0.05] start_is_tip: false }\n"
                "cracks { x_m: [0.35, 0.5, 0.7] y_m: [0.2, 0.25, 0.25] start_is_tip: true }"),
      "two.scene", side_rules()));
  // A mouth on a polygon's inner edge (a notch), no symmetry line.
  EXPECT_NO_THROW(
      hfmpm::coupling::parse_scene(mpm_scene("cracks { x_m: [0.6, 0.6] y_m: [0.2, 0.6] start_is_tip: false }",
                                             "regions { material: \"rock\" polygon { x_m: [0, 1, 1, 0.2, 0.2, 1, 1, 0] "
                                             "y_m: [-1, -1, -0.2, -0.2, 0.2, 0.2, 1, 1] } }",
                                             ""),
                                   "notch.scene", side_rules()));
  // A mouth at the end of the polyline, on the body's right edge.
  EXPECT_NO_THROW(hfmpm::coupling::parse_scene(
      mpm_scene("cracks { x_m: [0.5, 1] y_m: [0.05, 0.05] start_is_tip: true end_is_tip: false }"), "end.scene",
      side_rules()));
}

TEST(Hardening, MemoryEstimateIsAgainstPhysicalMemory) {
  EXPECT_GT(hfmpm::solid::memory_limit_bytes(), 1e8);
  const auto kgd = hfmpm::coupling::load_scene(hfmpm::test::source("scenarios/kgd-viscosity.scene"), side_rules());
  const double bytes = hfmpm::solid::mpm_solid_memory_bytes(kgd.solid().mpm());
  // 129 x 260 nodes and about 48000 particles (1 per cell, 2 x 2 around the crack): tens of MB.
  EXPECT_GT(bytes, 1e7);
  EXPECT_LT(bytes, 2e8);
}

// A coupler other than hfmpm may hand a side a scene hfmpm would refuse: each
// MPM side runs its own rules on its Welcome's scene and refuses it with the
// words `hfmpm validate` uses (an input Error).
TEST(Hardening, MpmSidesRefuseABadSceneInTheirWelcome) {
  auto s = hfmpm::coupling::load_scene(hfmpm::test::source("scenarios/kgd-viscosity-ci.scene"), side_rules());
  s.mutable_solid()->mutable_mpm()->set_cfl(0.7);
  s.mutable_fluid()->mutable_mpm()->set_cfl(2);
  const auto problems = hfmpm::coupling::validate(s, side_rules());
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].key, "solid.mpm.cfl");
  EXPECT_EQ(problems[1].key, "fluid.mpm.cfl");
  const auto refusal = [&](hfmpm::coupling::SideModel& side) -> std::string {
    try {
      side.setup(s, hfmpm::test::source("build/no-such-dir"));
    } catch (const hfmpm::coupling::InputError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  EXPECT_EQ(refusal(*hfmpm::solid::make_mpm_solid_side()), hfmpm::proto::problem_text(problems[0]));
  EXPECT_EQ(refusal(*hfmpm::fluid::make_mpm_fluid_side()), hfmpm::proto::problem_text(problems[1]));
  const auto e = scene_error([] {
    hfmpm::coupling::load_scene(hfmpm::test::source("scenarios/kgd-viscosity-ci.scene"), side_rules(),
                                {"solid.mpm.cfl=0.7"});
  });
  EXPECT_THAT(e.what(), HasSubstr(hfmpm::proto::problem_text(problems[0])));
}

}  // namespace
