// The derived method (coupler/src/method.cpp, docs/scenes.md "The derived
// method"): the physics read from a hand-written scene, the keys it fills
// and the ones it leaves, against the numbers computed here from the rules.
#include "hfmpm/coupling/method.hpp"

#include <gmock/gmock.h>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hfmpm/coupling/scene_loader.hpp"
#include "scene_test_support.hpp"
#include "test_support.hpp"

namespace hfmpm::method {
namespace {

using ::testing::HasSubstr;

scene::Scene parsed(const std::string& text) {
  scene::Scene s;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &s)) << text;
  return s;
}

// The lab viscosity-dominated KGD written with its physics only
// (scenarios/kgd-viscosity-ci.scene).
scene::Scene physics_only() {
  return parsed(hfmpm::test::read_file(hfmpm::test::source("scenarios/kgd-viscosity-ci.scene")));
}

const Setting* find(const std::vector<Setting>& settings, const std::string& key) {
  for (const auto& s : settings)
    if (s.key == key) return &s;
  return nullptr;
}

// kgd-viscosity-ci's physics with its notch turned to 30 degrees and
// sigma_xx raised to 150 kPa (sigma_H along x, 100 kPa across).
scene::Scene inclined_30() {
  scene::Scene written = physics_only();
  auto& m = *written.mutable_solid()->mutable_mpm();
  for (auto& r : *m.mutable_regions()) r.mutable_initial_stress()->set_xx_pa(-1.5e5);
  auto& crack = *m.mutable_cracks(0);
  crack.set_x_m(1, 0.15 * std::cos(std::numbers::pi / 6));
  crack.set_y_m(1, 0.15 * std::sin(std::numbers::pi / 6));
  return written;
}

TEST(Method, ReadsTheFluidDrivenCracksPhysicsFromAScene) {
  std::string why;
  const auto p = physics_of(physics_only(), &why);
  ASSERT_TRUE(p) << why;
  EXPECT_DOUBLE_EQ(p->physics.youngs_modulus, 1e7);
  EXPECT_DOUBLE_EQ(p->physics.toughness, 100);
  EXPECT_DOUBLE_EQ(p->physics.viscosity, 0.01);
  EXPECT_DOUBLE_EQ(p->physics.total_rate, 2.5e-4);        // an edge crack: twice the wing's 1.25e-4
  EXPECT_NEAR(p->physics.effective_s, 5 - 0.025, 1e-12);  // a ramp over 0.05 s: half of it lost
  EXPECT_DOUBLE_EQ(p->physics.notch, 0.15);
  EXPECT_DOUBLE_EQ(p->physics.normal_stress, 1e5);
  EXPECT_DOUBLE_EQ(p->physics.shear_stress, 0);
  EXPECT_TRUE(p->physics.symmetric);
  EXPECT_DOUBLE_EQ(p->cell, 0.035);
  EXPECT_DOUBLE_EQ(p->reach, 3);  // the body reaches 3 m along the crack, 3.05 m across
  EXPECT_TRUE(p->toughness_given);
}

