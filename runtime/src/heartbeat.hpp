// Private to the side runtime: the thread that sends a side's heartbeats on
// its own link, so the coupler hears from the side while it computes.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hfmpm/proto/envelope.hpp"
#include "hfmpm/runtime/transport.hpp"

namespace hfmpm::coupling {

// Heartbeat interval before the scene's is known (between Hello and Welcome).
// The scene validator keeps heartbeat_timeout_s >= 0.5 s, well above it.
constexpr double kFirstHeartbeatIntervalS = 0.1;

// Sends Heartbeat on its own socket at an interval until stopped.
class HeartbeatThread {
 public:
  HeartbeatThread(Transport& transport, const std::string& endpoint, protocol::Role role,
                  const std::atomic<std::uint64_t>& step, const std::atomic<bool>& waiting,
                  const std::optional<CurveKeys>& curve)
      : thread_([this, &transport, endpoint, role, &step, &waiting, curve] {
          const auto link = transport.connect_heartbeat(endpoint, role, curve);
          std::uint64_t sequence = 0;
          std::unique_lock lock(mutex_);
          while (!stop_) {
            protocol::Envelope envelope;
            auto* beat = envelope.mutable_heartbeat();
            beat->set_role(role);
            beat->set_sequence(++sequence);
            beat->set_step(step.load());
            beat->set_waiting_for_peer(waiting.load());
            (void)link->send_bytes(proto::encode(envelope), false);
            wake_.wait_for(lock, std::chrono::duration<double>(interval_s_.load()), [this] { return stop_; });
          }
        }) {}
  ~HeartbeatThread() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  HeartbeatThread(const HeartbeatThread&) = delete;
  HeartbeatThread& operator=(const HeartbeatThread&) = delete;
  void set_interval(double seconds) { interval_s_ = seconds; }

 private:
  std::atomic<double> interval_s_{kFirstHeartbeatIntervalS};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace hfmpm::coupling
