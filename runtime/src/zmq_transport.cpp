// The Transport over ZeroMQ: DEALER control and heartbeat links, PAIR data
// links, the coupler's ROUTER, each with the options the protocol needs
// (linger, message-size limits, handshake timeout, CURVE on tcp).
#include "hfmpm/runtime/zmq_transport.hpp"

#include "connection_cap.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

namespace hfmpm::coupling {

void send(zmq::socket_t& socket, const protocol::Envelope& envelope) {
  const std::string bytes = proto::encode(envelope);
  if (!socket.send(zmq::buffer(bytes), zmq::send_flags::none)) {
    throw std::runtime_error("could not send a " + std::string(proto::body_name(envelope)) + " message");
  }
}

namespace {

bool wait_readable(zmq::socket_t& socket, std::chrono::microseconds timeout, std::chrono::microseconds spin) {
  const auto start = Clock::now();
  if (spin.count() > 0) {
    zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
    while (Clock::now() - start < spin) {
      if (zmq::poll(&item, 1, std::chrono::milliseconds(0)) > 0) return true;
    }
  }
  const auto left = timeout - std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start);
  zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(left + std::chrono::microseconds(999));
  return zmq::poll(&item, 1, std::max(ms, std::chrono::milliseconds(0))) > 0;
}

}  // namespace

std::optional<protocol::Envelope> receive(zmq::socket_t& socket, std::string_view from,
                                          std::chrono::microseconds timeout, std::chrono::microseconds spin) {
  if (!wait_readable(socket, timeout, spin)) return std::nullopt;
  zmq::message_t message;
  if (!socket.recv(message, zmq::recv_flags::dontwait)) return std::nullopt;
  if (message.more()) {
    zmq::message_t rest;
    do {
      (void)socket.recv(rest, zmq::recv_flags::none);
    } while (rest.more());
    throw proto::ProtocolError("malformed message from " + std::string(from) +
                               ": several frames where the protocol sends exactly one");
  }
  return proto::decode(message.data(), message.size(), from);
}

std::optional<Routed> receive_routed(zmq::socket_t& router, std::chrono::microseconds timeout) {
  if (!wait_readable(router, timeout, std::chrono::microseconds(0))) return std::nullopt;
  std::vector<zmq::message_t> parts;
  do {
    parts.emplace_back();
    if (!router.recv(parts.back(), zmq::recv_flags::dontwait)) return std::nullopt;
  } while (parts.back().more());
  Routed routed;
  routed.peer = parts.front().to_string();
  routed.well_framed = parts.size() == 2;
  if (parts.size() >= 2) routed.payload = parts[1].to_string();
  // The connection's descriptor; -1 without one (inproc; cppzmq's get() would throw).
  routed.source_fd = zmq_msg_get(parts.back().handle(), ZMQ_SRCFD);
  return routed;
}

void send_routed(zmq::socket_t& router, const std::string& peer, const protocol::Envelope& envelope) {
  const std::string bytes = proto::encode(envelope);
  if (!router.send(zmq::buffer(peer), zmq::send_flags::sndmore) ||
      !router.send(zmq::buffer(bytes), zmq::send_flags::none)) {
    throw std::runtime_error("could not send a " + std::string(proto::body_name(envelope)) + " message to " + peer);
  }
}

namespace {

class ZmqLink final : public Link {
 public:
  ZmqLink(zmq::context_t& context, zmq::socket_type type) : socket_(context, type) {}
  // A bound data link with CURVE: its authenticator, which must outlive the socket.
  void guard(std::unique_ptr<ZapAuthenticator> zap) { zap_ = std::move(zap); }
  zmq::socket_t& socket() { return socket_; }