// Every method key of the physics-only scene, from the rules written out here.
TEST(Method, DerivesTheVerifiedMethodForAPhysicsOnlyScene) {
  std::vector<Setting> applied;
  const scene::Scene s = with_method(physics_only(), &applied);
  const double e_prime = 1e7 / (1 - 0.0625);
  const double km =
      std::sqrt(32 / std::numbers::pi) * 100 / std::pow(e_prime * e_prime * e_prime * 0.12 * 2.5e-4, 0.25);
  EXPECT_NEAR(km, 0.0231, 1e-4);
  const Vertex m = m_vertex(e_prime, 0.01, 2.5e-4, 4.975);
  // Density scaling: the scaled P-wave crosses l in 0.5% of 5 s, rounded down to 2 digits.
  const double c_p = std::sqrt(1e7 * 0.75 / (1.25 * 0.5) / 2500);
  const double scaling = std::pow(c_p * 0.005 * 5 / m.half_length, 2);
  EXPECT_DOUBLE_EQ(s.solid().mpm().density_scaling(), std::floor(scaling * 10) / 10);
  EXPECT_NEAR(s.solid().mpm().density_scaling(), 8.3, 1e-12);
  // Damping: 2% lag of the body's lowest mode over its reach of 3 m, at most critical.
  const double omega = std::numbers::pi * c_p / std::sqrt(8.3) / (2 * 3);
  const double t_3 = 4.975 * std::pow(0.45 / m.half_length, 1.5);
  const double alpha = std::min(2 * omega, 0.02 * omega * omega * t_3);
  EXPECT_DOUBLE_EQ(s.solid().mpm().damping().grid_alpha_per_s(), std::floor(alpha));  // 2 digits: 10
  EXPECT_DOUBLE_EQ(s.solid().mpm().damping().pic_fraction(), 0.5);
  // Growth: 2 g h within 2.5% of three notch lengths (0.01125 m): g = 1/8 at h = 0.035.
  EXPECT_DOUBLE_EQ(s.solid().mpm().fracture().growth_cells(), 0.125);
  EXPECT_DOUBLE_EQ(s.solid().mpm().fracture().max_lag_cells(), 0.125);
  EXPECT_TRUE(s.solid().mpm().fracture().propagate());
  EXPECT_EQ(s.solid().mpm().fracture().direction(), scene::FractureSpec::STRAIGHT);
  EXPECT_FALSE(s.solid().mpm().fracture().has_settle_transits());  // viscosity-dominated: no settling
  EXPECT_TRUE(s.solid().mpm().fracture().surfaces_from_material());
  EXPECT_TRUE(s.solid().mpm().in_situ_reference());
  EXPECT_EQ(s.coupling().scheme(), scene::Coupling::IMPLICIT);
  EXPECT_DOUBLE_EQ(s.time().safety_factor(), 0.9);
  const auto& f = s.fluid().mpm();
  EXPECT_EQ(f.lag(), scene::MpmFluid::TIP_ASYMPTOTE_MATCHED);  // Km < 2
  EXPECT_DOUBLE_EQ(f.lag_pressure_pa(), 1e5);
  EXPECT_DOUBLE_EQ(f.virtual_opening_m(), std::round(0.01 * m.opening * 1e6) / 1e6);  // 1.4e-5
  EXPECT_DOUBLE_EQ(f.merge_fraction(), 0.5);
  EXPECT_EQ(f.max_substeps(), 1000u);
  EXPECT_DOUBLE_EQ(f.initial_fill().front_m(), 0.15);
  EXPECT_DOUBLE_EQ(f.initial_fill().pressure_pa(), 1e5);
  // Each derived key is listed once with a rule.
  for (const char* key : {"coupling.scheme", "solid.mpm.density_scaling", "fluid.mpm.lag", "fluid.mpm.initial_fill",
                          "solid.mpm.fracture.surfaces_from_material"}) {
    const Setting* setting = find(applied, key);
    ASSERT_TRUE(setting) << key;
    EXPECT_FALSE(setting->rule.empty()) << key;
  }
  // Derived once, the scene has nothing left to derive.
  std::vector<Setting> again;
  with_method(s, &again);
  EXPECT_TRUE(again.empty());
}

