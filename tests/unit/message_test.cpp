// Unit tests of the wire codec (proto/include/hfmpm/proto/envelope.hpp) and of the
// converters between wire messages and plain types (proto/include/hfmpm/proto/convert.hpp).
// Checks: every Envelope body survives encode -> decode field by field
// (MessageDifferencer); decode throws ProtocolError naming the sender for bytes
// that do not parse, an envelope without a body, and unknown fields; the
// converters round-trip exactly and from_proto rejects each broken invariant
// of protocol.proto (CrackState.Crack, FluidState.Crack) with a message naming it.
#include <gmock/gmock.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/proto/envelope.hpp"
#include "test_support.hpp"

namespace {

namespace protocol = hfmpm::protocol;
using google::protobuf::util::MessageDifferencer;
using hfmpm::proto::ProtocolError;
using ::testing::HasSubstr;

constexpr const char* kFrom = "solid (ipc:///tmp/x/control)";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

protocol::Envelope round_trip(const protocol::Envelope& in) {
  const std::string bytes = hfmpm::proto::encode(in);
  return hfmpm::proto::decode(bytes.data(), bytes.size(), kFrom);
}

// Expects decode to throw ProtocolError; returns its text.
std::string decode_error(const std::string& bytes) {
  try {
    hfmpm::proto::decode(bytes.data(), bytes.size(), kFrom);
  } catch (const ProtocolError& e) {
    return e.what();
  }
  ADD_FAILURE() << "decode accepted " << bytes.size() << " bytes";
  return "";
}

template <class F>
std::string from_proto_error(const F& message) {
  try {
    hfmpm::proto::from_proto(message);
  } catch (const ProtocolError& e) {
    return e.what();
  }
  ADD_FAILURE() << "from_proto accepted " << message.ShortDebugString();
  return "";
}

protocol::Diagnostics sample_diagnostics() {
  protocol::Diagnostics d;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      "kinetic_energy: 1.25 crack_length: 0.75 mouth_opening: 1.0e-3 crack_face_load: -3.5e4 inlet_pressure: 2.0e5 "
      "injected_volume: 6.0e-4 fluid_volume: 5.5e-4 front_position: 0.6 crack_particles: 101 fluid_particles: 77",
      &d));
  return d;
}

// A straight crack of 4 particles along x with an elliptic-looking opening.
hfmpm::CrackGeometry sample_geometry() {
  hfmpm::CrackGeometry g;
  g.crack_id = 3;
  g.ids = {10, 11, 12, 40};
  const double c = std::cos(0.3), s = std::sin(0.3);
  for (int i = 0; i < 4; ++i) {
    g.position.emplace_back(0.1 + 0.25 * i * c, -0.2 + 0.25 * i * s);
    g.normal.emplace_back(-s, c);
  }
  g.width = {1.0e-3, 0.9e-3, 0.6e-3, 0.0};
  g.tip = {0, 0, 0, 1};
  g.grew = true;
  return g;
}

hfmpm::CrackPressure sample_pressure() {
  hfmpm::CrackPressure p;
  p.crack_id = 3;
  p.ids = {10, 11, 12, 40};
  p.pressure = {1.0e5, 7.5e4, 0.0, 0.0};
  p.front_position = 0.4;
  p.inlet_flux = 2.5e-5;
  p.fluid_volume = 3.0e-4;
  return p;
}

protocol::CrackState::Crack sample_crack_message() {
  protocol::CrackState::Crack m;
  hfmpm::proto::to_proto(sample_geometry(), &m);
  return m;
}

// ------------------------------------------------------------ envelope bodies

class EnvelopeRoundTrip : public ::testing::Test {
 protected:
  void expect_round_trip(const protocol::Envelope& in, const char* body) {
    ASSERT_NE(in.body_case(), protocol::Envelope::BODY_NOT_SET);
    const protocol::Envelope out = round_trip(in);
    EXPECT_TRUE(MessageDifferencer::Equals(in, out))
        << "sent:     " << in.ShortDebugString() << "\nreceived: " << out.ShortDebugString();
    EXPECT_EQ(out.body_case(), in.body_case());
    EXPECT_EQ(hfmpm::proto::body_name(out), body);
  }
};

TEST_F(EnvelopeRoundTrip, Hello) {
  protocol::Envelope e;
  auto* m = e.mutable_hello();
  m->set_role(protocol::FLUID);
  m->set_protocol_version(hfmpm::proto::kProtocolVersion);
  m->set_implementation("hfmpm-prescribed-fluid");
  m->set_implementation_version("0.1.0");
  m->add_capabilities("crack-growth");
  m->add_capabilities("output-hdf5");
  m->set_host("node-17");
  m->set_pid(123456789012LL);
  expect_round_trip(e, "hello");
}

