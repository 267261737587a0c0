// The real solid and the real fluid coupled on KGD scenes: the vertex
// references themselves, and the viscosity-dominated, field-scale and
// two-wing CI scenes against the M-vertex. The toughness-dominated scenes:
// kgd_toughness_test.cpp. Shared checks: kgd_support.hpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <string>
#include <vector>

#include "coupled_support.hpp"
#include "h5_reader.hpp"
#include "kgd_support.hpp"

namespace hfmpm::test {
namespace {

TEST(KgdScene, MVertexReference) {
  // The numbers the issue quotes for the full-size scene at 10 s.
  const Vertex v = m_vertex(1e7, 0.25, 0.01, 2.5e-4, 10);
  EXPECT_NEAR(v.length, 0.954, 1e-3);
  EXPECT_NEAR(v.opening, 1.82e-3, 1e-5);
  EXPECT_NEAR(v.pressure, 6.05e3, 10);
}

TEST(KgdScene, KVertexReference) {
  // The numbers the issue quotes for the full-size toughness scene at 10 s.
  const Vertex v = k_vertex(1e7, 0.25, 25e3, 8.3e-4, 10);
  EXPECT_NEAR(v.length, 0.999, 1e-3);
  EXPECT_NEAR(v.opening, 5.29e-3, 1e-5);
  EXPECT_NEAR(v.pressure, 14.1e3, 50);
}

// The virtual film the run derives for the CI viscosity scenes' physics
// (kgd-viscosity-ci, kgd-two-wing-ci): 1% of the M-vertex's mouth opening at
// the end, to 2 significant digits: 1.4e-5 m.
double derived_film() { return std::round(0.01 * m_vertex(1e7, 0.25, 0.01, 2.5e-4, 5 - 0.025).opening * 1e6) / 1e6; }

// Viscosity-dominated (Km = 0.023) against the M-vertex, with water:
// scenarios/kgd-viscosity-ci.scene, written with its physics only (body,
// rock, in-situ stress and its tractions, notch, water, injection, cell
// size). The run derives the method from the physics (docs/scenes.md, "The
// derived method"): the implicit scheme at 0.9 of the solid's step, density
// scaling 8.3, damping 10 /s, growth by 1/8 cell, the tip closure matched to
// the fluid (lag TIP_ASYMPTOTE_MATCHED), the faces read from the material
// and a virtual film of 1% of the M-vertex's mouth opening at the end.
// Measured: 1.4%, 2.2% and 5.6% worst. Asserted within 6%, 4% and 10%, tighter than the
// CI bounds (10%, 10%, 20%), so that the matched closure's gain in length
// over the former default (next test but one) stays held; a growth step is
// 0.7-1.0% of the crack at the compared rows. The pressure is low at every
// row: the finite box makes the body 4-5% more compliant than the
// M-vertex's infinite one (a net pressure 3% lower at the same injection),
// and the virtual film eases the flow by (1 + f / w)^3
// (docs/verification.md). The fluid's volume may fall below its
// compression (water: 6e-5 here) at a row where the tip has just grown:
// allowed 1e-4.
TEST(KgdScene, ViscosityCiSceneFollowsTheMVertex) {
  Bounds bounds{0.06, 0.04, 0.10, 1e-4};
  bounds.film = derived_film();
  expect_ci_scene_follows(
      "scenarios/kgd-viscosity-ci.scene", 2.5e-4, [](double t) { return m_vertex(1e7, 0.25, 0.01, 2.5e-4, t); }, 2e9,
      {}, bounds);
}

// The case of the scene above with both wings modelled and the fluid entering
// at the notch's centre (scenarios/kgd-two-wing-ci.scene; docs/fluid.md,
// "Injection from inside the body"): no symmetry plane, the fluid side
// sharing Q between the wings. Measured (5 December, sixteenth session):
// half-length (half the crack) 2.0%, opening at the wellbore 3.3%, net inlet
// pressure 7.0-8.8% worst, the one-wing scene's figures within a point
// (1.4 junction iterations per step). The wings are equal to 1e-6 m at most
// frames, but a tip's energy criterion is met at one growth check and its
// mirror's at the next when round-off tips J across the toughness, so one
// wing runs a growth step (a quarter cell, 8.75 mm) or two ahead until the
// other catches up: from three notch lengths on, measured 0.55% of their
// mean on average over the frames and 17.5 mm (0.5 cell, 3.0%) at worst.
// Asserted: the one-wing scene's bounds, the pressure's at 12%; the wings
// within 2% of each other on average (the bound, met exactly by
// the full-size scene: docs/verification.md) and within two growth steps.
// The scene now holds its physics only (the method derived: growth 1/8 cell,
// density scaling 8.3, damping 10 /s, film 14 um): 1.4%, 2.0% and 8.9%, the
// wings equal to 0.1 mm at every frame from three notch lengths on.
TEST(KgdScene, TwoWingCiSceneFollowsTheMVertexWithEqualWings) {
  Bounds bounds{0.06, 0.05, 0.12, 1e-4};
  bounds.wings = 2;
  bounds.film = derived_film();  // the scene holds its physics only
  expect_ci_scene_follows(
      "scenarios/kgd-two-wing-ci.scene", 2.5e-4, [](double t) { return m_vertex(1e7, 0.25, 0.01, 2.5e-4, t); }, 2e9, {},
      bounds);
}

// The same with the former defaults: the tip-asymptote closure (lag
// TIP_ASYMPTOTE) and the surfaces integrated from their fields' velocities,
// which read the grown part of the crack 13-16% narrow; the rest of the
// method derived as above. Measured: 6.9%, 0.4% and 5.7% worst (with the settings the
// scene wrote out before, density scaling 10, damping 5 /s, quarter-cell
// growth and a 2e-5 m film: 5.5%, 3.4% and 3.2%, the front within 0.5%;
// with the vacuum front, lag FIXED_PRESSURE, and half-cell growth 15.9%,
// 0.5% and 3.9%, the front 7.7% long; docs/verification.md). Held to the CI
// bounds.
TEST(KgdScene, ViscosityCiSceneWithTheVelocitySurfacesFollowsTheMVertex) {
  Bounds bounds;
  bounds.film = derived_film();
  expect_ci_scene_follows(
      "scenarios/kgd-viscosity-ci.scene", 2.5e-4, [](double t) { return m_vertex(1e7, 0.25, 0.01, 2.5e-4, t); }, 2e9,
      {"--set", "fluid.mpm.lag=TIP_ASYMPTOTE", "--set", "solid.mpm.fracture.surfaces_from_material=false"}, bounds);
}

// The paper's set-up in its own units with water (issue 19):
// scenarios/kgd-paper-field-ci.scene (E = 20 GPa, 1 MPa, water K = 2 GPa,
// mu = 1e-4 Pa s, 1e-5 m^2/s into the wing ramped over 5 s, h = 2 m, 300 s),
// written with its physics only: the method is derived (docs/scenes.md, "The
// derived method"). From three notch lengths on (the 4 m notch), the mouth
// opening within the CI 10% of the M-vertex and the net inlet pressure within
// 20%. Measured with the derived method: opening 3.5%, pressure 11.2%, front
// 5.7%, tip 4.6% (8 s). With the settings written out before (density scaling
// 1e4 against the derived 5.2e4, damping 5 /s against 0.34 /s): 3.7% and 10.2% with the matched closure,
// the faces read from the material and growth by 1/16 cell, since 5 December;
// 5.4% and 12.4% at a quarter cell; 3.5% and 9.3% with the tip-asymptote
// closure and velocity-read faces; 3.2% and 7.2% with the vacuum front and
// half-cell growth); the fluid front within 20% at every row and within 10% at
// the end (measured 5.6% worst; before 4.4%, 4.3%, and 15.5%), where the tip
// may lead it by the zero-lag closure's wait and a growth step (the tip is
// printed, not asserted: 4.6% worst; before 11%, 17%, 29%).
// The water's volume (sum of l w) is
// the injected volume plus the notch's virtual film within 1%: its
// compression p / K ~ 5e-4, and a partly filled front particle counts the
// empty part of its domain (measured 0.99947 to 1.0082, the
// largest at 30 s while the volume is small).
TEST(KgdScene, FieldScaleWaterCiSceneFollowsTheMVertex) {
  const auto out = scratch_dir("kgd_field_ci");
  const auto result =
      run_scene(read_file(source("scenarios/kgd-paper-field-ci.scene")), out, {"--set", "output.hdf5=false"}, 900);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv h = read_csv(out + "/history.csv");
  const auto t = h.values("time_s"), tip = h.values("crack_length_m"), mouth = h.values("mouth_opening_m");
  const auto p_in = h.values("inlet_pressure_pa"), front = h.values("front_position_m");
  const auto injected = h.values("injected_volume_m2"), volume = h.values("fluid_volume_m2");
  ASSERT_NEAR(t.back(), 300, 0.05);  // the run ends on a whole step (dt = 0.024 s)
  // kFilm: the derived virtual film, 1% of the M-vertex mouth opening at the end (2.1e-6 m).
  constexpr double kSigma0 = 1e6, kNotch = 4, kRamp = 5, kQ = 2e-5, kFilm = kNotch * 2.1e-6;
  int compared = 0;
  double e_front_last = 1;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] > 10) {
      // From 20 s within 1%; at 10 s the front particle, at zero pressure,
      // is stretched past its rest volume (water cavitates rather than carry
      // tension) and its domain counts some empty crack: measured 1.0630
      // with the matched closure (4.7e-6 m^2, a twentieth of the front
      // cell's volume), 1.0462 with the tip-asymptote closure, 0.9995 from
      // 20 s on.
      const double ratio = volume[i] / (injected[i] + kFilm);
      EXPECT_NEAR(ratio, 1.0, t[i] < 20 ? 7e-2 : 1e-2) << "t = " << t[i];
    }
    if (front[i] < 3 * kNotch) continue;
    const Vertex v = m_vertex(2e10, 0.25, 1e-4, kQ, t[i] - 0.5 * kRamp);
    const double e_front = front[i] / v.length - 1, e_tip = tip[i] / v.length - 1;
    const double e_opening = mouth[i] / v.opening - 1, e_pressure = (p_in[i] - kSigma0) / v.pressure - 1;
    std::printf("t %.0f s: front %+.3f (tip %+.3f), mouth opening %+.3f, net inlet pressure %+.3f\n", t[i], e_front,
                e_tip, e_opening, e_pressure);
    EXPECT_LT(std::abs(e_opening), 0.10) << "t = " << t[i];
    EXPECT_LT(std::abs(e_pressure), 0.20) << "t = " << t[i];
    EXPECT_LT(std::abs(e_front), 0.20) << "t = " << t[i];
    e_front_last = e_front;
    ++compared;
  }
  EXPECT_LT(std::abs(e_front_last), 0.10);
  EXPECT_GE(compared, 10);
}