TEST(Method, KeepsEveryKeyTheSceneSets) {
  scene::Scene written = physics_only();
  auto& m = *written.mutable_solid()->mutable_mpm();
  m.set_density_scaling(3);
  m.mutable_damping()->set_grid_alpha_per_s(7);
  m.mutable_fracture()->set_surfaces_from_material(false);
  m.mutable_fracture()->set_direction(scene::FractureSpec::MAX_HOOP_STRESS);
  written.mutable_fluid()->mutable_mpm()->set_lag(scene::MpmFluid::FRONT_PRESSURE);
  written.mutable_coupling()->set_exchange_interval(5);  // IMPLICIT needs 1: the scheme stays JACOBI
  std::vector<Setting> applied;
  const scene::Scene s = with_method(written, &applied);
  EXPECT_DOUBLE_EQ(s.solid().mpm().density_scaling(), 3);
  EXPECT_DOUBLE_EQ(s.solid().mpm().damping().grid_alpha_per_s(), 7);
  EXPECT_FALSE(s.solid().mpm().fracture().surfaces_from_material());
  EXPECT_EQ(s.solid().mpm().fracture().direction(), scene::FractureSpec::MAX_HOOP_STRESS);
  EXPECT_EQ(s.fluid().mpm().lag(), scene::MpmFluid::FRONT_PRESSURE);
  EXPECT_FALSE(s.fluid().mpm().has_lag_pressure_pa());  // no zero-lag tip solution: no lag pressure
  EXPECT_EQ(s.coupling().scheme(), scene::Coupling::JACOBI);
  EXPECT_FALSE(s.time().has_safety_factor());
  for (const char* key : {"solid.mpm.density_scaling", "solid.mpm.damping.grid_alpha_per_s", "coupling.scheme",
                          "fluid.mpm.lag", "solid.mpm.fracture.direction"}) {
    EXPECT_FALSE(find(applied, key)) << key;
  }
}

// Toughness-dominated (kgd-toughness-ci's physics): the settling wait and
// the load released over it; the settle a scene sets bounds the release.
TEST(Method, ToughnessDominatedCrackSettlesAfterEachStep) {
  scene::Scene written = physics_only();
  auto& mat = *written.mutable_solid()->mutable_mpm()->mutable_materials(0);
  mat.set_toughness_pa_sqrt_m(25e3);
  written.mutable_fluid()->mutable_mpm()->set_viscosity_pa_s(0.001);
  written.mutable_fluid()->mutable_mpm()->mutable_inlet()->mutable_flow_rate_m2_s()->mutable_ramp()->set_v1(4.15e-4);
  const scene::Scene s = with_method(written);
  EXPECT_EQ(s.fluid().mpm().lag(), scene::MpmFluid::FRONT_PRESSURE);  // Km = 7.6
  EXPECT_DOUBLE_EQ(s.solid().mpm().fracture().growth_cells(), 0.25);
  EXPECT_DOUBLE_EQ(s.solid().mpm().fracture().settle_transits(), 2);
  EXPECT_DOUBLE_EQ(s.solid().mpm().fracture().release_transits(), 2);
  written.mutable_solid()->mutable_mpm()->mutable_fracture()->set_settle_transits(1);
  EXPECT_DOUBLE_EQ(with_method(written).solid().mpm().fracture().release_transits(), 1);
}

