// Unit tests of hfmpm::TimeFunction (proto/include/hfmpm/time_function.hpp) and of
// hfmpm::proto::to_time_function, which builds one from a scene's TimeFunction.
// Checks: a constant is the same at every time; a table interpolates linearly
// between its points and is constant (clamped) outside them; a ramp is a
// 2-point table; a power law is scale * (t / t_ref)^exponent for t > 0 and 0
// for t <= 0 (scene.proto, message TimeFunction.Power). Expected values are
// computed by hand from those definitions.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/time_function.hpp"

namespace {

using hfmpm::TimeFunction;
using hfmpm::proto::to_time_function;

TEST(TimeFunction, ConstantIsTheSameAtEveryTime) {
  const auto f = TimeFunction::constant(2.5e-3);
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Constant);
  for (double t : {-10.0, 0.0, 1e-9, 1.0, 1e6}) EXPECT_EQ(f(t), 2.5e-3) << "t = " << t;
}

TEST(TimeFunction, DefaultConstructedIsZero) {
  const TimeFunction f;
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Constant);
  EXPECT_EQ(f(0.0), 0.0);
  EXPECT_EQ(f(3.0), 0.0);
}

TEST(TimeFunction, TableInterpolatesLinearlyBetweenPoints) {
  // (0, 0) -> (1, 10) -> (3, 4)
  const auto f = TimeFunction::table({0.0, 1.0, 3.0}, {0.0, 10.0, 4.0});
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Table);
  EXPECT_DOUBLE_EQ(f(0.25), 2.5);
  EXPECT_DOUBLE_EQ(f(0.5), 5.0);
  EXPECT_DOUBLE_EQ(f(2.0), 7.0);  // halfway from 10 to 4
  EXPECT_DOUBLE_EQ(f(2.5), 5.5);  // three quarters of the way
  // At the points themselves, exactly the point values.
  EXPECT_EQ(f(0.0), 0.0);
  EXPECT_EQ(f(1.0), 10.0);
  EXPECT_EQ(f(3.0), 4.0);
}

TEST(TimeFunction, TableIsClampedOutsideItsRange) {
  const auto f = TimeFunction::table({1.0, 2.0}, {5.0, 7.0});
  EXPECT_EQ(f(0.0), 5.0);
  EXPECT_EQ(f(-100.0), 5.0);
  EXPECT_EQ(f(2.0 + 1e-12), 7.0);
  EXPECT_EQ(f(1e9), 7.0);
  EXPECT_EQ(f(-std::numeric_limits<double>::infinity()), 5.0);
  EXPECT_EQ(f(std::numeric_limits<double>::infinity()), 7.0);
}

TEST(TimeFunction, TableWithUnevenSpacingPicksTheRightInterval) {
  // Many intervals of different lengths: each query must use its own bracket.
  const std::vector<double> t = {0.0, 0.1, 0.15, 1.0, 4.0, 4.5};
  const std::vector<double> v = {1.0, 2.0, 0.0, 3.0, 3.0, -1.0};
  const auto f = TimeFunction::table(t, v);
  for (std::size_t i = 1; i < t.size(); ++i) {
    for (double a : {0.1, 0.5, 0.9}) {
      const double ti = t[i - 1] + a * (t[i] - t[i - 1]);
      EXPECT_NEAR(f(ti), v[i - 1] + a * (v[i] - v[i - 1]), 1e-12) << "interval " << i << ", a = " << a;
    }
  }
}

TEST(TimeFunction, PowerLawValues) {
  // v = 2 * (t / 0.5)^(1/3)
  const auto f = TimeFunction::power(2.0, 0.5, 1.0 / 3.0);
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Power);
  EXPECT_DOUBLE_EQ(f(0.5), 2.0);
  EXPECT_NEAR(f(4.0), 4.0, 1e-14);             // 8^(1/3) = 2
  EXPECT_NEAR(f(0.5 / 27), 2.0 / 3.0, 1e-14);  // (1/27)^(1/3) = 1/3
  EXPECT_EQ(f(0.0), 0.0);
  EXPECT_EQ(f(-1.0), 0.0);

  const auto linear = TimeFunction::power(3.0, 1.0, 1.0);
  EXPECT_DOUBLE_EQ(linear(2.5), 7.5);
  const auto square = TimeFunction::power(1.0, 2.0, 2.0);
  EXPECT_DOUBLE_EQ(square(6.0), 9.0);
}

