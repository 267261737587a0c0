// The Transport in memory: thread-safe queues between the coupler and the
// sides running as threads of one process (RunOptions::transport with
// coupling.transport INPROC). No sockets, no ZeroMQ: the coupling scheme,
// the handshake and the step loop run exactly as over ZeroMQ, message for
// message (the same encoded Envelopes), so a coupled run can be tested in
// one process. Endpoints are names; a link may connect before its endpoint
// is bound (as ZeroMQ's inproc allows). There is no CURVE (nothing leaves
// the process) and no size limit.
#pragma once

#include <cstdint>
#include <memory>

#include "hfmpm/runtime/transport.hpp"

namespace hfmpm::coupling {

class MemoryTransport : public Transport {
 public:
  MemoryTransport();
  ~MemoryTransport() override;
  MemoryTransport(const MemoryTransport&) = delete;
  MemoryTransport& operator=(const MemoryTransport&) = delete;

  std::unique_ptr<Router> bind_router(const std::string& endpoint, const RouterSecurity& security) override;
  std::unique_ptr<Link> connect_control(const std::string& endpoint, protocol::Role role,
                                        const std::optional<CurveKeys>& curve) override;
  std::unique_ptr<Link> connect_heartbeat(const std::string& endpoint, protocol::Role role,
                                          const std::optional<CurveKeys>& curve) override;
  std::unique_ptr<Link> bind_data(const std::string& endpoint, std::int64_t max_message_bytes,
                                  const std::optional<CurveKeys>& curve) override;
  std::unique_ptr<Link> connect_data(const std::string& endpoint, std::int64_t max_message_bytes,
                                     const std::optional<CurveKeys>& curve) override;
  int poll(std::span<PollItem> items, std::chrono::milliseconds timeout) override;

  // Messages sent so far through any link of this transport (for tests).
  std::uint64_t messages() const;

  struct State;  // the queues, behind one mutex (memory_transport.cpp)

 private:
  std::shared_ptr<State> state_;  // shared with the links, which may outlive this object
};

}  // namespace hfmpm::coupling