// Turning tips wait front_settle_transits shear transits of their J domain
// after each growth step, which caps them at g c_s / (N j_outer). The field
// well of issue 46 at 30 degrees (E 20 GPa, nu 0.25, 2600 kg/m^3, water,
// 1e-3 m^2/s for 100 s, a 5 m wing, 2.29 m cells; Km 0.97): the P-wave rule
// gives a scaling of 1000, whose cap (0.29 m/s) held the tips below the
// M-vertex's speed at three notch lengths. The derived wait is shorter for
// a shorter step; where a wait still caps the tips below that speed the
// scaling is lowered until the cap reaches it.
TEST(Method, TurningTipsWaitNoLongerThanTheirExpectedSpeedAllows) {
  Physics p;
  p.youngs_modulus = 2e10;
  p.poisson_ratio = 0.25;
  p.density = 2600;
  p.toughness = 1e6;
  p.viscosity = 1e-3;
  p.total_rate = 1e-3;
  p.end_s = 100;
  p.effective_s = 99.5;
  p.notch = 5;
  const double h = 2.29, reach = 231;
  const Method straight = derive(p, h, reach);
  ASSERT_TRUE(straight.expected.viscosity_dominated);
  ASSERT_DOUBLE_EQ(straight.growth_cells, 1.0 / 16);
  EXPECT_DOUBLE_EQ(straight.density_scaling, 1000);
  EXPECT_FALSE(straight.front_settle_capped);

  // The M-vertex's speed when the crack reaches three notch lengths, 2/3 l / t.
  const double e_prime = p.youngs_modulus / (1 - p.poisson_ratio * p.poisson_ratio);
  const double l_end = m_vertex(e_prime, p.viscosity, p.total_rate, p.effective_s).half_length;
  const double t_3 = p.effective_s * std::pow(3 * p.notch / l_end, 1.5);
  const double speed = 2.0 / 3.0 * 3 * p.notch / t_3;
  EXPECT_NEAR(speed, 0.539, 0.001);
  const double c_s = std::sqrt(p.youngs_modulus / (2 * (1 + p.poisson_ratio)) / p.density);
  auto cap = [&](const Method& d, double transits) {
    return d.growth_cells * c_s / std::sqrt(d.density_scaling) / (transits * 3);
  };
  EXPECT_LT(cap(straight, 4), 0.3);  // the old scaling's cap

  // The derived wait: 4 transits per quarter cell of step, 1 at this
  // sixteenth-cell step, whose cap (1.15 m/s) is above the speed: the
  // P-wave rule's scaling stands.
  Chosen turning;
  turning.turning_waits = true;
  const Method derived = derive(p, h, reach, turning);
  EXPECT_DOUBLE_EQ(derived.front_settle_transits, 1);
  EXPECT_FALSE(derived.front_settle_capped);
  EXPECT_DOUBLE_EQ(derived.density_scaling, 1000);
  EXPECT_GE(cap(derived, 1), 2 * speed);
  EXPECT_DOUBLE_EQ(derive(p, h, reach, Chosen{0, 0.125, true}).front_settle_transits, 2);
  EXPECT_DOUBLE_EQ(derive(p, h, reach, Chosen{0, 0.5, true}).front_settle_transits, 4);

  // The wait of 4 transits a scene may set caps the tips below the speed:
  // the scaling is lowered until the cap reaches it.
  turning.front_settle_transits = 4;
  const Method turned = derive(p, h, reach, turning);
  EXPECT_TRUE(turned.front_settle_capped);
  EXPECT_NEAR(turned.early_tip_speed, speed, 1e-9);
  EXPECT_DOUBLE_EQ(turned.density_scaling, 280);  // two digits, rounded down
  EXPECT_GE(cap(turned, 4), speed);
  EXPECT_LT(cap(turned, 4), 1.05 * speed);  // no slower than the rule needs
  // The damping follows the lower scaling (a faster body).
  EXPECT_GT(turned.damping, straight.damping);

  // A rock of half the modulus elsewhere in the body: the wait is longest
  // there, and the scaling halves.
  p.slowest_shear_speed = c_s / std::sqrt(2.0);
  const Method softer = derive(p, h, reach, turning);
  EXPECT_DOUBLE_EQ(softer.density_scaling, 140);
  EXPECT_GE(softer.growth_cells * p.slowest_shear_speed / std::sqrt(softer.density_scaling) / 12, speed);
  p.slowest_shear_speed = 0;

  // No wait, no cap.
  turning.front_settle_transits = 0;
  const Method no_wait = derive(p, h, reach, turning);
  EXPECT_FALSE(no_wait.front_settle_capped);
  EXPECT_DOUBLE_EQ(no_wait.density_scaling, 1000);
  // A scaling the scene sets is kept.
  turning.front_settle_transits = 4;
  turning.density_scaling = 500;
  EXPECT_DOUBLE_EQ(derive(p, h, reach, turning).density_scaling, 500);
}

