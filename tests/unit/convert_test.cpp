// Unit tests of the converters between wire messages and plain types
// (proto/include/hfmpm/proto/convert.hpp): exact round trips, and every
// invalid array named in the error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "message_samples.hpp"
#include "test_support.hpp"

namespace {

// ------------------------------------------------------------ CrackGeometry

TEST(CrackGeometryConvert, RoundTripIsExact) {
  const auto in = sample_geometry();
  protocol::CrackState::Crack m;
  hfmpm::proto::to_proto(in, &m);
  EXPECT_EQ(m.ids_size(), 4);
  EXPECT_EQ(m.x(3), in.position[3].x());
  EXPECT_TRUE(m.tip(3));
  EXPECT_FALSE(m.tip(0));
  const auto out = hfmpm::proto::from_proto(m);
  EXPECT_EQ(out.crack_id, in.crack_id);
  EXPECT_EQ(out.ids, in.ids);
  EXPECT_EQ(out.position, in.position);
  EXPECT_EQ(out.normal, in.normal);
  EXPECT_EQ(out.width, in.width);
  EXPECT_EQ(out.tip, in.tip);
  EXPECT_EQ(out.grew, in.grew);
}

TEST(CrackGeometryConvert, ToProtoReplacesPreviousContent) {
  protocol::CrackState::Crack m;
  hfmpm::proto::to_proto(sample_geometry(), &m);
  hfmpm::proto::to_proto(sample_geometry(), &m);
  EXPECT_TRUE(MessageDifferencer::Equals(m, sample_crack_message()));
}

TEST(CrackGeometryConvert, MismatchedArrayLengthNamesTheArray) {
  auto m = sample_crack_message();
  m.mutable_width()->RemoveLast();
  const std::string text = from_proto_error(m);
  EXPECT_THAT(text, HasSubstr("'width'"));
  EXPECT_THAT(text, HasSubstr("3 entries"));
  EXPECT_THAT(text, HasSubstr("crack 3"));
  auto long_x = sample_crack_message();
  long_x.add_x(0.0);
  EXPECT_THAT(from_proto_error(long_x), HasSubstr("'x'"));
  auto short_ny = sample_crack_message();
  short_ny.mutable_ny()->RemoveLast();
  EXPECT_THAT(from_proto_error(short_ny), HasSubstr("'ny'"));
  auto no_tip = sample_crack_message();
  no_tip.clear_tip();
  EXPECT_THAT(from_proto_error(no_tip), HasSubstr("'tip'"));
}

TEST(CrackGeometryConvert, NaNCoordinateIsNamed) {
  auto m = sample_crack_message();
  m.set_y(2, kNaN);
  const std::string text = from_proto_error(m);
  EXPECT_THAT(text, HasSubstr("y[2]"));
  EXPECT_THAT(text, HasSubstr("not finite"));
  auto inf_width = sample_crack_message();
  inf_width.set_width(1, std::numeric_limits<double>::infinity());
  EXPECT_THAT(from_proto_error(inf_width), HasSubstr("width[1]"));
}

TEST(CrackGeometryConvert, DuplicateIdIsNamed) {
  auto m = sample_crack_message();
  m.set_ids(3, 11);
  const std::string text = from_proto_error(m);
  EXPECT_THAT(text, HasSubstr("id 11 appears twice"));
  EXPECT_THAT(text, HasSubstr("index 3"));
}

TEST(CrackGeometryConvert, NonUnitNormalIsNamed) {
  auto m = sample_crack_message();
  m.set_nx(1, 0.0);
  m.set_ny(1, 2.0);
  const std::string text = from_proto_error(m);
  EXPECT_THAT(text, HasSubstr("normal 1"));
  EXPECT_THAT(text, HasSubstr("unit"));
  auto zero = sample_crack_message();
  zero.set_nx(0, 0.0);
  zero.set_ny(0, 0.0);
  EXPECT_THAT(from_proto_error(zero), HasSubstr("normal 0"));
}

TEST(CrackGeometryConvert, NegativeWidthIsNamed) {
  auto m = sample_crack_message();
  m.set_width(2, -1.0e-6);
  const std::string text = from_proto_error(m);
  EXPECT_THAT(text, HasSubstr("width[2]"));
  EXPECT_THAT(text, HasSubstr(">= 0"));
}

// The tip closure's data (CrackState tip_modulus_pa, resolution_m): carried
// exactly, absent as 0, and a negative or non-finite value named.
TEST(CrackGeometryConvert, TipModulusAndResolutionRoundTripAndAreChecked) {
  auto in = sample_geometry();
  EXPECT_EQ(hfmpm::proto::from_proto([&] {
              protocol::CrackState::Crack m;
              hfmpm::proto::to_proto(in, &m);
              return m;
            }())
                .tip_modulus,
            0.0);
  in.tip_modulus = 1.0666666666666667e7;
  in.resolution = 0.035;
  protocol::CrackState::Crack m;
  hfmpm::proto::to_proto(in, &m);
  const auto out = hfmpm::proto::from_proto(m);
  EXPECT_EQ(out.tip_modulus, in.tip_modulus);
  EXPECT_EQ(out.resolution, in.resolution);
  m.set_tip_modulus_pa(-1);
  EXPECT_THAT(from_proto_error(m), HasSubstr("tip_modulus_pa = -1"));
  m.set_tip_modulus_pa(1e7);
  m.set_resolution_m(std::numeric_limits<double>::infinity());
  EXPECT_THAT(from_proto_error(m), HasSubstr("resolution_m = inf; it must be finite and >= 0"));
}

TEST(CrackGeometryConvert, FewerThanTwoParticlesIsRejected) {
  auto g = sample_geometry();
  g.crack_id = 5;
  for (auto* v : {&g.position, &g.normal}) v->resize(1);
  g.ids.resize(1);
  g.width.resize(1);
  g.tip.resize(1);
  protocol::CrackState::Crack one;
  hfmpm::proto::to_proto(g, &one);
  std::string text = from_proto_error(one);
  EXPECT_THAT(text, HasSubstr("at least 2"));
  EXPECT_THAT(text, HasSubstr("got 1"));
  EXPECT_THAT(text, HasSubstr("crack 5"));
  EXPECT_THAT(from_proto_error(protocol::CrackState::Crack{}), HasSubstr("got 0"));
}

// ------------------------------------------------------------ CrackPressure

TEST(CrackPressureConvert, RoundTripIsExact) {
  const auto in = sample_pressure();
  protocol::FluidState::Crack m;
  hfmpm::proto::to_proto(in, &m);
  const auto out = hfmpm::proto::from_proto(m);
  EXPECT_EQ(out.crack_id, in.crack_id);
  EXPECT_EQ(out.ids, in.ids);
  EXPECT_EQ(out.pressure, in.pressure);
  EXPECT_EQ(out.front_position, in.front_position);
  EXPECT_EQ(out.inlet_flux, in.inlet_flux);
  EXPECT_EQ(out.fluid_volume, in.fluid_volume);
}

TEST(CrackPressureConvert, StiffnessAndWidthRoundTripAndAreChecked) {
  auto in = sample_pressure();
  in.stiffness = {2.0e9, 1.5e9, 0.0, 0.0};
  in.width = {1e-3, 8e-4, 2e-4, 0.0};
  protocol::FluidState::Crack m;
  hfmpm::proto::to_proto(in, &m);
  const auto out = hfmpm::proto::from_proto(m);
  EXPECT_EQ(out.stiffness, in.stiffness);
  EXPECT_EQ(out.width, in.width);
  // Optional: absent in a message without them.
  protocol::FluidState::Crack plain;
  hfmpm::proto::to_proto(sample_pressure(), &plain);
  EXPECT_TRUE(hfmpm::proto::from_proto(plain).stiffness.empty());
  // Both or neither, one per id, finite, >= 0.
  auto only_stiffness = m;
  only_stiffness.clear_width();
  EXPECT_THAT(from_proto_error(only_stiffness), HasSubstr("'width'"));
  auto short_stiffness = m;
  short_stiffness.mutable_stiffness()->RemoveLast();
  EXPECT_THAT(from_proto_error(short_stiffness), HasSubstr("'stiffness'"));
  auto negative = m;
  negative.set_stiffness(1, -1.0);
  EXPECT_THAT(from_proto_error(negative), HasSubstr("stiffness (-dp/dw) must be >= 0"));
  auto nan_width = m;
  nan_width.set_width(2, kNaN);
  EXPECT_THAT(from_proto_error(nan_width), HasSubstr("width[2]"));
}

TEST(CrackPressureConvert, LengthMismatchNamesPressure) {
  protocol::FluidState::Crack m;
  hfmpm::proto::to_proto(sample_pressure(), &m);
  m.mutable_pressure()->RemoveLast();
  const std::string text = from_proto_error(m);
  EXPECT_THAT(text, HasSubstr("'pressure'"));
  EXPECT_THAT(text, HasSubstr("FluidState crack 3"));
}

TEST(CrackPressureConvert, NaNPressureIsNamed) {
  protocol::FluidState::Crack m;
  hfmpm::proto::to_proto(sample_pressure(), &m);
  m.set_pressure(1, kNaN);
  EXPECT_THAT(from_proto_error(m), HasSubstr("pressure[1]"));
  protocol::FluidState::Crack front;
  hfmpm::proto::to_proto(sample_pressure(), &front);
  front.set_front_position(kNaN);
  EXPECT_THAT(from_proto_error(front), HasSubstr("front_position"));
}

TEST(CrackPressureConvert, DuplicateIdsAreNamed) {
  protocol::FluidState::Crack m;
  hfmpm::proto::to_proto(sample_pressure(), &m);
  m.set_ids(0, 40);
  EXPECT_THAT(from_proto_error(m), HasSubstr("id 40 appears twice"));
}

// ------------------------------------------------------------ Diagnostics

TEST(DiagnosticsConvert, RoundTripIsExact) {
  const auto message = sample_diagnostics();
  const auto plain = hfmpm::proto::from_proto(message);
  EXPECT_EQ(plain.kinetic_energy, 1.25);
  EXPECT_EQ(plain.crack_length, 0.75);
  EXPECT_EQ(plain.mouth_opening, 1.0e-3);
  EXPECT_EQ(plain.crack_face_load, -3.5e4);
  EXPECT_EQ(plain.inlet_pressure, 2.0e5);
  EXPECT_EQ(plain.injected_volume, 6.0e-4);
  EXPECT_EQ(plain.fluid_volume, 5.5e-4);
  EXPECT_EQ(plain.front_position, 0.6);
  EXPECT_EQ(plain.crack_particles, 101u);
  EXPECT_EQ(plain.fluid_particles, 77u);
  EXPECT_EQ(plain.coupling_lag, 1.5e3);
  EXPECT_EQ(plain.strain_energy, 2.5);
  protocol::Diagnostics back;
  hfmpm::proto::to_proto(plain, &back);
  EXPECT_TRUE(MessageDifferencer::Equals(back, message)) << back.ShortDebugString();
}

}  // namespace