  bool send_bytes(const std::string& bytes, bool wait) override {
    return socket_.send(zmq::buffer(bytes), wait ? zmq::send_flags::none : zmq::send_flags::dontwait).has_value();
  }
  std::optional<protocol::Envelope> receive(std::string_view from, std::chrono::microseconds timeout,
                                            std::chrono::microseconds spin) override {
    return coupling::receive(socket_, from, timeout, spin);
  }
  std::string endpoint() const override { return bound_; }
  void bind(const std::string& endpoint) {
    socket_.bind(endpoint);
    bound_ = socket_.get(zmq::sockopt::last_endpoint);
  }

 private:
  std::unique_ptr<ZapAuthenticator> zap_;  // before socket_: outlives the socket it guards
  zmq::socket_t socket_;
  std::string bound_;
};

class ZmqRouter final : public Router {
 public:
  explicit ZmqRouter(zmq::context_t& context) : socket_(context, zmq::socket_type::router) {}
  ~ZmqRouter() override { cap_.reset(); }  // stops watching before the socket closes
  void guard(std::unique_ptr<ZapAuthenticator> zap) { zap_ = std::move(zap); }
  void limit(std::unique_ptr<ConnectionCap> cap) { cap_ = std::move(cap); }
  zmq::socket_t& socket() { return socket_; }
  void bind(const std::string& endpoint) {
    socket_.bind(endpoint);
    bound_ = socket_.get(zmq::sockopt::last_endpoint);
  }

  std::optional<Routed> receive(std::chrono::microseconds timeout) override {
    auto routed = receive_routed(socket_, timeout);
    // A message under a side's routing id: its connection is not a stranger's
    // to be dropped at the cap (with CURVE only the sides get a message through).
    if (routed && cap_ && is_side_routing_id(routed->peer)) cap_->admit(routed->source_fd);
    return routed;
  }
  void send(const std::string& peer, const protocol::Envelope& envelope) override {
    send_routed(socket_, peer, envelope);
  }
  std::string endpoint() const override { return bound_; }

 private:
  static bool is_side_routing_id(const std::string& peer) {
    return peer == "solid" || peer == "fluid" || peer == "solid.hb" || peer == "fluid.hb";
  }

  std::unique_ptr<ZapAuthenticator> zap_;  // tcp with CURVE; before socket_: outlives it
  zmq::socket_t socket_;
  std::unique_ptr<ConnectionCap> cap_;  // tcp: watches socket_
  std::string bound_;
};

class ZmqTransport final : public Transport {
 public:
  std::unique_ptr<Router> bind_router(const std::string& endpoint, const RouterSecurity& security) override {
    auto router = std::make_unique<ZmqRouter>(context_);
    auto& socket = router->socket();
    socket.set(zmq::sockopt::linger, kLingerMs);
    socket.set(zmq::sockopt::router_mandatory, 1);
    socket.set(zmq::sockopt::maxmsgsize, kCouplerMaxMessageBytes);
    socket.set(zmq::sockopt::handshake_ivl, kHandshakeMs);
    if (security.curve) {
      router->guard(std::make_unique<ZapAuthenticator>(context_, security.curve->client_public, security.refused));
      make_curve_server(socket, security.curve->server_secret);
    } else if (endpoint.rfind("tcp://", 0) == 0) {
      // Plain tcp: a ZAP domain (with no handler, so every peer is admitted)
      // makes ZeroMQ refuse ZMTP 1.0 and 2.0 peers at the greeting. libzmq
      // 4.3.4 aborts the process (errno_assert, zmtp_engine.cpp:446) when
      // such a peer's first frame, its routing id, completes while the
      // socket is being closed; the sides all speak ZMTP 3
      // (docs/reliability.md, "The libzmq abort").
      socket.set(zmq::sockopt::zap_domain, std::string("hfmpm"));
    }
    if (endpoint.rfind("tcp://", 0) == 0) {
      // A long listen queue: a side's connection that arrives amid a flood
      // waits in it for the next accept() instead of having its SYN dropped
      // (the kernel retries a dropped SYN after 1 s, then 3 s).
      socket.set(zmq::sockopt::backlog, kListenBacklog);
      router->limit(
          std::make_unique<ConnectionCap>(context_, socket, connection_cap_for_this_process(), security.refused));
    }
    router->bind(endpoint);
    return router;
  }