TEST_F(EnvelopeRoundTrip, WelcomeWithAnEmbeddedScene) {
  protocol::Envelope e;
  auto* m = e.mutable_welcome();
  m->set_protocol_version(1);
  m->set_run_id("run-2024-abc");
  m->mutable_data_plane()->set_mode(protocol::DataPlane::BIND);
  m->mutable_data_plane()->set_endpoint("ipc:///tmp/hfmpm/data");
  m->set_output_dir("/tmp/out/prescribed");
  const std::string scene_text = hfmpm::test::read_file(hfmpm::test::source("scenarios/prescribed.scene"));
  ASSERT_TRUE(google::protobuf::TextFormat::ParseFromString(scene_text, m->mutable_scene()));
  m->mutable_scene()->mutable_coupling()->add_solid_args("--verbose");
  ASSERT_TRUE(m->scene().solid().has_prescribed_crack());
  ASSERT_TRUE(m->scene().fluid().prescribed_pressure().inlet_pressure_pa().has_ramp());
  expect_round_trip(e, "welcome");
  // proto2 presence survives: an unset field with a default stays unset.
  const auto out = round_trip(e);
  EXPECT_FALSE(out.welcome().scene().coupling().has_heartbeat_timeout_s());
  EXPECT_TRUE(out.welcome().scene().time().has_safety_factor());
}

TEST_F(EnvelopeRoundTrip, Reject) {
  protocol::Envelope e;
  e.mutable_reject()->set_reason("protocol version 2 is not supported; this coupler speaks 1");
  e.mutable_reject()->set_coupler_protocol_version(1);
  expect_round_trip(e, "reject");
}

TEST_F(EnvelopeRoundTrip, Listening) {
  protocol::Envelope e;
  e.mutable_listening()->set_data_endpoint("tcp://10.0.0.5:45123");
  expect_round_trip(e, "listening");
}

TEST_F(EnvelopeRoundTrip, ReadyWithInfiniteStableStep) {
  protocol::Envelope e;
  e.mutable_ready()->set_stable_dt(std::numeric_limits<double>::infinity());
  *e.mutable_ready()->mutable_diagnostics() = sample_diagnostics();
  expect_round_trip(e, "ready");
  EXPECT_TRUE(std::isinf(round_trip(e).ready().stable_dt()));
}

TEST_F(EnvelopeRoundTrip, StepCommand) {
  protocol::Envelope e;
  auto* m = e.mutable_step_command();
  m->set_first_step(1ULL << 40);
  m->set_num_steps(20);
  m->set_t(0.123456789012345);
  m->set_dt(1.0e-4);
  m->set_write_output(true);
  m->set_output_frame(17);
  expect_round_trip(e, "step_command");
}

TEST_F(EnvelopeRoundTrip, StepReport) {
  protocol::Envelope e;
  auto* m = e.mutable_step_report();
  m->set_step(2000);
  m->set_t(0.2);
  m->set_stable_dt(2.0e-4);
  m->set_status(protocol::StepReport::DONE);
  *m->mutable_diagnostics() = sample_diagnostics();
  m->set_compute_s(0.031);
  m->set_exchange_s(0.002);
  expect_round_trip(e, "step_report");
}

TEST_F(EnvelopeRoundTrip, DataFrameWithCrackState) {
  protocol::Envelope e;
  auto* m = e.mutable_data();
  m->set_step(40);
  m->set_t(0.004);
  *m->mutable_crack()->add_cracks() = sample_crack_message();
  auto second = sample_crack_message();
  second.set_crack_id(4);
  second.set_grew(false);
  *m->mutable_crack()->add_cracks() = second;
  expect_round_trip(e, "data");
  const auto out = round_trip(e);
  ASSERT_EQ(out.data().payload_case(), protocol::DataFrame::kCrack);
  EXPECT_EQ(out.data().crack().cracks_size(), 2);
}

TEST_F(EnvelopeRoundTrip, DataFrameWithFluidState) {
  protocol::Envelope e;
  auto* m = e.mutable_data();
  m->set_step(41);
  m->set_t(0.0041);
  hfmpm::proto::to_proto(sample_pressure(), m->mutable_fluid()->add_cracks());
  expect_round_trip(e, "data");
  EXPECT_EQ(round_trip(e).data().payload_case(), protocol::DataFrame::kFluid);
}

TEST_F(EnvelopeRoundTrip, Heartbeat) {
  protocol::Envelope e;
  e.mutable_heartbeat()->set_role(protocol::SOLID);
  e.mutable_heartbeat()->set_sequence(99);
  e.mutable_heartbeat()->set_step(12345);
  e.mutable_heartbeat()->set_waiting_for_peer(true);
  expect_round_trip(e, "heartbeat");
}

TEST_F(EnvelopeRoundTrip, Shutdown) {
  protocol::Envelope e;
  e.mutable_shutdown()->set_reason("fluid stopped responding");
  e.mutable_shutdown()->set_error(true);
  expect_round_trip(e, "shutdown");
}

TEST_F(EnvelopeRoundTrip, Error) {
  protocol::Envelope e;
  auto* m = e.mutable_error();
  m->set_who(protocol::FLUID);
  m->set_what("numerics");
  m->set_where("step 120, crack 0, particle 37");
  m->set_message("pressure is NaN; reduce safety_factor");
  m->set_step(120);
  expect_round_trip(e, "error");
}

