// The Transport over ZeroMQ (every message one frame holding one Envelope;
// the coupler's ROUTER adds the peer's routing id in front), and the
// single-frame helpers over raw sockets it is made of (also used by the
// conformance harness, the fuzzer and the benchmarks). The socket options
// are the protocol's (docs/protocol.md, docs/reliability.md).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <zmq.hpp>

#include "hfmpm/runtime/transport.hpp"

namespace hfmpm::coupling {

// Sockets never block process exit for more than this (ms) on unsent messages.
inline constexpr int kLingerMs = 500;

// Largest message a socket accepts (ZMQ_MAXMSGSIZE; a peer that sends more
// is disconnected before the bytes are kept). The coupler hears only small
// control messages; a side's control socket receives Welcome with the scene
// (scene files are at most 16 MiB of text); the data plane carries the crack
// and fluid state, bounded from the scene (data_plane_message_limit).
inline constexpr std::int64_t kCouplerMaxMessageBytes = std::int64_t{4} << 20;
inline constexpr std::int64_t kSideControlMaxMessageBytes = std::int64_t{64} << 20;

// How long a connection may take to complete the ZeroMQ handshake (and, on
// tcp, CURVE) before it is dropped: a peer that connects and says nothing
// holds a descriptor for at most this long.
inline constexpr int kHandshakeMs = 5000;

// The coupler's tcp listen queue (ZMQ_BACKLOG; ZeroMQ's default is 100; the
// kernel caps it at net.core.somaxconn, 4096 by default).
inline constexpr int kListenBacklog = 1024;

// A Transport over a ZeroMQ context of its own (one I/O thread).
std::shared_ptr<Transport> make_zmq_transport();

void send(zmq::socket_t& socket, const protocol::Envelope& envelope);

// Waits up to `timeout` for one message. `spin` is a busy-poll phase before
// sleeping (trades one core for latency). Throws ProtocolError if the bytes
// are not a valid Envelope.
std::optional<protocol::Envelope> receive(zmq::socket_t& socket, std::string_view from,
                                          std::chrono::microseconds timeout,
                                          std::chrono::microseconds spin = std::chrono::microseconds(0));

// One message on a ROUTER: who sent it and the raw payload.
std::optional<Routed> receive_routed(zmq::socket_t& router, std::chrono::microseconds timeout);
void send_routed(zmq::socket_t& router, const std::string& peer, const protocol::Envelope& envelope);

}  // namespace hfmpm::coupling
