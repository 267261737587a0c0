// The Transport in memory: queues of encoded Envelopes behind one mutex and
// one condition variable per transport (a handful of threads: the coupler,
// two sides and their heartbeat threads).
#include "hfmpm/runtime/memory_transport.hpp"

#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace hfmpm::coupling {

using Queue = std::deque<std::string>;

struct MemoryTransport::State {
  struct ControlEndpoint {
    bool bound = false;
    std::deque<Routed> inbox;                             // to the coupler
    std::map<std::string, std::shared_ptr<Queue>> peers;  // to each connected link, by routing id
  };
  struct DataEndpoint {
    bool bound = false, connected = false;
    Queue to_binder, to_connector;
  };
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::string, std::shared_ptr<ControlEndpoint>> control;
  std::map<std::string, std::shared_ptr<DataEndpoint>> data;
  std::uint64_t messages = 0;

  // Waits (holding `lock`) until `ready()` or `timeout`; true if ready.
  template <class Ready>
  bool wait(std::unique_lock<std::mutex>& lock, std::chrono::microseconds timeout, Ready ready) {
    return changed.wait_for(lock, timeout, ready);
  }
};

namespace {

using State = MemoryTransport::State;

// A link that receives from one queue of the transport.
class MemoryLink : public Link {
 public:
  explicit MemoryLink(std::shared_ptr<State> state) : state_(std::move(state)) {}
  std::optional<protocol::Envelope> receive(std::string_view from, std::chrono::microseconds timeout,
                                            std::chrono::microseconds /*spin*/) override {
    std::string bytes;
    {
      std::unique_lock lock(state_->mutex);
      Queue& queue = inbox();
      if (!state_->wait(lock, timeout, [&] { return !queue.empty(); })) return std::nullopt;
      bytes = std::move(queue.front());
      queue.pop_front();
    }
    return proto::decode(bytes.data(), bytes.size(), from);
  }
  // Under the transport's mutex:
  virtual Queue& inbox() = 0;

 protected:
  std::shared_ptr<State> state_;
};

// A side's control or heartbeat link: a DEALER to the coupler's router.
class MemoryDealer final : public MemoryLink {
 public:
  MemoryDealer(std::shared_ptr<State> state, const std::string& endpoint, std::string id)
      : MemoryLink(std::move(state)), id_(std::move(id)), own_(std::make_shared<Queue>()) {
    std::lock_guard lock(state_->mutex);
    auto& endpoint_state = state_->control[endpoint];
    if (!endpoint_state) endpoint_state = std::make_shared<State::ControlEndpoint>();
    endpoint_ = endpoint_state;
    endpoint_->peers.emplace(id_, own_);  // like ZeroMQ: a second link with the same id is not heard
  }
  ~MemoryDealer() override {
    std::lock_guard lock(state_->mutex);
    const auto at = endpoint_->peers.find(id_);
    if (at != endpoint_->peers.end() && at->second == own_) endpoint_->peers.erase(at);
  }
  MemoryDealer(const MemoryDealer&) = delete;
  MemoryDealer& operator=(const MemoryDealer&) = delete;

  bool send_bytes(const std::string& bytes, bool /*wait*/) override {
    {
      std::lock_guard lock(state_->mutex);
      endpoint_->inbox.push_back(Routed{id_, bytes, true});
      ++state_->messages;
    }
    state_->changed.notify_all();
    return true;
  }
  std::string endpoint() const override { return ""; }
  Queue& inbox() override { return *own_; }

 private:
  std::string id_;
  std::shared_ptr<Queue> own_;
  std::shared_ptr<State::ControlEndpoint> endpoint_;
};

// One end of the data plane (a PAIR).
class MemoryPair final : public MemoryLink {
 public:
  MemoryPair(std::shared_ptr<State> state, std::shared_ptr<State::DataEndpoint> endpoint, bool binder, std::string name)
      : MemoryLink(std::move(state)), endpoint_(std::move(endpoint)), binder_(binder), name_(std::move(name)) {}
  ~MemoryPair() override {
    std::lock_guard lock(state_->mutex);
    (binder_ ? endpoint_->bound : endpoint_->connected) = false;
  }
  MemoryPair(const MemoryPair&) = delete;
  MemoryPair& operator=(const MemoryPair&) = delete;

  // Queued even before the peer connects: it reads the queue when it does.
  bool send_bytes(const std::string& bytes, bool /*wait*/) override {
    {
      std::lock_guard lock(state_->mutex);
      (binder_ ? endpoint_->to_connector : endpoint_->to_binder).push_back(bytes);
      ++state_->messages;
    }
    state_->changed.notify_all();
    return true;
  }
  std::string endpoint() const override { return binder_ ? name_ : ""; }
  Queue& inbox() override { return binder_ ? endpoint_->to_binder : endpoint_->to_connector; }