  std::unique_ptr<Link> connect_control(const std::string& endpoint, protocol::Role role,
                                        const std::optional<CurveKeys>& curve) override {
    auto link = std::make_unique<ZmqLink>(context_, zmq::socket_type::dealer);
    auto& socket = link->socket();
    socket.set(zmq::sockopt::linger, kLingerMs);
    socket.set(zmq::sockopt::routing_id, std::string(proto::role_name(role)));
    socket.set(zmq::sockopt::maxmsgsize, kSideControlMaxMessageBytes);
    if (curve) make_curve_client(socket, curve->server_public, curve->client_public, curve->client_secret);
    socket.connect(endpoint);
    return link;
  }

  std::unique_ptr<Link> connect_heartbeat(const std::string& endpoint, protocol::Role role,
                                          const std::optional<CurveKeys>& curve) override {
    auto link = std::make_unique<ZmqLink>(context_, zmq::socket_type::dealer);
    auto& socket = link->socket();
    socket.set(zmq::sockopt::linger, 0);
    socket.set(zmq::sockopt::routing_id, std::string(proto::role_name(role)) + ".hb");
    if (curve) make_curve_client(socket, curve->server_public, curve->client_public, curve->client_secret);
    socket.connect(endpoint);
    return link;
  }

  std::unique_ptr<Link> bind_data(const std::string& endpoint, std::int64_t max_message_bytes,
                                  const std::optional<CurveKeys>& curve) override {
    auto link = data_link(max_message_bytes);
    if (curve) {
      // Only the other side, holding the same key pair, gets through.
      link->guard(std::make_unique<ZapAuthenticator>(context_, curve->client_public));
      make_curve_server(link->socket(), curve->client_secret);
    }
    link->bind(endpoint);
    return link;
  }

  std::unique_ptr<Link> connect_data(const std::string& endpoint, std::int64_t max_message_bytes,
                                     const std::optional<CurveKeys>& curve) override {
    auto link = data_link(max_message_bytes);
    if (curve) make_curve_client(link->socket(), curve->client_public, curve->client_public, curve->client_secret);
    link->socket().connect(endpoint);
    return link;
  }

  int poll(std::span<PollItem> items, std::chrono::milliseconds timeout) override {
    // No allocation: consume() polls in a busy loop while it spins (coupling.spin_us).
    constexpr std::size_t kMaxItems = 4;
    if (items.size() > kMaxItems) throw std::invalid_argument("poll: at most 4 links at once");
    std::array<zmq::pollitem_t, kMaxItems> polled{};
    for (std::size_t i = 0; i < items.size(); ++i) {
      auto& socket = dynamic_cast<ZmqLink&>(*items[i].link).socket();
      polled[i] = {socket.handle(), 0, static_cast<short>(items[i].for_send ? ZMQ_POLLOUT : ZMQ_POLLIN), 0};
    }
    const int ready = zmq::poll(polled.data(), items.size(), timeout);
    for (std::size_t i = 0; i < items.size(); ++i) items[i].ready = (polled[i].revents & polled[i].events) != 0;
    return ready;
  }

 private:
  std::unique_ptr<ZmqLink> data_link(std::int64_t max_message_bytes) {
    auto link = std::make_unique<ZmqLink>(context_, zmq::socket_type::pair);
    auto& socket = link->socket();
    socket.set(zmq::sockopt::linger, kLingerMs);
    socket.set(zmq::sockopt::maxmsgsize, max_message_bytes);
    socket.set(zmq::sockopt::handshake_ivl, kHandshakeMs);
    return link;
  }

  zmq::context_t context_{1};
};

}  // namespace

std::shared_ptr<Transport> make_zmq_transport() { return std::make_shared<ZmqTransport>(); }

}  // namespace hfmpm::coupling
