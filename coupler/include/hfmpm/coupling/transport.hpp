// Thin helpers over cppzmq: every message is one frame holding one Envelope
// (the coupler's ROUTER adds the peer's routing id in front). No physics here.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <zmq.hpp>

#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::coupling {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);

// Sockets never block process exit for more than this (ms) on unsent messages.
inline constexpr int kLingerMs = 500;

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
