// Private to the coupler: the state of one run and the steps it goes
// through. coupler.cpp: start, launch and shutdown; coupler_liveness.cpp:
// messages in, heartbeats, dead and stuck sides; coupler_schedule.cpp: the
// handshake and the step schedule.
#pragma once

#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/energy_watch.hpp"
#include "hfmpm/coupling/state_watch.hpp"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "hfmpm/coupling/process.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/coupling/stop_signals.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/runtime/coupling_scheme.hpp"
#include "hfmpm/runtime/curve.hpp"
#include "hfmpm/runtime/transport.hpp"
#include "hfmpm/runtime/zmq_transport.hpp"
#include "run_output.hpp"

namespace hfmpm::coupling::detail {

namespace fs = std::filesystem;
using std::chrono::microseconds;
using std::chrono::milliseconds;

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// A run cannot go on; the text names the side, the step and what happened.
struct RunFailure {
  std::string message;
};

// The operator asked the run to stop (a signal; RunOptions::stop_request).
struct RunInterrupted {
  int signal;
};

struct Side {
  protocol::Role role = protocol::ROLE_UNSPECIFIED;
  std::string name;  // routing id: "solid" or "fluid"
  bool expected = false;
  bool joined = false;
  int repeated_hellos = 0;  // Hellos after the first (a side repeats it until Welcome), ignored
  bool ready = false;
  bool stopping = false;
  std::string implementation;
  bool can_checkpoint = false;  // Hello lists the capability "checkpoint"
  std::string log_path;
  std::unique_ptr<ChildProcess> process;
  std::thread thread;
  std::shared_ptr<std::atomic<int>> thread_exit;  // in-process side: -1 while running
  Clock::time_point last_heard = Clock::now();
  Clock::time_point last_sent = Clock::now();
  std::uint64_t heartbeat_step = 0;
  bool waiting_for_peer = false;
  double stable_dt = kInf;
  std::string stable_dt_limit;  // what the side says sets its stable_dt
  SideDiagnostics diagnostics;
  std::optional<protocol::StepReport> report;
  std::string data_endpoint;
  double compute_s = 0, exchange_s = 0;
};

inline std::string random_id() {
  std::random_device device;
  std::ostringstream out;
  out << std::hex << device() << device();
  return out.str().substr(0, 12);
}

// ISO 8601, UTC, to the second: 2026-12-03T02:41:07Z.
inline std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32] = {};
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

inline bool loopback(const std::string& host) {
  return host == "localhost" || host.rfind("127.", 0) == 0 || host == "::1";
}

class Coupler {
 public:
  Coupler(const scene::Scene& scene, const RunOptions& options);
  ~Coupler();
  RunSummary run();

 private:
  // ---------------------------------------------------------------- start
  void prepare();
  void report_rest();
  std::string program_for(const Side& side) const;
  void launch_sides();

  // --------------------------------------------------------- messages in
  Side* side_named(const std::string& name);
  std::string at_step() const { return " at step " + std::to_string(step_); }
  // The step a side's fault came at, as near as the coupler knows: its last
  // heartbeat's step when that is past the start of the current command.
  std::string at_step(const Side& side) const {
    if (side.heartbeat_step <= step_) return at_step();
    return " at step " + std::to_string(side.heartbeat_step) + " (its last heartbeat; the command began at step " +
           std::to_string(step_) + ")";
  }

  std::string log_hint(const Side& side) const;

  // One message from a side, or nullopt after `wait`; runs the liveness checks.
  std::optional<std::pair<Side*, protocol::Envelope>> pump(microseconds wait);
  void housekeeping();
  // Throws RunInterrupted if a stop was requested.
  void check_stop_request() const;
  std::string ended_message(Side& side, const std::string& ended);

  // After a side ended: its last words, if it sent an Error before going.
  std::string drain_error_from(Side& side);
  void send_to(Side& side, const protocol::Envelope& envelope);
  [[noreturn]] void unexpected(const Side& side, const protocol::Envelope& envelope, const std::string& expected);

