// Unit tests of the stand-in physics: hfmpm::solid::PrescribedCrack
// (solid/include/hfmpm/solid/prescribed_crack.hpp) and hfmpm::fluid::PrescribedPressure
// (fluid/include/hfmpm/fluid/prescribed_pressure.hpp).
// Solid: particle layout (spacing rounded so initial_length is a whole number of
// segments), ids, tip flags, normals, the width formulas of scene.proto
// (ELLIPTIC w = w_mouth(t) sqrt(1 - (s/L)^2), UNIFORM w = w_mouth(t), 0 at the tip),
// growth at L(t) = min(max_length, initial_length + growth_speed t), received
// pressures and their trapezoidal face load (uniform p over length L: p L).
// Fluid: pressure profiles (UNIFORM p, LINEAR p (1 - s/s_front), 0 beyond the
// front), id checks, and the wetted volume. Reference for the volume: the exact
// integral of w0 sqrt(1 - (s/L)^2) over [0, a] is (w0 L / 2) (x sqrt(1 - x^2) + asin x),
// x = a / L (w0 L pi / 4 for a = L). The trapezoidal rule has error O(h^2) for a
// smooth integrand but O(h^1.5) when the integrand has a square-root endpoint
// singularity, as at the tip (J. N. Lyness and B. W. Ninham, "Numerical quadrature
// and asymptotic expansions", Math. Comp. 21 (1967) 162-178).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "hfmpm/fluid/prescribed_pressure.hpp"
#include "hfmpm/solid/prescribed_crack.hpp"

namespace {

using hfmpm::CrackGeometry;
using hfmpm::CrackPressure;
using hfmpm::TimeFunction;
using hfmpm::Vec2;
using hfmpm::fluid::PrescribedPressure;
using hfmpm::fluid::PrescribedPressureConfig;
using hfmpm::solid::PrescribedCrack;
using hfmpm::solid::PrescribedCrackConfig;

// ================================================================ solid

PrescribedCrackConfig crack_config(double initial_length = 1.0, double spacing = 0.25) {
  PrescribedCrackConfig c;
  c.mouth = Vec2(0.5, -0.25);
  c.angle_rad = 0;
  c.initial_length = initial_length;
  c.max_length = initial_length;
  c.spacing = spacing;
  c.mouth_opening = TimeFunction::constant(1e-3);
  return c;
}

CrackPressure pressure_for(std::vector<std::uint64_t> ids, std::vector<double> p) {
  CrackPressure out;
  out.ids = std::move(ids);
  out.pressure = std::move(p);
  return out;
}

TEST(PrescribedCrack, SpacingIsRoundedToAWholeNumberOfSegments) {
  struct Case {
    double length, spacing;
    std::size_t particles;
    double h;
  };
  for (const Case& c : {Case{1.0, 0.25, 5, 0.25}, Case{1.0, 0.3, 4, 1.0 / 3}, Case{1.0, 0.26, 5, 0.25},
                        Case{0.2, 0.01, 21, 0.01}, Case{1.0, 2.5, 2, 1.0}}) {
    const PrescribedCrack crack(crack_config(c.length, c.spacing));
    const auto& g = crack.geometry();
    ASSERT_EQ(g.size(), c.particles) << "spacing " << c.spacing;
    EXPECT_NEAR(crack.length(), c.length, 1e-12);
    for (std::size_t i = 1; i < g.size(); ++i) {
      EXPECT_NEAR((g.position[i] - g.position[i - 1]).norm(), c.h, 1e-12) << "spacing " << c.spacing << ", i " << i;
    }
    EXPECT_EQ(g.position[0], Vec2(0.5, -0.25));
    EXPECT_FALSE(g.grew);  // nothing appended since a publication yet
    EXPECT_EQ(crack.time(), 0.0);
  }
}

TEST(PrescribedCrack, IdsCountFromTheMouthAndOnlyTheLastParticleIsATip) {
  const PrescribedCrack crack(crack_config(1.0, 0.1));
  const auto& g = crack.geometry();
  ASSERT_EQ(g.size(), 11u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(g.ids[i], i);
    EXPECT_EQ(g.tip[i], i + 1 == g.size() ? 1 : 0) << i;
  }
  EXPECT_EQ(g.position.size(), g.size());
  EXPECT_EQ(g.normal.size(), g.size());
  EXPECT_EQ(g.width.size(), g.size());
}

TEST(PrescribedCrack, ThirtyDegreeCrackHasUnitNormalsPerpendicularAndToTheLeft) {
  auto config = crack_config(1.0, 0.125);
  config.angle_rad = std::numbers::pi / 6;
  const PrescribedCrack crack(config);
  const auto& g = crack.geometry();
  const Vec2 direction(std::sqrt(3.0) / 2, 0.5);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Vec2& n = g.normal[i];
    EXPECT_NEAR(n.norm(), 1.0, 1e-15) << i;
    EXPECT_NEAR(n.dot(direction), 0.0, 1e-15) << i;
    EXPECT_NEAR(direction.x() * n.y() - direction.y() * n.x(), 1.0, 1e-15) << i;  // "above" = left of mouth -> tip
    const Vec2 r = g.position[i] - config.mouth;
    EXPECT_NEAR(r.dot(direction), 0.125 * static_cast<double>(i), 1e-12) << i;
    EXPECT_NEAR(direction.x() * r.y() - direction.y() * r.x(), 0.0, 1e-12) << i;  // on the line
  }
}