// With toughness the settling wait after each step counts the whole crack:
// a well's two wings wait twice as long as one wing, so the scaling that
// keeps the wait's cap above the tip's final speed is a quarter. The lab
// toughness well of tests/coupled/inclined_test.cpp at 20 cells per
// half-length (h = 0.0139 m): 1.0 for two wings, where the P-wave rule's 3.4
// held its tips to half the reference's speed; at 10 cells the P-wave rule
// stands.
TEST(Method, ToughnessWaitCountsBothWingsOfAWell) {
  Physics p;
  p.youngs_modulus = 1e7;
  p.poisson_ratio = 0.25;
  p.density = 2500;
  p.toughness = 25e3;
  p.viscosity = 1e-3;
  p.total_rate = 8.3e-4;
  p.end_s = 1.5;
  p.effective_s = 1.475;
  p.notch = 0.15;
  const Method one = derive(p, 0.0139, 3);
  ASSERT_TRUE(one.settle);
  p.two_wings = true;
  const Method two = derive(p, 0.0139, 3);
  EXPECT_DOUBLE_EQ(one.density_scaling, 3.4);
  EXPECT_DOUBLE_EQ(two.density_scaling, 1);
  // The cap g h c_s / (2 L), L the whole crack at the end, against the tip's final speed.
  const double c_s = std::sqrt(p.youngs_modulus / (2 * (1 + p.poisson_ratio)) / p.density);
  const double whole = 2 * two.expected.end.half_length;
  EXPECT_GE(two.growth_cells * 0.0139 * c_s / std::sqrt(two.density_scaling) / (2 * whole), 0.99 * two.tip_speed);
  EXPECT_DOUBLE_EQ(derive(p, 0.0278, 3).density_scaling, 3.4);
}

// The same through a scene: the lab KGD (kgd-viscosity-ci's physics) turned
// to 30 degrees under 150 / 100 kPa. Its tips turn and wait; with the wait
// the scene sets, 40 transits, the cap binds and lowers the scaling. Set
// STRAIGHT, or with the zero lag the scene turned off, it does not.
TEST(Method, ASceneTurningTipsWaitSetsItsScaling) {
  scene::Scene written = inclined_30();
  written.mutable_solid()->mutable_mpm()->mutable_fracture()->set_front_settle_transits(40);
  std::vector<Setting> applied;
  const scene::Scene turned = with_method(written, &applied);
  ASSERT_EQ(turned.solid().mpm().fracture().direction(), scene::FractureSpec::MAX_HOOP_STRESS);
  const auto p = physics_of(written);
  ASSERT_TRUE(p);
  Chosen chosen;
  chosen.turning_waits = true;
  chosen.front_settle_transits = 40;
  const Method d = derive(p->physics, p->cell, p->reach, chosen);
  EXPECT_DOUBLE_EQ(turned.solid().mpm().density_scaling(), d.density_scaling);
  const Setting* scaling = find(applied, "solid.mpm.density_scaling");
  ASSERT_TRUE(scaling);
  EXPECT_TRUE(d.front_settle_capped);
  EXPECT_LT(d.density_scaling, derive(p->physics, p->cell, p->reach).density_scaling);
  EXPECT_THAT(scaling->rule, HasSubstr("turning tips' wait"));

  written.mutable_solid()->mutable_mpm()->mutable_fracture()->set_direction(scene::FractureSpec::STRAIGHT);
  EXPECT_DOUBLE_EQ(with_method(written).solid().mpm().density_scaling(),
                   derive(p->physics, p->cell, p->reach).density_scaling);
  written.mutable_solid()->mutable_mpm()->mutable_fracture()->set_direction(scene::FractureSpec::MAX_HOOP_STRESS);
  EXPECT_DOUBLE_EQ(with_method(written).solid().mpm().density_scaling(), d.density_scaling);
  written.mutable_fluid()->mutable_mpm()->set_lag(scene::MpmFluid::ZERO_PRESSURE);
  EXPECT_DOUBLE_EQ(with_method(written).solid().mpm().density_scaling(),
                   derive(p->physics, p->cell, p->reach).density_scaling);
}