TEST(TimeFunction, PowerLawWithZeroExponentIsAStepAtZero) {
  // Exponent 0 (allowed, >= 0): scale for t > 0, 0 for t <= 0 (by definition, not 0^0).
  const auto f = TimeFunction::power(5.0, 1.0, 0.0);
  EXPECT_EQ(f(0.0), 0.0);
  EXPECT_EQ(f(1e-12), 5.0);
  EXPECT_EQ(f(100.0), 5.0);
}

// ------------------------------------------------------- from the scene message

TEST(ToTimeFunction, Constant) {
  hfmpm::scene::TimeFunction s;
  s.set_constant(1.5e5);
  const auto f = to_time_function(s);
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Constant);
  EXPECT_EQ(f(0.0), 1.5e5);
  EXPECT_EQ(f(7.0), 1.5e5);
}

TEST(ToTimeFunction, RampIsLinearBetweenItsEndsAndClampedOutside) {
  hfmpm::scene::TimeFunction s;
  auto* ramp = s.mutable_ramp();
  ramp->set_t0(1.0);
  ramp->set_v0(2.0);
  ramp->set_t1(3.0);
  ramp->set_v1(6.0);
  const auto f = to_time_function(s);
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Table);
  EXPECT_EQ(f(0.0), 2.0);
  EXPECT_EQ(f(1.0), 2.0);
  EXPECT_DOUBLE_EQ(f(1.5), 3.0);
  EXPECT_DOUBLE_EQ(f(2.0), 4.0);
  EXPECT_EQ(f(3.0), 6.0);
  EXPECT_EQ(f(10.0), 6.0);
}

TEST(ToTimeFunction, RampUsesTheSchemaDefaultsForT0AndV0) {
  // scene.proto: Ramp.t0 and Ramp.v0 default to 0.
  hfmpm::scene::TimeFunction s;
  s.mutable_ramp()->set_t1(0.5);
  s.mutable_ramp()->set_v1(1.0e5);
  const auto f = to_time_function(s);
  EXPECT_EQ(f(-1.0), 0.0);
  EXPECT_EQ(f(0.0), 0.0);
  EXPECT_DOUBLE_EQ(f(0.25), 0.5e5);
  EXPECT_EQ(f(0.5), 1.0e5);
  EXPECT_EQ(f(2.0), 1.0e5);
}

TEST(ToTimeFunction, Table) {
  hfmpm::scene::TimeFunction s;
  for (double t : {0.0, 1.0, 2.0}) s.mutable_table()->add_t(t);
  for (double v : {0.0, 4.0, 2.0}) s.mutable_table()->add_v(v);
  const auto f = to_time_function(s);
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Table);
  EXPECT_DOUBLE_EQ(f(0.5), 2.0);
  EXPECT_DOUBLE_EQ(f(1.5), 3.0);
  EXPECT_EQ(f(-1.0), 0.0);
  EXPECT_EQ(f(5.0), 2.0);
}

TEST(ToTimeFunction, Power) {
  hfmpm::scene::TimeFunction s;
  s.mutable_power()->set_scale(1.0e-3);
  s.mutable_power()->set_t_ref(2.0);
  s.mutable_power()->set_exponent(0.5);
  const auto f = to_time_function(s);
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Power);
  EXPECT_DOUBLE_EQ(f(8.0), 2.0e-3);  // sqrt(8 / 2) = 2
  EXPECT_DOUBLE_EQ(f(2.0), 1.0e-3);
  EXPECT_EQ(f(0.0), 0.0);
}

TEST(ToTimeFunction, PowerUsesTheSchemaDefaultTRef) {
  // scene.proto: Power.t_ref defaults to 1.
  hfmpm::scene::TimeFunction s;
  s.mutable_power()->set_scale(3.0);
  s.mutable_power()->set_exponent(2.0);
  const auto f = to_time_function(s);
  EXPECT_DOUBLE_EQ(f(2.0), 12.0);
}

TEST(ToTimeFunction, UnsetKindIsZero) {
  const auto f = to_time_function(hfmpm::scene::TimeFunction{});
  EXPECT_EQ(f.kind(), TimeFunction::Kind::Constant);
  EXPECT_EQ(f(1.0), 0.0);
}

}  // namespace