TEST(PrescribedCrack, EllipticWidthsFollowTheFormulaAtTheCurrentTime) {
  auto config = crack_config(1.0, 0.1);
  config.mouth_opening = TimeFunction::table({0.0, 1.0}, {1e-3, 3e-3});
  PrescribedCrack crack(config);
  EXPECT_EQ(crack.geometry().width.front(), 1e-3);
  crack.advance(0.5);
  EXPECT_EQ(crack.time(), 0.5);
  const double w0 = 2e-3;
  const auto& g = crack.geometry();
  ASSERT_EQ(g.size(), 11u);
  // Arc length as the crack lays it out: h = L0 / round(L0 / spacing), accumulated from the mouth.
  const double h = 1.0 / std::round(1.0 / 0.1);
  const double length = crack.length();
  double s = 0;
  for (std::size_t i = 0; i + 1 < g.size(); ++i, s += h) {
    const double r = s / length;
    EXPECT_DOUBLE_EQ(g.width[i], w0 * std::sqrt(1.0 - r * r)) << i;
    EXPECT_DOUBLE_EQ(crack.width_at(s), g.width[i]) << i;
  }
  EXPECT_EQ(s, length);
  EXPECT_EQ(g.width.front(), w0);
  EXPECT_EQ(g.width.back(), 0.0);
  EXPECT_EQ(crack.width_at(length + 0.1), 0.0);
  const auto d = crack.diagnostics();
  EXPECT_EQ(d.mouth_opening, w0);
  EXPECT_NEAR(d.crack_length, 1.0, 1e-12);
  EXPECT_EQ(d.crack_particles, 11u);
}

TEST(PrescribedCrack, UniformWidthIsTheMouthOpeningExceptZeroAtTheTip) {
  auto config = crack_config(1.0, 0.2);
  config.profile = PrescribedCrackConfig::Profile::Uniform;
  config.mouth_opening = TimeFunction::power(1e-3, 1.0, 0.5);
  PrescribedCrack crack(config);
  for (double w : crack.geometry().width) EXPECT_EQ(w, 0.0);  // w_mouth(0) = 0
  crack.advance(4.0);                                         // w_mouth(4) = 2e-3
  const auto& g = crack.geometry();
  for (std::size_t i = 0; i + 1 < g.size(); ++i) EXPECT_DOUBLE_EQ(g.width[i], 2e-3) << i;
  EXPECT_EQ(g.width.back(), 0.0);
}

TEST(PrescribedCrack, GrowsAtTheSetSpeedWithNewIdsAndStopsAtMaxLength) {
  // L(t) = 1 + 0.5 t, h = 0.25: particle 5 + m appears at t = m / 2, up to L = 2 (9 particles).
  auto config = crack_config(1.0, 0.25);
  config.growth_speed = 0.5;
  config.max_length = 2.0;
  PrescribedCrack crack(config);
  std::size_t previous = crack.geometry().size();
  for (int k = 1; k <= 32; ++k) {  // dt = 1/8 (exact in binary), t up to 4
    crack.advance(0.125);
    const double t = 0.125 * k;
    const auto& g = crack.geometry();
    const std::size_t expected = 5 + static_cast<std::size_t>(std::min(4, k / 4));
    ASSERT_EQ(g.size(), expected) << "t = " << t;
    EXPECT_EQ(g.grew, expected > previous) << "t = " << t;
    EXPECT_EQ(crack.length(), 0.25 * static_cast<double>(expected - 1)) << "t = " << t;
    for (std::size_t i = 0; i < g.size(); ++i) {
      EXPECT_EQ(g.ids[i], i);
      EXPECT_EQ(g.tip[i], i + 1 == g.size() ? 1 : 0);
      EXPECT_EQ(g.position[i], config.mouth + Vec2(0.25 * static_cast<double>(i), 0.0));
    }
    // Widths follow the formula on the new length; the new tip is closed.
    const double r = 0.25 / crack.length();
    EXPECT_DOUBLE_EQ(g.width[1], 1e-3 * std::sqrt(1 - r * r));
    EXPECT_EQ(g.width.back(), 0.0);
    previous = g.size();
    crack.clear_grew();
    EXPECT_FALSE(crack.geometry().grew);
  }
  EXPECT_EQ(crack.length(), 2.0);
}