// A well inside the body: the inlet's rate is both wings', the notch half the crack.
TEST(Method, InletVertexSharesTheRateBetweenTheWings) {
  scene::Scene written = physics_only();
  auto& crack = *written.mutable_solid()->mutable_mpm()->mutable_cracks(0);
  crack.clear_x_m();
  crack.clear_y_m();
  for (const double x : {-0.15, 0.0, 0.15}) {
    crack.add_x_m(x);
    crack.add_y_m(0);
  }
  crack.set_start_is_tip(true);
  crack.set_inlet_vertex(1);
  const auto p = physics_of(written);
  ASSERT_TRUE(p);
  EXPECT_DOUBLE_EQ(p->physics.total_rate, 1.25e-4);
  EXPECT_DOUBLE_EQ(p->physics.notch, 0.15);
}

// A notch at 30 degrees under 150 / 100 kPa with sigma_H along x: the tips
// turn (hoop stress) and the dry zone carries the minimum stress.
TEST(Method, InclinedNotchUnderAnisotropicStressTurns) {
  scene::Scene written = inclined_30();
  const auto p = physics_of(written);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->physics.normal_stress, 1.5e5 * 0.25 + 1e5 * 0.75, 1e-6);
  EXPECT_NEAR(std::abs(p->physics.shear_stress), 5e4 * std::sin(std::numbers::pi / 6) * std::cos(std::numbers::pi / 6),
              1e-6);
  EXPECT_DOUBLE_EQ(p->physics.minimum_stress, 1e5);
  EXPECT_FALSE(p->physics.symmetric);
  const scene::Scene s = with_method(written);
  EXPECT_EQ(s.solid().mpm().fracture().direction(), scene::FractureSpec::MAX_HOOP_STRESS);
  EXPECT_DOUBLE_EQ(s.fluid().mpm().lag_pressure_pa(), 1e5);
  EXPECT_NEAR(s.fluid().mpm().initial_fill().pressure_pa(), 112500, 1e-6);
}

// A region of a rock of half the modulus, in the far field's in-situ
// stress; its shape is the caller's.
scene::RegionSpec* add_soft_region(scene::Scene& s) {
  auto& m = *s.mutable_solid()->mutable_mpm();
  auto* soft = m.add_materials();
  *soft = m.materials(0);
  soft->set_name("soft");
  soft->set_youngs_modulus_pa(5e6);
  auto* region = m.add_regions();
  region->set_material("soft");
  *region->mutable_initial_stress() = m.regions(0).initial_stress();
  return region;
}

// A layer of another rock beside the crack breaks the symmetry: the tips may turn.
TEST(Method, LayeredBodyTurnsByHoopStress) {
  scene::Scene written = physics_only();
  auto* layer = add_soft_region(written);
  layer->mutable_layer()->set_y_min_m(0.2);
  layer->mutable_layer()->set_y_max_m(3.05);
  const auto p = physics_of(written);
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->physics.symmetric);
  EXPECT_EQ(with_method(written).solid().mpm().fracture().direction(), scene::FractureSpec::MAX_HOOP_STRESS);
}

// A layer of another rock across the crack's path, the body its own mirror
// image about the crack's line: K_II = 0 by symmetry, the crack grows
// straight on. Break the mirror (the layer cut short on one side, the top
// edge loaded differently, a second crack, a shear in-situ stress) and the
// tips turn.
TEST(Method, ALayerAcrossThePathKeepsTheCrackStraight) {
  scene::Scene written = physics_only();
  auto* across = add_soft_region(written);
  across->mutable_rectangle()->set_x_min_m(0.5);
  across->mutable_rectangle()->set_x_max_m(3);
  across->mutable_rectangle()->set_y_min_m(-3.05);
  across->mutable_rectangle()->set_y_max_m(3.05);
  const int last = written.solid().mpm().regions_size() - 1;
  auto direction = [](const scene::Scene& s) { return with_method(s).solid().mpm().fracture().direction(); };
  ASSERT_TRUE(physics_of(written));
  EXPECT_TRUE(physics_of(written)->physics.symmetric);
  EXPECT_EQ(direction(written), scene::FractureSpec::STRAIGHT);

  scene::Scene cut_short = written;
  cut_short.mutable_solid()->mutable_mpm()->mutable_regions(last)->mutable_rectangle()->set_y_max_m(2);
  EXPECT_EQ(direction(cut_short), scene::FractureSpec::MAX_HOOP_STRESS);

  scene::Scene top_loaded = written;
  for (auto& t : *top_loaded.mutable_solid()->mutable_mpm()->mutable_tractions())
    if (t.edge() == scene::TOP) t.mutable_normal_pa()->set_constant(-2e5);
  EXPECT_EQ(direction(top_loaded), scene::FractureSpec::MAX_HOOP_STRESS);

  scene::Scene two_cracks = written;
  auto* second = two_cracks.mutable_solid()->mutable_mpm()->add_cracks();
  *second = two_cracks.solid().mpm().cracks(0);
  for (auto& y : *second->mutable_y_m()) y = 1;
  EXPECT_EQ(direction(two_cracks), scene::FractureSpec::MAX_HOOP_STRESS);

  scene::Scene sheared = written;
  for (auto& r : *sheared.mutable_solid()->mutable_mpm()->mutable_regions()) r.mutable_initial_stress()->set_xy_pa(1e3);
  EXPECT_EQ(direction(sheared), scene::FractureSpec::MAX_HOOP_STRESS);
}

