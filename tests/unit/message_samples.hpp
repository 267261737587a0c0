// Shared by the codec tests (message_test.cpp) and the converter tests
// (convert_test.cpp): sample plain types and messages, and helpers that
// return the text of an expected ProtocolError.
#pragma once

#include <gmock/gmock.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/proto/envelope.hpp"

namespace {

namespace protocol = hfmpm::protocol;
using google::protobuf::util::MessageDifferencer;
using hfmpm::proto::ProtocolError;
using ::testing::HasSubstr;

constexpr const char* kFrom = "solid (ipc:///tmp/x/control)";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

inline protocol::Envelope round_trip(const protocol::Envelope& in) {
  const std::string bytes = hfmpm::proto::encode(in);
  return hfmpm::proto::decode(bytes.data(), bytes.size(), kFrom);
}

// Expects decode to throw ProtocolError; returns its text.
inline std::string decode_error(const std::string& bytes) {
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

inline protocol::Diagnostics sample_diagnostics() {
  protocol::Diagnostics d;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      "kinetic_energy: 1.25 crack_length: 0.75 mouth_opening: 1.0e-3 crack_face_load: -3.5e4 inlet_pressure: 2.0e5 "
      "injected_volume: 6.0e-4 fluid_volume: 5.5e-4 front_position: 0.6 crack_particles: 101 fluid_particles: 77 "
      "coupling_lag: 1.5e3 strain_energy: 2.5",
      &d));
  return d;
}

// A straight crack of 4 particles along x with an elliptic-looking opening.
inline hfmpm::CrackGeometry sample_geometry() {
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

inline hfmpm::CrackPressure sample_pressure() {
  hfmpm::CrackPressure p;
  p.crack_id = 3;
  p.ids = {10, 11, 12, 40};
  p.pressure = {1.0e5, 7.5e4, 0.0, 0.0};
  p.front_position = 0.4;
  p.inlet_flux = 2.5e-5;
  p.fluid_volume = 3.0e-4;
  return p;
}

inline protocol::CrackState::Crack sample_crack_message() {
  protocol::CrackState::Crack m;
  hfmpm::proto::to_proto(sample_geometry(), &m);
  return m;
}

}  // namespace