 private:
  std::shared_ptr<State::DataEndpoint> endpoint_;
  bool binder_;
  std::string name_;
};

class MemoryRouter final : public Router {
 public:
  MemoryRouter(std::shared_ptr<State> state, std::shared_ptr<State::ControlEndpoint> endpoint, std::string name)
      : state_(std::move(state)), endpoint_(std::move(endpoint)), name_(std::move(name)) {}
  ~MemoryRouter() override {
    std::lock_guard lock(state_->mutex);
    endpoint_->bound = false;
    endpoint_->inbox.clear();
  }
  MemoryRouter(const MemoryRouter&) = delete;
  MemoryRouter& operator=(const MemoryRouter&) = delete;

  std::optional<Routed> receive(std::chrono::microseconds timeout) override {
    std::unique_lock lock(state_->mutex);
    auto& inbox = endpoint_->inbox;
    if (!state_->wait(lock, timeout, [&] { return !inbox.empty(); })) return std::nullopt;
    Routed routed = std::move(inbox.front());
    inbox.pop_front();
    return routed;
  }
  // As a ZeroMQ ROUTER with ZMQ_ROUTER_MANDATORY: an unknown peer is an error.
  void send(const std::string& peer, const protocol::Envelope& envelope) override {
    const std::string bytes = proto::encode(envelope);
    {
      std::lock_guard lock(state_->mutex);
      const auto at = endpoint_->peers.find(peer);
      if (at == endpoint_->peers.end()) throw std::runtime_error("Host unreachable");
      at->second->push_back(bytes);
      ++state_->messages;
    }
    state_->changed.notify_all();
  }
  std::string endpoint() const override { return name_; }

 private:
  std::shared_ptr<State> state_;
  std::shared_ptr<State::ControlEndpoint> endpoint_;
  std::string name_;
};

}  // namespace

MemoryTransport::MemoryTransport() : state_(std::make_shared<State>()) {}
MemoryTransport::~MemoryTransport() = default;

std::unique_ptr<Router> MemoryTransport::bind_router(const std::string& endpoint, const RouterSecurity& /*security*/) {
  std::lock_guard lock(state_->mutex);
  auto& endpoint_state = state_->control[endpoint];
  if (!endpoint_state) endpoint_state = std::make_shared<State::ControlEndpoint>();
  if (endpoint_state->bound) throw std::runtime_error("Address already in use");
  endpoint_state->bound = true;
  return std::make_unique<MemoryRouter>(state_, endpoint_state, endpoint);
}

std::unique_ptr<Link> MemoryTransport::connect_control(const std::string& endpoint, protocol::Role role,
                                                       const std::optional<CurveKeys>& /*curve*/) {
  return std::make_unique<MemoryDealer>(state_, endpoint, std::string(proto::role_name(role)));
}

std::unique_ptr<Link> MemoryTransport::connect_heartbeat(const std::string& endpoint, protocol::Role role,
                                                         const std::optional<CurveKeys>& /*curve*/) {
  return std::make_unique<MemoryDealer>(state_, endpoint, std::string(proto::role_name(role)) + ".hb");
}

std::unique_ptr<Link> MemoryTransport::bind_data(const std::string& endpoint, std::int64_t /*max_message_bytes*/,
                                                 const std::optional<CurveKeys>& /*curve*/) {
  std::lock_guard lock(state_->mutex);
  auto& endpoint_state = state_->data[endpoint];
  if (!endpoint_state) endpoint_state = std::make_shared<State::DataEndpoint>();
  if (endpoint_state->bound) throw std::runtime_error("Address already in use");
  endpoint_state->bound = true;
  return std::make_unique<MemoryPair>(state_, endpoint_state, true, endpoint);
}

std::unique_ptr<Link> MemoryTransport::connect_data(const std::string& endpoint, std::int64_t /*max_message_bytes*/,
                                                    const std::optional<CurveKeys>& /*curve*/) {
  std::lock_guard lock(state_->mutex);
  auto& endpoint_state = state_->data[endpoint];
  if (!endpoint_state) endpoint_state = std::make_shared<State::DataEndpoint>();
  endpoint_state->connected = true;
  return std::make_unique<MemoryPair>(state_, endpoint_state, false, endpoint);
}

int MemoryTransport::poll(std::span<PollItem> items, std::chrono::milliseconds timeout) {
  std::unique_lock lock(state_->mutex);
  int ready = 0;
  auto check = [&] {
    ready = 0;
    for (auto& item : items) {
      // A message can always be queued; a link is readable when its queue is not empty.
      item.ready = item.for_send || !dynamic_cast<MemoryLink&>(*item.link).inbox().empty();
      ready += item.ready ? 1 : 0;
    }
    return ready > 0;
  };
  state_->wait(lock, timeout, check);
  return ready;
}

std::uint64_t MemoryTransport::messages() const {
  std::lock_guard lock(state_->mutex);
  return state_->messages;
}

}  // namespace hfmpm::coupling