// The implicit interface scheme (coupling.scheme IMPLICIT, issue 17) on the
// CI viscosity scene at its own step: the answer no longer depends on how
// stiff the fluid is. At K = 2e7 Pa and water (2e9 Pa), from three notch
// lengths on, the mouth opening and the net inlet pressure agree within 2%
// at every row where the two tips have grown equally, and within 3% where
// one tip is ahead (each growth step dips the pressure for a while); the
// fluid fronts within 2%; the tips differ by at most two growth increments
// (the derived eighth of a cell each, 0.0044 m) plus 2%. Against the
// M-vertex, water's opening is within 10% and its net pressure within 20%
// (the CI bounds). The method is derived from the physics, the same for
// both fluids (`hfmpm validate` lists the same keys at K = 2e7 Pa).
// Measured: 0.27% (opening), 0.34% (pressure) and 0.41% (front) worst over
// 8 rows, the tips equal at every row; with the settings the scene wrote
// out before (density scaling 10, damping 5 /s, quarter-cell growth):
// 0.30%, 1.79% and 0.43%, the tips at most 0.0088 m apart; with the former
// tip-asymptote closure and velocity surfaces: 0.6%, 0.8% and 0.8% over 9
// rows, the tips at most 0.0175 m apart (with the front particle's own
// velocity as the closure's V instead of the last cell's mean: 3.1%, 3.5%,
// 3.6%). K = 2e6 Pa is left out
// on purpose: at 1.1e5 Pa it is compressed by 5%, a physical difference (its
// opening was 2.9% from water's).
TEST(KgdScene, ImplicitSchemeAnswerDoesNotDependOnTheFluidStiffness) {
  struct Run {
    std::vector<double> t, length, front, mouth, p_in;
  };
  // The two runs at once, one solid thread each (the answer does not depend
  // on the thread count; together they take about the wall time of one run
  // with two threads after the other, less on a loaded machine).
  auto run_at = [](const std::string& bulk_modulus) {
    const auto out = scratch_dir("kgd_implicit_" + bulk_modulus);
    const auto scene = read_file(source("scenarios/kgd-viscosity-ci.scene"));
    return std::async(std::launch::async, [out, scene, bulk_modulus] {
      const auto result = run_scene(scene, out,
                                    {"--set", "output.hdf5=false", "--set", "coupling.scheme=IMPLICIT", "--set",
                                     "solid.mpm.threads=1", "--set", "fluid.mpm.bulk_modulus_pa=" + bulk_modulus},
                                    900);
      EXPECT_EQ(result.exit_code, 0) << result.err;
      const Csv h = read_csv(out + "/history.csv");
      return Run{h.values("time_s"), h.values("crack_length_m"), h.values("front_position_m"),
                 h.values("mouth_opening_m"), h.values("inlet_pressure_pa")};
    });
  };
  auto soft_run = run_at("2e7"), water_run = run_at("2e9");
  const Run soft = soft_run.get(), water = water_run.get();
  ASSERT_EQ(soft.t.size(), water.t.size());
  ASSERT_GE(water.t.size(), 20u);
  constexpr double kSigma0 = 1e5, kNotch = 0.15, kGrowth = 0.035 / 8;  // the derived growth step
  double worst_opening = 0, worst_pressure = 0, worst_front = 0;
  int compared = 0;
  for (std::size_t i = 0; i < water.t.size(); ++i) {
    ASSERT_NEAR(soft.t[i], water.t[i], 1e-9);
    if (std::min(soft.length[i], water.length[i]) < 3 * kNotch) continue;
    const double opening = std::abs(soft.mouth[i] / water.mouth[i] - 1);
    const double pressure = std::abs((soft.p_in[i] - kSigma0) / (water.p_in[i] - kSigma0) - 1);
    const double front = std::abs(soft.front[i] / water.front[i] - 1);
    std::printf("t %.2f s: K = 2e7 against water: opening %.4f, net pressure %.4f, front %.4f, tip %.4f m\n",
                water.t[i], opening, pressure, front, soft.length[i] - water.length[i]);
    const double bound = std::abs(soft.length[i] - water.length[i]) < 0.5 * kGrowth ? 0.02 : 0.03;
    EXPECT_LT(opening, bound) << "t = " << water.t[i];
    EXPECT_LT(pressure, bound) << "t = " << water.t[i];
    EXPECT_LT(front, 0.02) << "t = " << water.t[i];
    EXPECT_LT(std::abs(soft.length[i] - water.length[i]), 2 * kGrowth + 0.02 * water.length[i]) << "t = " << water.t[i];
    const Vertex v = m_vertex(1e7, 0.25, 0.01, 2.5e-4, water.t[i] - 0.025);
    EXPECT_LT(std::abs(water.mouth[i] / v.opening - 1), 0.10) << "t = " << water.t[i];
    EXPECT_LT(std::abs((water.p_in[i] - kSigma0) / v.pressure - 1), 0.20) << "t = " << water.t[i];
    worst_opening = std::max(worst_opening, opening);
    worst_pressure = std::max(worst_pressure, pressure);
    worst_front = std::max(worst_front, front);
    ++compared;
  }
  std::printf("%d rows: worst difference opening %.4f, net pressure %.4f, front %.4f\n", compared, worst_opening,
              worst_pressure, worst_front);
  EXPECT_GE(compared, 5);
}

}  // namespace
}  // namespace hfmpm::test