  // ------------------------------------------------------------ handshake
  void handshake();
  protocol::Envelope welcome_for(protocol::DataPlane::Mode mode, const std::string& endpoint) const;
  void on_handshake_message(Side& side, const protocol::Envelope& envelope);
  [[noreturn]] void reject(Side& side, const std::string& reason);

  // ------------------------------------------------------------- stepping
  double next_dt();
  void step_loop(RunSummary& summary);
  // The step loop's own state, kept in checkpoints.
  struct Schedule {
    double dt = 0;
    std::uint64_t frame = 1;
    double next_output = 0, next_checkpoint = 0;
    double mean_command_s = 0;
  };
  void save_checkpoint(const Schedule& schedule, const RunSummary& summary);
  void restore_checkpoint(Schedule& schedule, RunSummary& summary);
  void await_reports(std::uint64_t step, double t, double timeout_s);
  std::string hung_message(double timeout_s) const;

  // ------------------------------------------------------------- shutdown
  void stop_sides(bool error, const std::string& reason);

  scene::Scene scene_;
  RunOptions options_;
  // Shared with in-process side threads; before router_: outlives it. A side
  // thread left behind (stop_sides) keeps it alive: ZeroMQ's context then
  // ends with the process instead of waiting here for its sockets.
  std::shared_ptr<Transport> transport_;
  bool curve_ = false;  // tcp with CURVE: refusals are logged
  std::mutex refusals_mutex_;
  std::string refusals_;         // told by the ZAP thread, logged by housekeeping()
  std::string keys_dir_;         // the sides' key file of a launched tcp run (0700, removed at the end)
  std::string side_keys_;        // that file, passed to the sides with --keys
  std::uint64_t strangers_ = 0;  // messages from peers that are not a side (plain tcp)
  Clock::time_point last_stranger_log_{};
  std::unique_ptr<Router> router_;  // bound in prepare()
  Side sides_[2];
  std::string run_id_, output_dir_, control_endpoint_, data_bind_, ipc_dir_;
  Manifest manifest_{""};
  std::unique_ptr<History> history_;
  bool prepared_ = false;
  bool stopped_at_max_steps_ = false;
  bool stepping_ = false;  // in the step loop: stop requests are taken between control rounds
  // Largest fluid pressure change at frozen crack width over a report, and when (run.json).
  double max_coupling_lag_ = 0, max_coupling_lag_t_ = 0;
  std::string dt_limit_;                                 // "side: term" that set the last step
  std::map<std::string, std::uint64_t> dt_limit_steps_;  // steps taken under each limit
  double dt_min_ = kInf, dt_max_ = 0;
  Log log_;
  Progress progress_;
  microseconds heartbeat_interval_{500000}, heartbeat_timeout_{3000000};
  Clock::time_point start_ = Clock::now(), last_housekeeping_{};
  Clock::duration stalled_{};
  Clock::time_point stepping_start_ = Clock::now();  // the step loop's start
  double stepping_before_ =
      0;  // s of stepping before a restart's checkpoint  // time the coupler itself did not run (housekeeping())
  std::uint64_t step_ = 0;
  std::uint64_t heartbeats_sent_ = 0;
  std::unique_ptr<EnergyWatch> energy_;
  std::unique_ptr<RestWatch> rest_;          // dry runs: is the solid at rest at the end?
  std::unique_ptr<StateWatch> state_watch_;  // coupled runs: the fluid's end states
  // The end-state warnings so far, by code (run.json "warnings"; docs/stability.md).
  std::map<std::string, std::string> warnings_;
  void warn(const std::string& who, const std::string& code, const std::string& message);
  std::string done_reason_;  // a side said DONE: why (the run stops there)
  double t_ = 0;
};

}  // namespace hfmpm::coupling::detail
