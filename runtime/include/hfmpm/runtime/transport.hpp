// How a side and the coupler talk: links that carry one Envelope per message.
// The side runtime and the coupler see only these interfaces; ZeroMQ
// (zmq_transport.hpp: processes, ipc/tcp, or inproc threads) and plain queues
// in memory (memory_transport.hpp: the coupler and both sides as threads of
// one process, no sockets) implement them. No physics here.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "hfmpm/proto/envelope.hpp"
#include "hfmpm/runtime/curve.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);

// Data-plane limit for a scene: 16 MiB plus 2 KiB for every crack particle
// the grid can hold along its cracks (8 per cell over the grid's width plus
// height, per crack), or 256 MiB without an MPM grid.
std::int64_t data_plane_message_limit(const scene::Scene& scene);

// One end of a link: a side's control link to the coupler, its heartbeat
// link, or one end of the data plane between the sides. Every message is one
// frame holding one encoded Envelope. Used from one thread at a time.
class Link {
 public:
  virtual ~Link() = default;
  // One message of raw bytes. wait: block until it is queued; otherwise
  // return false at once if it cannot be (a data link whose peer has not
  // connected yet).
  virtual bool send_bytes(const std::string& bytes, bool wait) = 0;
  // Waits up to `timeout` for one message (busy-polling for `spin` first).
  // Throws proto::ProtocolError naming `from` if the bytes are not exactly
  // one valid Envelope.
  virtual std::optional<protocol::Envelope> receive(std::string_view from, std::chrono::microseconds timeout,
                                                    std::chrono::microseconds spin = std::chrono::microseconds(0)) = 0;
  // A bound link: the endpoint it is reachable at (the port chosen); "" otherwise.
  virtual std::string endpoint() const = 0;

  // One Envelope, waiting until it is queued; throws std::runtime_error if it cannot be sent.
  void send(const protocol::Envelope& envelope);
};

// One message at the coupler's end: who sent it and the raw payload.
struct Routed {
  std::string peer;
  std::string payload;
  bool well_framed = true;  // exactly [routing id][payload]
  int source_fd = -1;       // ZeroMQ over tcp/ipc: the connection's descriptor (ZMQ_SRCFD), else -1
};

// The coupler's end of the control plane: every side connects its control
// link (routing id "solid", "fluid") and heartbeat link ("solid.hb", ...).
class Router {
 public:
  virtual ~Router() = default;
  virtual std::optional<Routed> receive(std::chrono::microseconds timeout) = 0;
  // Throws std::runtime_error if `peer` is not connected.
  virtual void send(const std::string& peer, const protocol::Envelope& envelope) = 0;
  virtual std::string endpoint() const = 0;  // the bound endpoint (the port chosen)
};

// Who may join the coupler on tcp: CURVE with the coupler's secret key, and
// only peers presenting the sides' public key (docs/reliability.md).
// On tcp, the connections of peers that have not yet sent a side's message
// are capped (docs/reliability.md, "A cap on connections"); `refused` also
// hears about connections closed beyond the cap.
struct RouterSecurity {
  std::optional<CurveKeys> curve;
  std::function<void(const std::string&)> refused;  // told about refused peers (another thread)
};

// A wait on several links at once (like zmq_poll).
struct PollItem {
  Link* link = nullptr;
  bool for_send = false;  // wait until a message can be queued, not until one arrives
  bool ready = false;     // set by Transport::poll
};

// Makes the links of one process (ZeroMQ: one context) or, in memory, of
// the coupler and side threads of one run. Thread-safe.
class Transport {
 public:
  virtual ~Transport() = default;
  // The coupler: binds its control endpoint; throws std::runtime_error (the
  // transport's words) if it cannot.
  virtual std::unique_ptr<Router> bind_router(const std::string& endpoint, const RouterSecurity& security) = 0;
  // A side: its control link to the coupler, routing id = the role's name.
  virtual std::unique_ptr<Link> connect_control(const std::string& endpoint, protocol::Role role,
                                                const std::optional<CurveKeys>& curve) = 0;
  // A side: its heartbeat link, routing id "<role>.hb" (sends never wait).
  virtual std::unique_ptr<Link> connect_heartbeat(const std::string& endpoint, protocol::Role role,
                                                  const std::optional<CurveKeys>& curve) = 0;
  // The data plane: the solid binds, the fluid connects. `curve` (tcp only):
  // a CURVE server admitting only the sides' key / a client holding it.
  virtual std::unique_ptr<Link> bind_data(const std::string& endpoint, std::int64_t max_message_bytes,
                                          const std::optional<CurveKeys>& curve) = 0;
  virtual std::unique_ptr<Link> connect_data(const std::string& endpoint, std::int64_t max_message_bytes,
                                             const std::optional<CurveKeys>& curve) = 0;
  // Waits up to `timeout` until an item is ready; marks them; returns how many are.
  virtual int poll(std::span<PollItem> items, std::chrono::milliseconds timeout) = 0;
};

// `text` fit for a log line: at most `max` characters, anything outside
// printable ASCII as \xNN (a peer's name cannot forge lines or reach the
// terminal as escape sequences).
std::string printable(const std::string& text, std::size_t max = 64);

// "tcp://0.0.0.0:5555" with host "node7" -> "tcp://node7:5555"; other transports unchanged.
std::string advertise(const std::string& bound_endpoint, const std::string& host);

// The host part of a tcp endpoint, "" otherwise.
std::string tcp_host(const std::string& endpoint);

// This machine's host name ("localhost" if it has none): Hello, run.json, advertised endpoints.
std::string host_name();

}  // namespace hfmpm::coupling
