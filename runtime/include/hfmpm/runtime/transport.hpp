// Thin helpers over cppzmq: every message is one frame holding one Envelope
// (the coupler's ROUTER adds the peer's routing id in front). No physics here.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <zmq.hpp>

#include "hfmpm/proto/envelope.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);

// Sockets never block process exit for more than this (ms) on unsent messages.
inline constexpr int kLingerMs = 500;

// Largest message a socket accepts (ZMQ_MAXMSGSIZE; a peer that sends more
// is disconnected before the bytes are kept). The coupler hears only small
// control messages; a side's control socket receives Welcome with the scene
// (scene files are at most 16 MiB of text); the data plane carries the crack
// and fluid state, bounded from the scene (data_plane_message_limit).
inline constexpr std::int64_t kCouplerMaxMessageBytes = std::int64_t{4} << 20;
inline constexpr std::int64_t kSideControlMaxMessageBytes = std::int64_t{64} << 20;
// Data-plane limit for a scene: 16 MiB plus 2 KiB for every crack particle
// the grid can hold along its cracks (8 per cell over the grid's width plus
// height, per crack), or 256 MiB without an MPM grid.
std::int64_t data_plane_message_limit(const scene::Scene& scene);

// How long a connection may take to complete the ZeroMQ handshake (and, on
// tcp, CURVE) before it is dropped: a peer that connects and says nothing
// holds a descriptor for at most this long.
inline constexpr int kHandshakeMs = 5000;

void send(zmq::socket_t& socket, const protocol::Envelope& envelope);

// Waits up to `timeout` for one message. `spin` is a busy-poll phase before
// sleeping (trades one core for latency). Throws ProtocolError if the bytes
// are not a valid Envelope.
std::optional<protocol::Envelope> receive(zmq::socket_t& socket, std::string_view from,
                                          std::chrono::microseconds timeout,
                                          std::chrono::microseconds spin = std::chrono::microseconds(0));

// One message on a ROUTER: who sent it and the raw payload.
struct Routed {
  std::string peer;
  std::string payload;
  bool well_framed = true;  // exactly [routing id][payload]
};
std::optional<Routed> receive_routed(zmq::socket_t& router, std::chrono::microseconds timeout);
void send_routed(zmq::socket_t& router, const std::string& peer, const protocol::Envelope& envelope);

// "tcp://0.0.0.0:5555" with host "node7" -> "tcp://node7:5555"; other transports unchanged.
std::string advertise(const std::string& bound_endpoint, const std::string& host);

// The host part of a tcp endpoint, "" otherwise.
std::string tcp_host(const std::string& endpoint);

// `text` fit for a log line: at most `max` characters, anything outside
// printable ASCII as \xNN (a peer's name cannot forge lines or reach the
// terminal as escape sequences).
std::string printable(const std::string& text, std::size_t max = 64);

}  // namespace hfmpm::coupling
