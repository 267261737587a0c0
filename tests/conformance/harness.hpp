// The conformance harness: a fake coupler (ROUTER control socket, heartbeats,
// the step schedule) and a fake opposite side (PAIR data socket) around one
// launch of the program under test. Every wait has a timeout; a broken rule
// throws CheckFailure with a sentence that says what was due and what came.
// Defined in harness.cpp (launch, control plane, handshake) and data_plane.cpp.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>
#include <zmq.hpp>

#include "hfmpm/coupling/process.hpp"
#include "hfmpm/protocol.pb.h"
#include "hfmpm/runtime/zmq_transport.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::conformance {

using coupling::Clock;

// Waits (s). A check that runs into one of these fails.
inline constexpr double kStartTimeout = 10;    // Hello after launch
inline constexpr double kMessageTimeout = 10;  // Listening, Ready, a DataFrame, a StepReport
inline constexpr double kErrorTimeout = 3;     // Error after bad input, and the exit after it
inline constexpr double kShutdownTimeout = 2;  // exit after Shutdown

// A rule of the protocol was broken (or a wait timed out).
class CheckFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
[[noreturn]] void fail(const std::string& why);
std::string fmt(double value);  // shortest text that reads back bit for bit

// What the conformance program was asked to test.
struct Config {
  protocol::Role role = protocol::ROLE_UNSPECIFIED;
  std::string program;
  std::string scene_path;
  std::vector<std::string> overrides;  // --set KEY=VALUE, before each check's own
  bool tcp = false;
  std::string scratch;  // fresh directory of this run
};

// State shared by the launches of one check (their logs are shown if it fails).
struct Context {
  const Config& config;
  std::string check;
  std::vector<std::string> logs;
  int launches = 0;
};

// The opposite side, played by the conformance program.
class FakePeer {
 public:
  virtual ~FakePeer() = default;
  // Checks a frame from the side under test against the protocol; throws CheckFailure.
  virtual void check(const protocol::DataFrame& frame) = 0;
  // Our frame for `step` (the state after it, at time t).
  virtual protocol::DataFrame make(std::uint64_t step, double t) = 0;
  // Checks the side's Diagnostics (Ready, StepReport) against the frames exchanged so far.
  virtual void check_diagnostics(const protocol::Diagnostics& diagnostics, const std::string& where) const = 0;
  virtual std::size_t frames_checked() const = 0;
  virtual std::size_t growth_events() const = 0;  // frames in which a crack grew
};
std::unique_ptr<FakePeer> make_fake_fluid(const scene::Scene& scene);  // solid_checks.cpp
std::unique_ptr<FakePeer> make_fake_solid(const scene::Scene& scene);  // fluid_checks.cpp

struct Beat {
  Clock::time_point at;
  std::string from;  // routing id
  protocol::Heartbeat heartbeat;
};

struct LaunchOptions {
  std::vector<std::string> overrides;  // scene overrides of this launch
  std::vector<std::string> args;       // extra command-line arguments
};

// One launch of the program under test, with the fake coupler and the fake peer.
class Session {
 public:
  explicit Session(Context& context, const LaunchOptions& options = {});
  ~Session();  // SIGKILL and reap the program if it still runs
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const scene::Scene& scene() const { return scene_; }
  protocol::Role role() const { return role_; }
  const std::string& side() const { return side_; }  // "solid" or "fluid": its routing id
  FakePeer& peer() { return *peer_; }

  // ---------------------------------------------------------- control plane
  // Next message from the side's control socket other than a heartbeat; nullopt after timeout_s.
  std::optional<protocol::Envelope> poll_control(double timeout_s);
  // The next such message, which must be `expected`; `context` says when (for the failure text).
  protocol::Envelope expect_control(protocol::Envelope::BodyCase expected, double timeout_s,
                                    const std::string& context);
  void send_control(const protocol::Envelope& envelope);
  void send_control_frames(const std::vector<std::string>& frames);  // raw, after the routing id
  void set_heartbeats(bool on) { heartbeats_ = on; }
  const std::vector<Beat>& beats() const { return beats_; }
  Clock::time_point last_sent() const { return last_sent_; }

