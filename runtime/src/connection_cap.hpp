// A cap on the tcp connections a bound ZeroMQ socket holds for peers that
// have not (yet) proven to be a side (docs/reliability.md, "A cap on
// connections"). ZeroMQ accepts every connection and has no limit of its own;
// once the process runs out of file descriptors its listener spins on the
// failing accept() (100% CPU) and nobody, a side included, gets in. This
// watches the socket's connections (zmq_socket_monitor: accepted and
// disconnected, with their descriptors) and, when more than `cap` are open
// that have not carried a side's message, shuts down the excess
// (shutdown(2): ZeroMQ then sees the peer leave and closes it): those that
// received the fewest bytes (TCP_INFO), idle ones first, the oldest first
// among equals. A side sends its greeting at once and is admitted by its
// first message, so idle strangers never push it out, however many; strangers
// that send partial greetings compete with it only during its handshake, and
// then the side reconnects.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>
#include <zmq.hpp>

namespace hfmpm::coupling {

// The cap for this process: at most 256 connections, and at most half of what
// the open-file limit (RLIMIT_NOFILE) leaves after 64 for the program itself.
std::size_t connection_cap_for_this_process();

class ConnectionCap {
 public:
  // Watches `socket` (before it binds; from the thread that owns it). `told`
  // hears about dropped connections, at most once a second (another thread).
  ConnectionCap(zmq::context_t& context, zmq::socket_t& socket, std::size_t cap,
                std::function<void(const std::string&)> told);
  ~ConnectionCap();  // from the socket's thread, before the socket closes
  ConnectionCap(const ConnectionCap&) = delete;
  ConnectionCap& operator=(const ConnectionCap&) = delete;

  // A side's message came through the connection on `fd`: it is never dropped.
  void admit(int fd);

 private:
  void watch(zmq::socket_t& events);

  zmq::socket_t& socket_;
  std::size_t cap_;
  std::function<void(const std::string&)> told_;
  std::mutex mutex_;
  std::vector<int> admitted_;  // told by admit(), taken by the watcher
  int last_admitted_ = -1;     // admit()'s thread only: skip repeats
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace hfmpm::coupling