TEST(PrescribedCrack, GrowthStopsAtTheLastWholeSegmentBelowMaxLength) {
  auto config = crack_config(1.0, 0.25);
  config.growth_speed = 1.0;
  config.max_length = 1.9;  // not a multiple of h
  PrescribedCrack crack(config);
  crack.advance(0.7);  // L = 1.7: two particles in one step
  EXPECT_EQ(crack.geometry().size(), 7u);
  EXPECT_EQ(crack.geometry().ids.back(), 6u);
  EXPECT_TRUE(crack.geometry().grew);
  crack.advance(10.0);
  EXPECT_EQ(crack.geometry().size(), 8u);
  EXPECT_EQ(crack.length(), 1.75);
}

TEST(PrescribedCrack, UniformPressureOverTheWholeCrackGivesPTimesLength) {
  PrescribedCrack crack(crack_config(1.0, 0.1));
  const auto& ids = crack.geometry().ids;
  crack.set_pressure(pressure_for(ids, std::vector<double>(ids.size(), 2e5)));
  EXPECT_NEAR(crack.diagnostics().crack_face_load, 2e5 * crack.length(), 1e-9 * 2e5);
}

TEST(PrescribedCrack, PrefixPressureLeavesTheTailAtZero) {
  PrescribedCrack crack(crack_config(1.0, 0.25));  // s = 0, 0.25, 0.5, 0.75, 1
  crack.set_pressure(pressure_for({0, 1, 2, 3, 4}, {10, 10, 10, 10, 10}));
  EXPECT_DOUBLE_EQ(crack.diagnostics().crack_face_load, 10.0);
  // Trapezoid over (3, 2, 1, 0, 0): 0.25 * (2.5 + 1.5 + 0.5) = 1.125.
  crack.set_pressure(pressure_for({0, 1, 2}, {3, 2, 1}));
  EXPECT_DOUBLE_EQ(crack.diagnostics().crack_face_load, 1.125);
  crack.set_pressure(pressure_for({}, {}));
  EXPECT_EQ(crack.diagnostics().crack_face_load, 0.0);
}

TEST(PrescribedCrack, PressureIdsThatAreNotAPrefixThrow) {
  PrescribedCrack crack(crack_config(1.0, 0.25));
  EXPECT_THROW(crack.set_pressure(pressure_for({0, 2}, {1, 1})), std::invalid_argument);
  EXPECT_THROW(crack.set_pressure(pressure_for({1, 2, 3}, {1, 1, 1})), std::invalid_argument);
  EXPECT_THROW(crack.set_pressure(pressure_for({0, 1, 2, 3, 4, 5}, {1, 1, 1, 1, 1, 1})), std::invalid_argument);
}

// ================================================================ fluid

// A straight crack along x of `segments` equal segments, elliptic opening w0 sqrt(1 - (s/L)^2).
CrackGeometry elliptic_geometry(std::size_t segments, double length, double w0, std::uint32_t crack_id = 0) {
  CrackGeometry g;
  g.crack_id = crack_id;
  for (std::size_t i = 0; i <= segments; ++i) {
    const double s = length * static_cast<double>(i) / static_cast<double>(segments);
    const double r = s / length;
    g.ids.push_back(i);
    g.position.emplace_back(s, 0.0);
    g.normal.emplace_back(0.0, 1.0);
    g.width.push_back(w0 * std::sqrt(std::max(0.0, 1 - r * r)));
    g.tip.push_back(i == segments ? 1 : 0);
  }
  return g;
}