  // -------------------------------------------------------------- handshake
  // The first message, which must be a valid Hello from routing id side() claiming `version`.
  protocol::Hello expect_hello(std::uint32_t version = 1);
  // Welcome with the role's data plane (solid: BIND, fluid: CONNECT to our socket).
  void send_welcome();
  // Solid: expects Listening after Welcome and connects the data plane to its endpoint.
  void connect_to_listening();
  // expect_hello + send_welcome + the step-0 exchange + Ready, all checked. `strict`
  // also checks that nothing comes early (Ready before the exchange, data before ours).
  void start(bool strict = false);
  const protocol::Hello& hello() const { return hello_; }
  const protocol::Ready& ready() const { return ready_; }
  const std::string& data_endpoint() const { return data_endpoint_; }
  Clock::time_point welcome_sent_at() const { return welcome_sent_at_; }

  // ------------------------------------------------------------- data plane
  // The side's next frame. Control messages meanwhile are kept for poll_control; an Error fails.
  std::optional<protocol::DataFrame> poll_frame(double timeout_s);
  // Its frame for `step` at time t, with the right payload; then peer().check.
  protocol::DataFrame expect_frame(std::uint64_t step, double t);
  void send_frame(const protocol::DataFrame& frame);
  void send_data_bytes(const std::string& bytes);
  // One exchange at `step` in the order the scheme prescribes, both frames checked.
  void exchange(std::uint64_t step, double t);
  // At `step`, the conformance peer sends its frame before it waits for the side's
  // (a fluid under test: step 0, and every exchange under Gauss-Seidel).
  bool peer_sends_first(std::uint64_t step) const;
  // Jacobi as it happens in a run: both sides step at once, so the peer's frame for step n
  // may arrive before the side has sent its own. With this on the peer always sends first.
  void set_peer_early(bool on) { peer_early_ = on; }

  // --------------------------------------------------------------- schedule
  std::uint64_t step() const { return step_; }
  double t() const { return t_; }
  double dt() const { return dt_; }
  std::uint32_t exchange_interval() const { return exchange_interval_; }
  // Sends StepCommand{step(), num_steps, t(), dt()}; returns the time after each step
  // (index i: after step step()+i+1), accumulated as t += dt like the sides do.
  std::vector<double> send_command(std::uint32_t num_steps, bool write_output = false);
  // One StepCommand end to end: every exchange, then the StepReport, all checked.
  protocol::StepReport run_command(std::uint32_t num_steps, bool write_output = false);

  // ---------------------------------------------------------------- process
  // Waits for the program to end, taking control messages meanwhile (Errors are kept).
  bool wait_exit(double timeout_s);
  std::optional<std::string> ended();  // "exited with status 3", or nullopt while running
  std::string status_note();           // " (the program exited with status 3)" or ""
  // ": the program exited with status 3 (log: ...)" if it has ended, else " within 10 s".
  std::string waited(double timeout_s);
  // Seconds from `since` to when the end was seen (polled every 20 ms), or -1.
  double seconds_to_exit(Clock::time_point since) const;
  std::optional<int> exit_status() const { return process_->exit_status(); }
  const std::vector<protocol::Error>& errors() const { return errors_; }
  const std::string& dir() const { return dir_; }

 private:
  std::optional<protocol::Envelope> take(const coupling::Routed& routed);
  void beat_if_due();
  bool gone();
  std::chrono::milliseconds wait_slice(Clock::time_point deadline) const;

  Context& context_;
  protocol::Role role_;
  std::string side_, dir_, control_endpoint_, data_endpoint_;
  scene::Scene scene_;
  zmq::context_t zmq_{1};
  zmq::socket_t router_;
  std::optional<zmq::socket_t> data_;
  std::unique_ptr<coupling::ChildProcess> process_;
  std::unique_ptr<FakePeer> peer_;
  protocol::Hello hello_;
  protocol::Ready ready_;
  bool joined_ = false;
  bool heartbeats_ = true;
  bool gauss_seidel_ = false;
  bool peer_early_ = false;
  double heartbeat_interval_s_ = 0.5;
  std::uint64_t beat_sequence_ = 0;
  std::uint64_t output_frame_ = 0;
  Clock::time_point last_sent_ = Clock::now();
  Clock::time_point welcome_sent_at_ = Clock::now();
  std::vector<Beat> beats_;
  std::vector<protocol::Error> errors_;
  std::deque<protocol::Envelope> pending_;  // control messages that came while a frame was due
  std::optional<Clock::time_point> ended_at_;
  std::uint64_t step_ = 0;
  double t_ = 0, dt_ = 0;
  std::uint32_t exchange_interval_ = 1;
};

// A readable one-line account of a message ("error (protocol): ...", "step_report").
std::string describe(const protocol::Envelope& envelope);

}  // namespace hfmpm::conformance
