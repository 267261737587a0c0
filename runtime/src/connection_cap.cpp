// A cap on connections that have not proven to be a side (connection_cap.hpp).
#include "connection_cap.hpp"

#include <sys/resource.h>
#include <sys/socket.h>
#include <zmq.h>

#include <arpa/inet.h>
#include <linux/tcp.h>
#include <netinet/in.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "hfmpm/runtime/transport.hpp"

namespace hfmpm::coupling {
namespace {

constexpr std::size_t kMaxCap = 256;
constexpr std::size_t kReservedDescriptors = 64;

std::string peer_of(int fd) {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) return "?";
  char text[INET6_ADDRSTRLEN] = {};
  if (address.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<const sockaddr_in*>(&address);
    inet_ntop(AF_INET, &in->sin_addr, text, sizeof(text));
    return std::string(text) + ":" + std::to_string(ntohs(in->sin_port));
  }
  if (address.ss_family == AF_INET6) {
    const auto* in = reinterpret_cast<const sockaddr_in6*>(&address);
    inet_ntop(AF_INET6, &in->sin6_addr, text, sizeof(text));
    return "[" + std::string(text) + "]:" + std::to_string(ntohs(in->sin6_port));
  }
  return "?";
}

// Bytes the peer has sent on this tcp connection (0 if unknown).
std::uint64_t bytes_received(int fd) {
  tcp_info info{};
  socklen_t length = sizeof(info);
  if (getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &length) != 0) return 0;
  if (length < offsetof(tcp_info, tcpi_bytes_received) + sizeof(info.tcpi_bytes_received)) return 0;
  return info.tcpi_bytes_received;
}

}  // namespace

std::size_t connection_cap_for_this_process() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return kMaxCap;
  const auto open_files = static_cast<std::size_t>(limit.rlim_cur);
  const std::size_t left = open_files > kReservedDescriptors ? open_files - kReservedDescriptors : 0;
  return std::clamp<std::size_t>(left / 2, 4, kMaxCap);
}

ConnectionCap::ConnectionCap(zmq::context_t& context, zmq::socket_t& socket, std::size_t cap,
                             std::function<void(const std::string&)> told)
    : socket_(socket), cap_(cap), told_(std::move(told)) {
  const std::string endpoint = "inproc://hfmpm-connections-" + std::to_string(reinterpret_cast<std::uintptr_t>(this));
  if (zmq_socket_monitor(socket.handle(), endpoint.c_str(), ZMQ_EVENT_ACCEPTED | ZMQ_EVENT_DISCONNECTED) != 0) {
    throw zmq::error_t();
  }
  auto events = std::make_shared<zmq::socket_t>(context, zmq::socket_type::pair);
  events->set(zmq::sockopt::linger, 0);
  events->connect(endpoint);
  thread_ = std::thread([this, events] { watch(*events); });
}

ConnectionCap::~ConnectionCap() {
  zmq_socket_monitor(socket_.handle(), nullptr, 0);
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void ConnectionCap::admit(int fd) {
  if (fd < 0 || fd == last_admitted_) return;
  last_admitted_ = fd;
  std::lock_guard<std::mutex> lock(mutex_);
  admitted_.push_back(fd);
}

void ConnectionCap::watch(zmq::socket_t& events) {
  std::map<int, std::uint64_t> open;   // descriptor -> when accepted (a sequence number)
  std::map<std::uint64_t, int> order;  // the same, oldest first
  std::set<int> admitted;              // open connections that carried a side's message
  std::uint64_t accepted = 0, dropped = 0, untold = 0;
  std::string last_peer;
  std::chrono::steady_clock::time_point last_told{};
  auto forget = [&](int fd) {
    const auto it = open.find(fd);
    if (it != open.end()) {
      order.erase(it->second);
      open.erase(it);
    }
    admitted.erase(fd);
  };
  while (!stop_.load()) {
    zmq::pollitem_t item{events.handle(), 0, ZMQ_POLLIN, 0};
    try {
      zmq::poll(&item, 1, std::chrono::milliseconds(50));
    } catch (const zmq::error_t&) {
      break;
    }
    // Admissions told before now come after the events of their connection,
    // which ZeroMQ queued before the message was read: take them first, then
    // read every queued event, then admit.
    std::vector<int> admits;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      admits.swap(admitted_);
    }
    while (true) {
      zmq::message_t head, address;
      if (!events.recv(head, zmq::recv_flags::dontwait)) break;
      while (head.more() && events.recv(address, zmq::recv_flags::dontwait) && address.more()) {
      }
      if (head.size() < 6) continue;
      std::uint16_t event = 0;
      std::uint32_t value = 0;
      std::memcpy(&event, head.data(), sizeof(event));
      std::memcpy(&value, static_cast<const char*>(head.data()) + sizeof(event), sizeof(value));
      const int fd = static_cast<int>(value);
      if (event == ZMQ_EVENT_ACCEPTED) {
        forget(fd);  // a descriptor number in use again
        open[fd] = accepted;
        order[accepted++] = fd;
      } else if (event == ZMQ_EVENT_DISCONNECTED) {
        forget(fd);
      }
    }
    for (int fd : admits) {
      if (open.count(fd)) admitted.insert(fd);
    }
    // Over the cap: of the connections that have not proven to be a side,
    // those that received the fewest bytes go first (an idle one, which never
    // began the ZeroMQ greeting, before one that did), the oldest first among
    // equals. A side sends its greeting and CURVE Hello as soon as it is
    // connected, so it outranks every stranger that holds a connection idle.
    const std::size_t strangers = open.size() - admitted.size();
    if (strangers > cap_) {
      std::vector<std::tuple<std::uint64_t, std::uint64_t, int>> candidates;  // bytes received, when accepted, fd
      candidates.reserve(strangers);
      for (const auto& [when, fd] : order) {
        if (!admitted.count(fd)) candidates.emplace_back(bytes_received(fd), when, fd);
      }
      const std::size_t excess = strangers - cap_;
      std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(excess), candidates.end());
      for (std::size_t i = 0; i < excess; ++i) {
        const auto [bytes, when, fd] = candidates[i];
        last_peer = peer_of(fd);
        ::shutdown(fd, SHUT_RDWR);  // ZeroMQ sees the peer leave, closes it and says DISCONNECTED
        order.erase(when);
        open.erase(fd);
        ++dropped;
        ++untold;
      }
    }
    const auto now = std::chrono::steady_clock::now();
    if (untold > 0 && told_ && now - last_told > std::chrono::seconds(1)) {
      told_("closed " + std::to_string(untold) + " connection" + (untold == 1 ? "" : "s") + " (" +
            std::to_string(dropped) + " in all) beyond the cap of " + std::to_string(cap_) +
            " connections that have not yet brought a side's message (the last from " + printable(last_peer) + ")");
      last_told = now;
      untold = 0;
    }
  }
}

}  // namespace hfmpm::coupling
