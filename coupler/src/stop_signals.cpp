#include "hfmpm/coupling/stop_signals.hpp"

#include <pthread.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace hfmpm::coupling {
namespace {

std::atomic<int> requested{0};
std::mutex cleanup_mutex;
std::function<void(int)> cleanup;

sigset_t stop_set() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  return set;
}

}  // namespace

const std::atomic<int>& install_stop_signals() {
  static const bool installed = [] {
    // Blocked everywhere, taken by one waiting thread: no system call in the
    // coupler or an in-process side is interrupted (EINTR), and the handling
    // is ordinary code, not a signal handler.
    const sigset_t set = stop_set();
    if (const int rc = pthread_sigmask(SIG_BLOCK, &set, nullptr); rc != 0) {
      throw std::runtime_error(std::string("cannot block the stop signals: ") + std::strerror(rc));
    }
    std::thread([set] {
      for (;;) {
        int signal = 0;
        if (sigwait(&set, &signal) != 0) continue;
        int none = 0;
        if (requested.compare_exchange_strong(none, signal)) continue;  // the first: stop at the next round
        // The second: at once. The message is written with write(2), which
        // cannot block on a lock another thread holds.
        const std::string line = "\nhfmpm: " + signal_name(signal) + " again: stopping at once\n";
        (void)!write(STDERR_FILENO, line.data(), line.size());
        {
          std::lock_guard<std::mutex> lock(cleanup_mutex);
          try {
            if (cleanup) cleanup(signal);
          } catch (...) {
          }
        }
        _exit(exit_status_for_signal(signal));
      }
    }).detach();
    return true;
  }();
  (void)installed;
  return requested;
}

void set_abort_cleanup(std::function<void(int)> f) {
  std::lock_guard<std::mutex> lock(cleanup_mutex);
  cleanup = std::move(f);
}

std::string signal_name(int signal) {
  const char* abbrev = sigabbrev_np(signal);
  return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(signal);
}

}  // namespace hfmpm::coupling