// A dry scene gets the faces from the material and, with its in-situ
// stress in equilibrium, that stress as the reference; nothing else.
TEST(Method, DrySceneGetsTheFacesAndTheInSituReferenceOnly) {
  scene::Scene written = physics_only();
  written.clear_fluid();
  std::vector<Setting> applied;
  const scene::Scene s = with_method(written, &applied);
  ASSERT_EQ(applied.size(), 2u);
  EXPECT_TRUE(s.solid().mpm().fracture().surfaces_from_material());
  EXPECT_TRUE(s.solid().mpm().in_situ_reference());
  EXPECT_FALSE(s.coupling().has_scheme());
  EXPECT_FALSE(s.solid().mpm().has_density_scaling());
  // Regions whose stresses differ across an interface: no reference state.
  written.mutable_solid()->mutable_mpm()->mutable_regions(1)->mutable_initial_stress()->set_xx_pa(-2e5);
  EXPECT_FALSE(with_method(written).solid().mpm().has_in_situ_reference());
}

// A pressure inlet has no vertex to size by: the general keys, and why not the rest.
TEST(Method, PressureInletGetsTheGeneralKeysAndSaysWhy) {
  scene::Scene written = physics_only();
  written.mutable_fluid()->mutable_mpm()->mutable_inlet()->mutable_pressure_pa()->set_constant(2e5);
  std::vector<Setting> applied;
  const scene::Scene s = with_method(written, &applied);
  EXPECT_EQ(s.coupling().scheme(), scene::Coupling::IMPLICIT);
  EXPECT_FALSE(s.solid().mpm().has_density_scaling());
  const Setting* why = find(applied, "(fluid-driven crack)");
  ASSERT_TRUE(why);
  EXPECT_THAT(why->rule, HasSubstr("pressure, not a flow rate"));
}

// The volume a rate function injects, as the time at its end rate.
TEST(Method, EffectiveTimeOfTheInjection) {
  auto time_of = [](const std::string& rate) {
    scene::Scene s = physics_only();
    auto* f = s.mutable_fluid()->mutable_mpm()->mutable_inlet()->mutable_flow_rate_m2_s();
    f->Clear();
    EXPECT_TRUE(google::protobuf::TextFormat::MergeFromString(rate, f)) << rate;
    const auto p = physics_of(s);
    return p ? p->physics.effective_s : -1.0;
  };
  EXPECT_DOUBLE_EQ(time_of("constant: 1e-4"), 5);
  EXPECT_NEAR(time_of("ramp { t1: 1 v1: 1e-4 }"), 4.5, 1e-12);
  // To 5 s: 1e-4 for 2 s, then rising to 1.375e-4 over 3 s.
  EXPECT_NEAR(time_of("table { t: [0, 2, 10] v: [1e-4, 1e-4, 2e-4] }"), (2e-4 + 3 * 1.1875e-4) / 1.375e-4, 1e-9);
  EXPECT_NEAR(time_of("power { scale: 1e-4 exponent: 1 }"), 2.5, 1e-12);
  EXPECT_EQ(time_of("constant: 0"), -1.0);  // no injection at the end: no vertex
}