double exact_elliptic_volume(double length, double w0, double front) {
  const double x = front / length;
  return 0.5 * w0 * length * (x * std::sqrt(1 - x * x) + std::asin(x));
}

PrescribedPressureConfig fluid_config(double front_fraction, TimeFunction inlet = TimeFunction::constant(1e5)) {
  PrescribedPressureConfig c;
  c.inlet_pressure = std::move(inlet);
  c.front_fraction = front_fraction;
  return c;
}

double wetted_volume(double front_fraction, std::size_t segments) {
  PrescribedPressure fluid(fluid_config(front_fraction));
  fluid.set_geometry({elliptic_geometry(segments, 2.0, 1e-3)});
  return fluid.pressures().at(0).fluid_volume;
}

TEST(PrescribedPressure, WettedVolumeToTheTipConvergesAtOrderOneAndAHalf) {
  const double exact = exact_elliptic_volume(2.0, 1e-3, 2.0);
  EXPECT_DOUBLE_EQ(exact, 1e-3 * 2.0 * std::numbers::pi / 4);
  double errors[3];
  int k = 0;
  for (std::size_t n : {100u, 200u, 400u}) errors[k++] = std::abs(wetted_volume(1.0, n) - exact);
  const double order_1 = std::log2(errors[0] / errors[1]);
  const double order_2 = std::log2(errors[1] / errors[2]);
  // Observed 1.4998 for both pairs; +-0.1 tells h^1.5 from h^1 and h^2.
  EXPECT_NEAR(order_1, 1.5, 0.1);
  EXPECT_NEAR(order_2, 1.5, 0.1);
  EXPECT_LT(errors[2] / exact, 1e-3);
}

TEST(PrescribedPressure, WettedVolumeBehindAFrontConvergesAtOrderTwo) {
  // Front at 0.9 L: the integrand is smooth on [0, 0.9 L], so the trapezoidal rule is second order.
  const double exact = exact_elliptic_volume(2.0, 1e-3, 1.8);
  double errors[3];
  int k = 0;
  for (std::size_t n : {100u, 200u, 400u}) errors[k++] = std::abs(wetted_volume(0.9, n) - exact);
  for (int i = 0; i < 2; ++i) {
    const double order = std::log2(errors[i] / errors[i + 1]);
    EXPECT_NEAR(order, 2.0, 0.1) << i;  // observed 1.9999
  }
}

TEST(PrescribedPressure, WettedVolumeInterpolatesTheWidthAtAFrontBetweenParticles) {
  // Linear width 1 - s on [0, 1] with 4 segments, front at 0.6 (between 0.5 and 0.75):
  // exact integral of a linear function, 0.6 - 0.18 = 0.42.
  CrackGeometry g = elliptic_geometry(4, 1.0, 1.0);
  for (std::size_t i = 0; i < g.size(); ++i) g.width[i] = 1.0 - g.position[i].x();
  PrescribedPressure fluid(fluid_config(0.6));
  fluid.set_geometry({g});
  EXPECT_NEAR(fluid.pressures().at(0).fluid_volume, 0.42, 1e-15);
}

TEST(PrescribedPressure, UniformProfileIsTheInletPressureBehindTheFrontAndZeroBeyond) {
  PrescribedPressure fluid(fluid_config(0.5, TimeFunction::table({0.0, 1.0}, {0.0, 1e5})));
  fluid.set_geometry({elliptic_geometry(4, 1.0, 1e-3, 7)});  // s = 0, 0.25, 0.5, 0.75, 1
  fluid.advance(0.25);
  const auto p = fluid.pressures();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].crack_id, 7u);
  EXPECT_EQ(p[0].ids, (std::vector<std::uint64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(p[0].front_position, 0.5);
  EXPECT_EQ(p[0].pressure, (std::vector<double>{2.5e4, 2.5e4, 2.5e4, 0, 0}));
  EXPECT_EQ(fluid.diagnostics().inlet_pressure, 2.5e4);
  EXPECT_EQ(fluid.diagnostics().front_position, 0.5);
}

TEST(PrescribedPressure, LinearProfileFallsToZeroAtTheFront) {
  auto config = fluid_config(0.8);
  config.profile = PrescribedPressureConfig::Profile::Linear;
  PrescribedPressure fluid(config);
  fluid.set_geometry({elliptic_geometry(5, 1.0, 1e-3)});  // s = 0, 0.2, ..., 1; front 0.8
  const auto p = fluid.pressures().at(0).pressure;
  ASSERT_EQ(p.size(), 6u);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(p[i], 1e5 * (1 - 0.2 * static_cast<double>(i) / 0.8), 1e-9) << i;
  EXPECT_NEAR(p[4], 0.0, 1e-9);
  EXPECT_EQ(p[5], 0.0);
}

TEST(PrescribedPressure, NegativeInletPressureIsClampedToZero) {
  PrescribedPressure fluid(fluid_config(1.0, TimeFunction::constant(-5.0)));
  fluid.set_geometry({elliptic_geometry(4, 1.0, 1e-3)});
  const auto p = fluid.pressures();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].pressure, std::vector<double>(5, 0.0));
}

