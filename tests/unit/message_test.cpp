// Unit tests of the wire codec (proto/include/hfmpm/proto/envelope.hpp) and of the
// converters' use inside envelopes; the converters themselves: convert_test.cpp.
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
#include <map>
#include <random>
#include <string>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/proto/envelope.hpp"
#include "message_samples.hpp"
#include "test_support.hpp"

namespace {

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

}  // namespace

// The scene schema's fingerprint (FNV-1a of the descriptor of scene.proto, as
// protoc parsed it, comments excluded; the text is that of Debian 12's
// protobuf 3.21, so another protobuf may change it) for each SceneSchema version. A change
// to scene.proto changes the fingerprint: bump SCENE_SCHEMA_CURRENT in
// protocol.proto and add the new line here (docs/protocol.md, section 3).
TEST(Versions, SceneSchemaIsBumpedWithTheSchema) {
  const std::string schema = hfmpm::scene::Scene::descriptor()->file()->DebugString();
  std::uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : schema) hash = (hash ^ c) * 1099511628211ull;
  const std::map<std::uint32_t, std::uint64_t> fingerprints{
      {1, 9993337185708650126ull},   // the first
      {2, 14058848928991701327ull},  // output.checkpoint_interval_s
      {3, 17634283515390672675ull},  // fracture.front_settle_transits
      {4, 1513303805568776259ull},   // fluid lag TIP_ASYMPTOTE
      {5, 9617441847628438774ull},   // fracture.surfaces_from_material
      {6, 17530128371913356884ull},  // fluid lag TIP_ASYMPTOTE_MATCHED
      {7, 2265630044900314741ull},   // fluid.mpm.affine_transfer
      {8, 1754681767318198518ull},   // cracks.inlet_vertex
      {9, 13498048890745661301ull},  // fracture.release_transits
      {10, 4473893897642791083ull},  // cracks.friction_coefficient, cautions
  };
  ASSERT_TRUE(fingerprints.count(hfmpm::proto::kSceneSchemaVersion))
      << "no fingerprint recorded for scene schema version " << hfmpm::proto::kSceneSchemaVersion;
  EXPECT_EQ(fingerprints.at(hfmpm::proto::kSceneSchemaVersion), hash)
      << "scene.proto changed (fingerprint " << hash << "ull) but SCENE_SCHEMA_CURRENT is still "
      << hfmpm::proto::kSceneSchemaVersion << ": bump it in protocol.proto and record the new fingerprint here";
}
