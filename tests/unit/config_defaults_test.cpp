// Where a default lives (docs/architecture.md, "Defaults"): a run's defaults
// are the scene schema's (proto/hfmpm/scene.proto); SolidConfig and
// FluidConfig keep member defaults of their own for programs and tests that
// build a config directly. to_solid_config / to_fluid_config set every member
// a scene key stands for, so a scene that omits every key it may omit gives
// the schema's defaults. These tests read each default from the schema (its
// descriptor, not a copy of it) and compare it with the config the
// translation makes; a key of the schema that this file does not account for
// fails, so a new key needs its translation and its line here. The library's
// own defaults are the schema's too, but for the differences listed.
#include <google/protobuf/descriptor.h>
#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <set>
#include <string>

#include "hfmpm/fluid/mpm/config.hpp"
#include "hfmpm/solid/mpm/config.hpp"
#include "mpm_fluid_side.hpp"
#include "mpm_solid_side.hpp"

namespace hfmpm {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;

// A field's schema default as a number (bool 0 or 1, an enum its number).
double schema_default(const FieldDescriptor& f) {
  switch (f.cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return f.default_value_double();
    case FieldDescriptor::CPPTYPE_FLOAT:
      return f.default_value_float();
    case FieldDescriptor::CPPTYPE_INT32:
      return f.default_value_int32();
    case FieldDescriptor::CPPTYPE_UINT32:
      return f.default_value_uint32();
    case FieldDescriptor::CPPTYPE_INT64:
      return static_cast<double>(f.default_value_int64());
    case FieldDescriptor::CPPTYPE_UINT64:
      return static_cast<double>(f.default_value_uint64());
    case FieldDescriptor::CPPTYPE_BOOL:
      return f.default_value_bool() ? 1 : 0;
    case FieldDescriptor::CPPTYPE_ENUM:
      return f.default_value_enum()->number();
    default:
      ADD_FAILURE() << f.full_name() << " is not a number";
      return 0;
  }
}

// The keys of one scene message and the members of one config they set.
template <class Config>
struct Keys {
  const Descriptor* message;
  // Every single (not repeated, not in a oneof) number, bool or enum key:
  // the member it sets, read as a number.
  std::map<std::string, std::function<double(const Config&)>> member;
  // Keys without a schema default: the value their absence stands for (as
  // the schema's comment says).
  std::map<std::string, double> unset = {};
  // Keys that set nothing in this config: required ones, or what the side
  // itself reads (named in the test).
  std::set<std::string> elsewhere = {};
};

// `config` holds the schema's default of every key of `keys` (or `instead`'s
// value for the keys it names), and every such key is accounted for.
template <class Config>
void expect_defaults(const Keys<Config>& keys, const Config& config,
                     const std::map<std::string, double>& instead = {}) {
  const Descriptor& message = *keys.message;
  for (int i = 0; i < message.field_count(); ++i) {
    const FieldDescriptor& f = *message.field(i);
    if (f.is_repeated() || f.cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE || f.containing_oneof() != nullptr ||
        f.cpp_type() == FieldDescriptor::CPPTYPE_STRING || keys.elsewhere.contains(f.name())) {
      continue;
    }
    const auto read = keys.member.find(f.name());
    if (read == keys.member.end()) {
      ADD_FAILURE() << f.full_name() << " sets no config member this test knows: translate it and list it here";
      continue;
    }
    double expected = 0;
    if (const auto other = instead.find(f.name()); other != instead.end()) {
      expected = other->second;
    } else if (f.has_default_value()) {
      expected = schema_default(f);
    } else if (const auto absent = keys.unset.find(f.name()); absent != keys.unset.end()) {
      expected = absent->second;
    } else {
      ADD_FAILURE() << f.full_name() << " has no schema default: list what its absence stands for";
      continue;
    }
    EXPECT_EQ(read->second(config), expected) << f.full_name();
  }
  for (const auto& [name, read] : keys.member) EXPECT_NE(message.FindFieldByName(name), nullptr) << name;
  for (const auto& name : keys.elsewhere) EXPECT_NE(message.FindFieldByName(name), nullptr) << name;
}

using solid::mpm::SolidConfig;

Keys<SolidConfig> mpm_solid_keys() {
  return {scene::MpmSolid::descriptor(),
          {{"particles_per_cell", [](const SolidConfig& c) { return c.particles_per_cell; }},
           {"cfl", [](const SolidConfig& c) { return c.cfl; }},
           {"density_scaling", [](const SolidConfig& c) { return c.density_scaling; }},
           {"threads", [](const SolidConfig& c) { return c.threads; }},
           {"implicit_face_stiffness", [](const SolidConfig& c) { return c.implicit_face_stiffness ? 1 : 0; }},
           {"in_situ_reference", [](const SolidConfig& c) { return c.in_situ_reference ? 1 : 0; }}},
          {},
          {"cell_size_m"}};  // required
}

Keys<SolidConfig> fracture_keys() {
  return {scene::FractureSpec::descriptor(),
          {{"j_inner_cells", [](const SolidConfig& c) { return c.fracture.inner_cells; }},
           {"j_outer_cells", [](const SolidConfig& c) { return c.fracture.outer_cells; }},
           {"propagate", [](const SolidConfig& c) { return c.fracture.propagate ? 1 : 0; }},
           {"growth_cells", [](const SolidConfig& c) { return c.fracture.growth_cells; }},
           {"check_interval", [](const SolidConfig& c) { return c.fracture.check_interval; }},
           {"direction",
            [](const SolidConfig& c) {
              return c.fracture.straight ? scene::FractureSpec::STRAIGHT : scene::FractureSpec::MAX_HOOP_STRESS;
            }},
           {"max_lag_cells", [](const SolidConfig& c) { return c.fracture.max_lag_cells; }},
           {"settle_transits", [](const SolidConfig& c) { return c.fracture.settle_transits; }},
           {"release_transits", [](const SolidConfig& c) { return c.fracture.release_transits; }},
           {"front_settle_transits", [](const SolidConfig& c) { return c.fracture.front_settle_transits; }},
           {"surfaces_from_material", [](const SolidConfig& c) { return c.fracture.surfaces_from_material ? 1 : 0; }}},
          {{"max_lag_cells", -1}}};  // unset: no limit
}

Keys<SolidConfig> damping_keys() {
  return {scene::DampingSpec::descriptor(),
          {{"grid_alpha_per_s", [](const SolidConfig& c) { return c.damping.grid_alpha; }},
           {"pic_fraction", [](const SolidConfig& c) { return c.damping.pic_fraction; }},
           {"feedback_q_m2", [](const SolidConfig& c) { return c.damping.feedback_q; }},
           {"feedback_target_kinetic_energy_j", [](const SolidConfig& c) { return c.damping.feedback_target_ke; }}}};
}

// A solid.mpm block with its required keys only, one region without an
// initial stress, a crack and a fixed box with only their required keys.
scene::MpmSolid required_only_solid() {
  scene::MpmSolid s;
  s.mutable_grid()->set_x_min_m(0);
  s.mutable_grid()->set_y_min_m(0);
  s.mutable_grid()->set_x_max_m(1);
  s.mutable_grid()->set_y_max_m(1);
  s.set_cell_size_m(0.1);
  auto* m = s.add_materials();
  m->set_name("rock");
  m->set_youngs_modulus_pa(10e9);
  m->set_poisson_ratio(0.25);
  m->set_density_kg_m3(2600);
  auto* r = s.add_regions();
  r->set_material("rock");
  r->mutable_rectangle()->set_x_max_m(1);
  r->mutable_rectangle()->set_y_max_m(1);
  auto* crack = s.add_cracks();
  for (const double x : {0.0, 0.4}) {
    crack->add_x_m(x);
    crack->add_y_m(0.5);
  }
  s.add_constraints()->mutable_fixed_box()->set_x_max_m(0.1);
  return s;
}

TEST(ConfigDefaults, SolidSceneWithEveryKeyOmittedHasTheSchemasDefaults) {
  const scene::MpmSolid s = required_only_solid();
  const SolidConfig c = solid::to_solid_config(s);
  expect_defaults(mpm_solid_keys(), c);
  expect_defaults(fracture_keys(), c);
  expect_defaults(damping_keys(), c);

  using solid::mpm::Region;
  expect_defaults(Keys<Region>{scene::RegionSpec::descriptor(),
                               {{"particles_per_cell", [](const Region& r) { return r.particles_per_cell; }}},
                               {{"particles_per_cell", 0}}},  // unset: solid.mpm.particles_per_cell's (0 says so)
                  c.regions.at(0));
  // No initial_stress: zero, and zz by plane strain (0 too).
  expect_defaults(Keys<Region>{scene::StressSpec::descriptor(),
                               {{"xx_pa", [](const Region& r) { return r.initial_stress(0); }},
                                {"yy_pa", [](const Region& r) { return r.initial_stress(1); }},
                                {"xy_pa", [](const Region& r) { return r.initial_stress(2); }},
                                {"zz_pa", [](const Region& r) { return r.initial_stress(3); }}},
                               {{"zz_pa", 0}}},  // unset: nu (xx + yy)
                  c.regions.at(0));

  using solid::mpm::CrackSpec;
  expect_defaults(
      Keys<CrackSpec>{scene::CrackSpecScene::descriptor(),
                      {{"spacing_m", [](const CrackSpec& k) { return (k.points.at(1) - k.points.at(0)).norm(); }},
                       {"start_is_tip", [](const CrackSpec& k) { return k.start_is_tip ? 1 : 0; }},
                       {"end_is_tip", [](const CrackSpec& k) { return k.end_is_tip ? 1 : 0; }},
                       {"inlet_vertex", [](const CrackSpec& k) { return static_cast<double>(k.inlet); }},
                       {"friction_coefficient", [](const CrackSpec& k) { return k.friction; }}},
                      {{"spacing_m", s.cell_size_m() / 2}, {"inlet_vertex", -1}}},  // unset: half a cell; a mouth
      c.cracks.at(0));

  using solid::mpm::Constraint;
  expect_defaults(Keys<Constraint>{scene::ConstraintSpec::descriptor(),
                                   {{"fix_x", [](const Constraint& k) { return k.fix_x ? 1 : 0; }},
                                    {"fix_y", [](const Constraint& k) { return k.fix_y ? 1 : 0; }}}},
                  c.constraints.at(0));
}

// SolidConfig{} is what a test or program gets that builds a config itself:
// one thread unless it asks for more (runs: the scene's 2).
TEST(ConfigDefaults, SolidLibraryDefaultsAreTheSchemasButThoseListed) {
  const SolidConfig library{};
  expect_defaults(mpm_solid_keys(), library, {{"threads", 1}});
  expect_defaults(fracture_keys(), library);
  expect_defaults(damping_keys(), library);
}

using fluid::mpm::FluidConfig;

Keys<FluidConfig> mpm_fluid_keys() {
  return {scene::MpmFluid::descriptor(),
          {{"density_kg_m3", [](const FluidConfig& c) { return c.density; }},
           {"bulk_modulus_pa", [](const FluidConfig& c) { return c.bulk_modulus; }},
           {"tait_c", [](const FluidConfig& c) { return c.tait_c; }},
           {"viscosity_pa_s", [](const FluidConfig& c) { return c.viscosity; }},
           {"cfl", [](const FluidConfig& c) { return c.cfl; }},
           {"particle_length_m", [](const FluidConfig& c) { return c.particle_length; }},
           {"merge_fraction", [](const FluidConfig& c) { return c.merge_fraction; }},
           {"flip_fraction", [](const FluidConfig& c) { return c.flip; }},
           {"affine_transfer", [](const FluidConfig& c) { return c.affine ? 1 : 0; }},
           {"element_pressure", [](const FluidConfig& c) { return c.smooth_jacobian ? 1 : 0; }},
           {"min_width_m", [](const FluidConfig& c) { return c.min_width; }},
           {"virtual_opening_m", [](const FluidConfig& c) { return c.virtual_opening; }},
           {"lag",
            [](const FluidConfig& c) {
              return c.lag == FluidConfig::Lag::Front   ? scene::MpmFluid::FRONT_PRESSURE
                     : c.lag == FluidConfig::Lag::Fixed ? scene::MpmFluid::FIXED_PRESSURE
                                                        : scene::MpmFluid::ZERO_PRESSURE;
            }},
           {"lag_pressure_pa", [](const FluidConfig& c) { return c.lag_pressure; }}},
          {},
          {"max_substeps"}};  // the side's subcycling (MpmFluidSide), not the solver's
}

Keys<FluidConfig> inlet_keys() {
  return {scene::FluidInlet::descriptor(),
          {{"pre_opening_m", [](const FluidConfig& c) { return c.inlet.pre_opening; }},
           {"pre_opening_length_m", [](const FluidConfig& c) { return c.inlet.pre_opening_length; }}}};
}

TEST(ConfigDefaults, FluidSceneWithEveryKeyOmittedHasTheSchemasDefaults) {
  scene::Scene s;
  s.mutable_fluid()->mutable_mpm()->mutable_inlet()->mutable_flow_rate_m2_s()->set_constant(1e-4);  // required
  const FluidConfig c = fluid::to_fluid_config(s);
  expect_defaults(mpm_fluid_keys(), c);
  expect_defaults(inlet_keys(), c);
  EXPECT_EQ(c.inlet.kind, fluid::mpm::InletConfig::Kind::FlowRate);
  EXPECT_FALSE(c.outlet.enabled);  // no outlet: the far end is closed
  // coupling.scheme's default (JACOBI) is not the implicit interface.
  EXPECT_EQ(c.implicit_interface,
            scene::Coupling::descriptor()->FindFieldByName("scheme")->default_value_enum()->number() ==
                scene::Coupling::IMPLICIT);
  s.mutable_coupling()->set_scheme(scene::Coupling::IMPLICIT);
  EXPECT_TRUE(fluid::to_fluid_config(s).implicit_interface);
}

TEST(ConfigDefaults, FluidLibraryDefaultsAreTheSchemas) {
  const FluidConfig library{};
  expect_defaults(mpm_fluid_keys(), library);
  expect_defaults(inlet_keys(), library);
}

}  // namespace
}  // namespace hfmpm