TEST(PrescribedPressure, IdsThatAreNotAPrefixOfTheOldIdsThrow) {
  PrescribedPressure fluid(fluid_config(1.0));
  const auto g = elliptic_geometry(4, 1.0, 1e-3);
  fluid.set_geometry({g});
  auto changed = g;
  changed.ids[4] = 9;
  EXPECT_THROW(fluid.set_geometry({changed}), std::invalid_argument);
  auto shorter = elliptic_geometry(3, 0.75, 1e-3);
  EXPECT_THROW(fluid.set_geometry({shorter}), std::invalid_argument);
  // A refused geometry leaves the previous one in place.
  EXPECT_EQ(fluid.pressures().at(0).ids, g.ids);
  // Another crack id is a new crack, not a change.
  EXPECT_NO_THROW(fluid.set_geometry({elliptic_geometry(3, 0.75, 1e-3, 1)}));
  EXPECT_EQ(fluid.pressures().size(), 2u);
}

TEST(PrescribedPressure, GrewFlagMustMatchAppendedIds) {
  PrescribedPressure fluid(fluid_config(1.0));
  fluid.set_geometry({elliptic_geometry(4, 1.0, 1e-3)});
  auto longer = elliptic_geometry(5, 1.25, 1e-3);
  longer.grew = false;
  EXPECT_THROW(fluid.set_geometry({longer}), std::invalid_argument);
  auto same = elliptic_geometry(4, 1.0, 1e-3);
  same.grew = true;
  EXPECT_THROW(fluid.set_geometry({same}), std::invalid_argument);
  longer.grew = true;
  EXPECT_NO_THROW(fluid.set_geometry({longer}));
  EXPECT_EQ(fluid.pressures().at(0).pressure.size(), 6u);
}

TEST(PrescribedPressure, InletFluxIsTheVolumeChangeOverTheStep) {
  PrescribedPressure fluid(fluid_config(1.0));
  const double dt = 0.01;
  fluid.set_geometry({elliptic_geometry(8, 1.0, 1e-3)});
  const double v1 = fluid.pressures().at(0).fluid_volume;
  EXPECT_GT(v1, 0.0);
  fluid.advance(dt);
  // From an empty crack: the time integral of the flux is the injected volume.
  EXPECT_DOUBLE_EQ(fluid.pressures().at(0).inlet_flux, v1 / dt);
  fluid.set_geometry({elliptic_geometry(8, 1.0, 2e-3)});
  const double v2 = fluid.pressures().at(0).fluid_volume;
  EXPECT_DOUBLE_EQ(v2, 2 * v1);
  fluid.advance(dt);
  EXPECT_DOUBLE_EQ(fluid.pressures().at(0).inlet_flux, (v2 - v1) / dt);
  fluid.advance(dt);  // no new geometry: no volume change
  EXPECT_EQ(fluid.pressures().at(0).inlet_flux, 0.0);
  const auto d = fluid.diagnostics();
  EXPECT_EQ(d.fluid_volume, v2);
  EXPECT_EQ(d.injected_volume, v2);
  EXPECT_DOUBLE_EQ(fluid.time(), 3 * dt);
}

TEST(PrescribedPressure, DiagnosticsSumVolumesAndTakeTheFarthestFront) {
  PrescribedPressure fluid(fluid_config(0.5));
  fluid.set_geometry({elliptic_geometry(10, 1.0, 1e-3, 0), elliptic_geometry(10, 3.0, 1e-3, 1)});
  const auto p = fluid.pressures();
  ASSERT_EQ(p.size(), 2u);
  const auto d = fluid.diagnostics();
  EXPECT_DOUBLE_EQ(d.fluid_volume, p[0].fluid_volume + p[1].fluid_volume);
  EXPECT_DOUBLE_EQ(d.front_position, 1.5);
}

}  // namespace