TEST_F(EnvelopeRoundTrip, BodyWithOnlyDefaultsStillHasABody) {
  // A Heartbeat with all fields zero is 2 bytes (tag + length 0), not an empty envelope.
  protocol::Envelope e;
  e.mutable_heartbeat();
  EXPECT_EQ(hfmpm::proto::encode(e).size(), 2u);
  expect_round_trip(e, "heartbeat");
}

// ------------------------------------------------------------ decode failures

TEST(Decode, TruncatedVarintThrowsNamingTheSender) {
  const std::string text = decode_error(std::string("\xFF\xFF", 2));
  EXPECT_THAT(text, HasSubstr(kFrom));
  EXPECT_THAT(text, HasSubstr("2 bytes"));
}

TEST(Decode, EmptyEnvelopeThrowsNamingTheSender) {
  const std::string text = decode_error("");
  EXPECT_THAT(text, HasSubstr(kFrom));
  EXPECT_THAT(text, HasSubstr("no body"));
}

TEST(Decode, UnknownTopLevelFieldThrowsNamingTheSender) {
  // Field 99, varint, value 1: tag (99 << 3) | 0 = 792 = 0x98 0x06.
  const std::string text = decode_error(std::string("\x98\x06\x01", 3));
  EXPECT_THAT(text, HasSubstr(kFrom));
  EXPECT_THAT(text, HasSubstr("does not define"));
}

TEST(Decode, UnknownFieldBesideAValidBodyThrows) {
  protocol::Envelope e;
  e.mutable_shutdown()->set_reason("x");
  const std::string bytes = hfmpm::proto::encode(e) + std::string("\x98\x06\x01", 3);
  EXPECT_THAT(decode_error(bytes), HasSubstr(kFrom));
}

TEST(Decode, UnknownFieldInsideABodyThrows) {
  // envelope.h: decode throws for bytes that "carry fields this version does not
  // know" -- not only at the top level. Hello { field 99 = 1 }: 0x0A (field 1,
  // length-delimited), length 3, then 0x98 0x06 0x01.
  const std::string text = decode_error(std::string("\x0A\x03\x98\x06\x01", 5));
  EXPECT_THAT(text, HasSubstr(kFrom));
}

TEST(Decode, InvalidWireTypeGarbageThrowsForEverySeed) {
  // Random bytes behind a first byte with wire type 7 (which does not exist) never parse.
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::string bytes(1 + rng() % 64, '\0');
    for (auto& b : bytes) b = static_cast<char>(rng() & 0xFF);
    bytes[0] = static_cast<char>((static_cast<unsigned>(1 + rng() % 15) << 3) | 7u);
    EXPECT_THAT(decode_error(bytes), HasSubstr(kFrom)) << "seed " << seed;
  }
}

TEST(Decode, RandomBytesEitherThrowProtocolErrorOrGiveABodyWithoutUnknownFields) {
  // Nothing read from a socket is trusted: no other exception, no crash, and
  // whatever is accepted is a known body that re-encodes to a parseable frame.
  int rejected = 0;
  for (unsigned seed = 1; seed <= 2000; ++seed) {
    std::mt19937 rng(seed);
    std::string bytes(rng() % 48, '\0');
    for (auto& b : bytes) b = static_cast<char>(rng() & 0xFF);
    try {
      const auto e = hfmpm::proto::decode(bytes.data(), bytes.size(), kFrom);
      EXPECT_NE(e.body_case(), protocol::Envelope::BODY_NOT_SET) << "seed " << seed;
      EXPECT_TRUE(e.GetReflection()->GetUnknownFields(e).empty()) << "seed " << seed;
      EXPECT_NO_THROW(round_trip(e)) << "seed " << seed;
    } catch (const ProtocolError& error) {
      ++rejected;
      EXPECT_THAT(error.what(), HasSubstr(kFrom)) << "seed " << seed;
    }
  }
  EXPECT_GT(rejected, 1000);  // most random buffers are not envelopes
}

TEST(Names, BodyAndRoleNames) {
  EXPECT_EQ(hfmpm::proto::body_name(protocol::Envelope{}), "empty");
  protocol::Envelope e;
  e.mutable_step_report();
  EXPECT_EQ(hfmpm::proto::body_name(e), "step_report");
  EXPECT_EQ(hfmpm::proto::role_name(protocol::SOLID), "solid");
  EXPECT_EQ(hfmpm::proto::role_name(protocol::FLUID), "fluid");
  EXPECT_EQ(hfmpm::proto::role_name(protocol::COUPLER), "coupler");
  EXPECT_EQ(hfmpm::proto::role_name(protocol::ROLE_UNSPECIFIED), "unspecified");
}

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
  protocol::Diagnostics back;
  hfmpm::proto::to_proto(plain, &back);
  EXPECT_TRUE(MessageDifferencer::Equals(back, message)) << back.ShortDebugString();
}

}  // namespace