// Through the loader: hfmpm run's path. The derived keys are checked by the
// sides' rules; a scene's own key set against a derived one is named.
TEST(Method, TheLoaderDerivesAndReportsTheMethod) {
  std::vector<Setting> derived;
  const auto s = hfmpm::coupling::load_scene(hfmpm::test::source("scenarios/kgd-viscosity-ci.scene"),
                                             hfmpm::test::side_rules(), {}, &derived);
  EXPECT_EQ(s.coupling().scheme(), scene::Coupling::IMPLICIT);
  EXPECT_GE(derived.size(), 19u);
  const std::string text = describe(derived, "#   ");
  EXPECT_THAT(text, HasSubstr("#   solid.mpm.density_scaling: 8.3   # quasi-static"));
  // A lag pressure the scene sets, beside the derived matched closure, is kept.
  const auto kept = hfmpm::coupling::load_scene(hfmpm::test::source("scenarios/kgd-viscosity-ci.scene"),
                                                hfmpm::test::side_rules(), {"fluid.mpm.lag_pressure_pa=2e5"});
  EXPECT_DOUBLE_EQ(kept.fluid().mpm().lag_pressure_pa(), 2e5);
}

}  // namespace
}  // namespace hfmpm::method

namespace hfmpm::method {
namespace {

// Hostile physics: the method is derived before the scene's rules run, so it
// must neither crash nor invent numbers from it; the rules then name the
// problem, not a derived key.
TEST(Method, HostilePhysicsGetsNoDerivedNumbersAndTheRulesNameIt) {
  const std::vector<std::string> bad = {
      "solid.mpm.materials[0].youngs_modulus_pa=nan",
      "solid.mpm.materials[0].poisson_ratio=0.7",
      "fluid.mpm.inlet.flow_rate_m2_s={table { t: [0, 1] v: [1e-4] }}",
      "fluid.mpm.inlet.flow_rate_m2_s={table { t: [] v: [] }}",
      "fluid.mpm.inlet.flow_rate_m2_s={table { t: [1, 0] v: [1e-4, 1e-4] }}",
      "fluid.mpm.inlet.flow_rate_m2_s={ramp { t0: 0 v0: 0 }}",
      "fluid.mpm.inlet.flow_rate_m2_s={power { scale: 1e-4 exponent: -1 }}",
      "time.end_s=inf",
      "solid.mpm.cracks[0].x_m=[0, 0]",
      "solid.mpm.cell_size_m=-1",
  };
  int derived_from = 0;
  for (const auto& assignment : bad) {
    SCOPED_TRACE(assignment);
    scene::Scene s = physics_only();
    try {
      hfmpm::coupling::apply_override(s, assignment);
    } catch (const hfmpm::coupling::SceneError&) {
      continue;  // refused as an override already
    }
    ++derived_from;
    EXPECT_FALSE(physics_of(s));
    std::vector<Setting> applied;
    EXPECT_NO_THROW(with_method(s, &applied));
    for (const auto& setting : applied) {
      EXPECT_EQ(setting.value.find("nan"), std::string::npos) << setting.key;
      EXPECT_EQ(setting.value.find("inf"), std::string::npos) << setting.key;
    }
    try {
      hfmpm::coupling::load_scene(hfmpm::test::source("scenarios/kgd-viscosity-ci.scene"), hfmpm::test::side_rules(),
                                  {assignment});
      ADD_FAILURE() << "accepted";
    } catch (const hfmpm::coupling::SceneError& e) {
      EXPECT_EQ(std::string(e.what()).find("was derived"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(derived_from, static_cast<int>(bad.size()));  // each reached the derivation
}

}  // namespace
}  // namespace hfmpm::method
