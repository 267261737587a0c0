#include "hfmpm/runtime/side_runtime.hpp"

#include <malloc.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "exchange_log.hpp"
#include "heartbeat.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/runtime/coupling_scheme.hpp"
#include "hfmpm/runtime/zmq_transport.hpp"
#include "side_checkpoint.hpp"
#include "side_checks.hpp"

namespace hfmpm::coupling {
namespace {

using std::chrono::microseconds;

// The coupler asked this side to stop.
struct ShutdownRequested {
  bool error = false;
};
// Nothing from the coupler (not even a heartbeat) for the heartbeat timeout.
struct CouplerLost {
  std::string what;
};

microseconds to_us(double seconds) { return microseconds(static_cast<std::int64_t>(seconds * 1e6)); }

class SideRuntime {
 public:
  SideRuntime(SideModel& model, const SideOptions& options)
      : model_(model),
        options_(options),
        transport_(options.transport ? options.transport : make_zmq_transport()),
        control_(transport_->connect_control(options.control_endpoint, options.role, options.curve)),
        role_(std::string(proto::role_name(options.role))),
        peer_(options.role == protocol::SOLID ? "fluid" : "solid") {}

  int run() {
    try {
      handshake();
      start();
      loop();
      finish();
      return kSideOk;
    } catch (const ShutdownRequested& shutdown) {
      finish();
      return shutdown.error ? kSideStoppedOnError : kSideOk;
    } catch (const CouplerLost& lost) {
      std::cerr << role_ << ": " << lost.what << "; exiting\n";
      return kSideCouplerLost;
    } catch (const proto::ProtocolError& e) {
      return fail("protocol", e.what(), kSideProtocol);
    } catch (const InputError& e) {
      return fail("input", e.what(), kSideInput);
    } catch (const std::exception& e) {
      return fail("side", e.what(), kSideFailed);
    }
  }

 private:
  // The model's finish() runs only for a model that was set up.
  void finish() {
    if (set_up_) model_.finish();
  }

  int fail(const std::string& what, const std::string& message, int code) {
    std::cerr << role_ << " side error (" << what << ") at step " << step_ << ": " << message << "\n";
    try {
      protocol::Envelope envelope;
      auto* error = envelope.mutable_error();
      error->set_who(options_.role);
      error->set_what(what);
      error->set_where("step " + std::to_string(step_));
      error->set_message(message);
      error->set_step(step_);
      control_->send(envelope);
    } catch (...) {
      // The coupler may already be gone; the exit code still tells.
    }
    return code;
  }

  // ------------------------------------------------------------ handshake
  void handshake() {
    protocol::Envelope hello_envelope;
    auto* hello = hello_envelope.mutable_hello();
    hello->set_role(options_.role);
    hello->set_protocol_version(options_.protocol_version);
    hello->set_scene_schema_version(options_.scene_schema_version);
    hello->set_implementation(options_.implementation);
    hello->set_implementation_version(options_.implementation_version);
    for (const auto& c : options_.capabilities) hello->add_capabilities(c);
    if (model_.can_checkpoint()) hello->add_capabilities(std::string(kCheckpointCapability));
    hello->set_host(host_name());
    hello->set_pid(getpid());
    control_->send(hello_envelope);
    // Repeats never wait: a DEALER with no connected peer (its connection
    // refused, or its CURVE handshake failed) blocks a send until one comes.
    std::string hello_bytes;
    hello_envelope.SerializeToString(&hello_bytes);
    for (int k = 0; k < options_.extra_hellos; ++k) control_->send_bytes(hello_bytes, false);
    // From now on the coupler hears from this side even during a long setup.
    heartbeat_ = std::make_unique<HeartbeatThread>(*transport_, options_.control_endpoint, options_.role,
                                                   heartbeat_step_, waiting_for_peer_, options_.curve);

    const auto deadline = Clock::now() + to_us(options_.welcome_timeout_s);
    const auto repeat = to_us(options_.hello_repeat_s);
    auto next_hello = Clock::now() + repeat;
    while (true) {
      const auto now = Clock::now();
      const auto left = std::chrono::duration_cast<microseconds>(deadline - now);
      if (left.count() <= 0) {
        throw CouplerLost{"no answer to Hello from the coupler at " + options_.control_endpoint + " within " +
                          std::to_string(options_.welcome_timeout_s) + " s"};
      }
      if (now >= next_hello) {  // unanswered: the first may have been lost (SideOptions::hello_repeat_s)
        control_->send_bytes(hello_bytes, false);
        next_hello = now + repeat;
      }
      const auto until_repeat = std::chrono::duration_cast<microseconds>(next_hello - now);
      auto envelope = control_->receive("the coupler", std::min(left, std::max(until_repeat, microseconds(1))));
      if (!envelope || envelope->has_heartbeat()) continue;
      if (envelope->has_reject()) {
        std::cerr << role_ << ": the coupler rejected this side: " << envelope->reject().reason() << "\n";
        throw ShutdownRejected{};
      }
      if (envelope->has_shutdown()) throw ShutdownRequested{envelope->shutdown().error()};
      if (!envelope->has_welcome()) unexpected(*envelope, "Welcome or Reject");
      welcome_ = envelope->welcome();
      if (welcome_.protocol_version() != options_.protocol_version) {
        throw proto::ProtocolError("the coupler's Welcome says protocol version " +
                                   std::to_string(welcome_.protocol_version()) + "; this side speaks version " +
                                   std::to_string(options_.protocol_version));
      }
      if (welcome_.scene_schema_version() != options_.scene_schema_version) {
        throw proto::ProtocolError("the coupler's Welcome carries a scene of schema version " +
                                   std::to_string(welcome_.scene_schema_version()) + "; this side was built with " +
                                   std::to_string(options_.scene_schema_version));
      }
      return;
    }
  }

  [[noreturn]] void unexpected(const protocol::Envelope& envelope, const std::string& expected) {
    throw proto::ProtocolError("unexpected " + std::string(proto::body_name(envelope)) +
                               " message from the coupler while waiting for " + expected);
  }

  void start() {
    const auto& scene = welcome_.scene();
    heartbeat_timeout_ = to_us(scene.coupling().heartbeat_timeout_s());
    spin_ = microseconds(scene.coupling().spin_us());

    const std::string& chosen = options_.output_dir.empty() ? welcome_.output_dir() : options_.output_dir;
    const std::string output_dir = chosen.empty() ? std::string(".") : chosen;
    std::filesystem::create_directories(output_dir);
    const bool restart = welcome_.has_restart();
    if (restart) model_.will_restart();
    model_.setup(scene, output_dir);
    set_up_ = true;
    output_dir_ = output_dir;
    if (restart) {
      // The state after the checkpoint's step, with what each side last
      // received from the other: no step-0 exchange.
      const auto& r = welcome_.restart();
      step_ = r.step();
      t_ = r.t();
      heartbeat_step_ = step_;
      model_.load_checkpoint(checkpoint_path(output_dir_, r.directory(), role_), stamp(r.step(), r.t()));
    }
    if (scene.output().exchange_log()) {
      log_ = std::make_unique<ExchangeLog>(output_dir, role_,
                                           restart ? static_cast<std::int64_t>(welcome_.restart().step()) : -1);
    }

    heartbeat_->set_interval(scene.coupling().heartbeat_interval_s());
    last_from_coupler_ = Clock::now();

    const auto mode = welcome_.data_plane().mode();
    if (mode != protocol::DataPlane::NONE && mode != protocol::DataPlane::BIND &&
        mode != protocol::DataPlane::CONNECT) {
      throw proto::ProtocolError("Welcome.data_plane.mode = " + std::to_string(mode) +
                                 "; allowed: NONE, BIND, CONNECT");
    }
    if (mode == protocol::DataPlane::BIND && options_.role != protocol::SOLID) {
      throw proto::ProtocolError("Welcome asks a " + role_ + " side to bind the data plane; only the solid binds");
    }
    const bool has_peer = mode == protocol::DataPlane::BIND || mode == protocol::DataPlane::CONNECT;
    scheme_.emplace(scene.coupling().scheme(), scene.coupling().exchange_interval(), has_peer);
    if (has_peer) {
      // CURVE on tcp only: a bound data link admits only the other side, holding the same key pair.
      const bool tcp = welcome_.data_plane().endpoint().rfind("tcp://", 0) == 0;
      std::optional<CurveKeys> curve;
      if (tcp) curve = options_.curve;
      const auto limit = data_plane_message_limit(welcome_.scene());
      if (mode == protocol::DataPlane::BIND) {
        data_ = transport_->bind_data(welcome_.data_plane().endpoint(), limit, curve);
        std::string host = options_.advertise_host;
        if (host.empty()) {
          host = tcp_host(options_.control_endpoint);
          if (host.empty() || host == "*" || host == "0.0.0.0") host = host_name();
        }
        std::string bound = data_->endpoint();
        if (tcp_host(bound) == "0.0.0.0") bound = advertise(bound, host);
        protocol::Envelope listening;
        listening.mutable_listening()->set_data_endpoint(bound);
        control_->send(listening);
      } else {
        data_ = transport_->connect_data(welcome_.data_plane().endpoint(), limit, curve);
      }
      // Initial exchange (step 0), in the scheme's order; none on a restart.
      for (const auto& action :
           restart ? std::vector<CouplingScheme::Action>{} : scheme_->initial_exchange(options_.role)) {
        if (action.kind == CouplingScheme::Action::Publish) {
          publish();
        } else {
          consume(action.step);
        }
      }
    }
    protocol::Envelope ready;
    ready.mutable_ready()->set_stable_dt(model_.stable_dt());
    ready.mutable_ready()->set_stable_dt_limit(model_.stable_dt_limit());
    proto::to_proto(model_.diagnostics(), ready.mutable_ready()->mutable_diagnostics());
    control_->send(ready);
  }

  // ------------------------------------------------------------ step loop
  void loop() {
    while (true) {
      const auto envelope = next_command();
      if (!envelope.has_step_command()) unexpected(envelope, "StepCommand or Shutdown");
      execute(envelope.step_command());
    }
  }

  // Has the coupler been silent for heartbeat_timeout_? A wait that took far
  // longer than it asked for means this process did not run (stopped, or
  // starved; with --transport inproc the coupler stopped with it): that time
  // is not the coupler's silence, and its clock starts again.
  bool coupler_silent(Clock::time_point wait_start, microseconds asked) {
    const auto now = Clock::now();
    if (now - wait_start > asked + asked / 2 + std::chrono::milliseconds(100)) {
      last_from_coupler_ = now;
      return false;
    }
    return now - last_from_coupler_ > heartbeat_timeout_;
  }

  // Next message from the coupler that is not a heartbeat. Shutdown throws.
  protocol::Envelope next_command() {
    while (true) {
      const auto wait_start = Clock::now();
      auto envelope = control_->receive("the coupler", heartbeat_timeout_);
      if (!envelope) {
        if (coupler_silent(wait_start, heartbeat_timeout_)) {
          throw CouplerLost{"nothing from the coupler for " +
                            std::to_string(welcome_.scene().coupling().heartbeat_timeout_s()) + " s"};
        }
        continue;
      }
      last_from_coupler_ = Clock::now();
      if (envelope->has_heartbeat()) continue;
      if (envelope->has_shutdown()) throw ShutdownRequested{envelope->shutdown().error()};
      return *envelope;
    }
  }

  CheckpointStamp stamp(std::uint64_t step, double t) const {
    return checkpoint_stamp(options_, role_, welcome_.scene(), step, t);
  }

  void check_command(const protocol::StepCommand& command) const {
    check_step_command(command, step_, t_, scheme_->exchange_interval());
  }

  void execute(const protocol::StepCommand& command) {
    check_command(command);
    t_ = command.t();
    double compute_s = 0, exchange_s = 0;
    publish_compute_s_ = 0;
    // The steps, sends and waits of this block in the scheme's order.
    for (const auto& action : scheme_->block(options_.role, step_, command.num_steps())) {
      const auto start = Clock::now();
      switch (action.kind) {
        case CouplingScheme::Action::Advance:
          inject_fault(step_ + 1);
          model_.advance(command.dt());
          ++step_;
          heartbeat_step_ = step_;
          t_ += command.dt();
          compute_s += seconds_since(start);
          break;
        case CouplingScheme::Action::Publish:
          publish();
          exchange_s += seconds_since(start);
          break;
        case CouplingScheme::Action::Consume:
          consume(action.step);
          exchange_s += seconds_since(start);
          break;
      }
    }
    // What the model did inside publish() is compute, not exchange.
    compute_s += publish_compute_s_;
    exchange_s = std::max(0.0, exchange_s - publish_compute_s_);
    publish_compute_s_ = 0;
    if (command.write_output()) model_.write_output(command.output_frame(), t_);
    if (command.checkpoint()) {
      const std::string path = checkpoint_path(output_dir_, command.checkpoint_directory(), role_);
      compute_s += write_side_checkpoint(model_, path, stamp(step_, t_), role_);
    }

    protocol::Envelope envelope;
    auto* report = envelope.mutable_step_report();
    report->set_step(step_);
    report->set_t(t_);
    report->set_stable_dt(model_.stable_dt());
    report->set_stable_dt_limit(model_.stable_dt_limit());
    const std::string done = model_.done_reason();
    report->set_status(done.empty() ? protocol::StepReport::OK : protocol::StepReport::DONE);
    report->set_done_reason(done);
    proto::to_proto(model_.diagnostics(), report->mutable_diagnostics());
    for (const auto& notice : model_.notices()) {
      if (!notices_sent_.insert(notice.code).second) continue;
      auto* out = report->add_notices();
      out->set_code(notice.code);
      out->set_message(notice.message);
    }
    report->set_compute_s(compute_s);
    report->set_exchange_s(exchange_s);
    report->set_checkpoint_written(command.checkpoint());
    control_->send(envelope);
  }

  // ----------------------------------------------------------- data plane
  void publish() {
    protocol::Envelope envelope;
    auto* frame = envelope.mutable_data();
    frame->set_step(step_);
    frame->set_t(t_);
    const auto start = Clock::now();
    model_.publish(*frame);  // physics too: the MPM solid begins its next step here in IMPLICIT
    publish_compute_s_ += seconds_since(start);
    if (poison_next_frame_) {
      poison_next_frame_ = false;
      if (frame->has_crack() && frame->crack().cracks_size() > 0) {
        frame->mutable_crack()->mutable_cracks(0)->set_width(0, std::numeric_limits<double>::quiet_NaN());
      } else if (frame->has_fluid() && frame->fluid().cracks_size() > 0) {
        frame->mutable_fluid()->mutable_cracks(0)->set_pressure(0, std::numeric_limits<double>::quiet_NaN());
      }
    }
    send_data(envelope);
  }

  // A data link may not take a message until its peer is connected (a
  // ZeroMQ PAIR): wait for that while watching the coupler, as consume() does.
  void send_data(const protocol::Envelope& envelope) {
    const std::string bytes = proto::encode(envelope);
    while (!data_->send_bytes(bytes, false)) {
      PollItem items[] = {{data_.get(), true}, {control_.get(), false}};
      const auto wait_start = Clock::now();
      transport_->poll(items, std::chrono::duration_cast<std::chrono::milliseconds>(heartbeat_timeout_));
      if (items[1].ready) watch_coupler("to send data to the " + peer_ + " side");
      if (!items[0].ready && coupler_silent(wait_start, heartbeat_timeout_)) {
        throw CouplerLost{"nothing from the coupler for " +
                          std::to_string(welcome_.scene().coupling().heartbeat_timeout_s()) +
                          " s while waiting to send data to the " + peer_ + " side"};
      }
    }
  }

  // One message from the coupler while busy on the data plane: a heartbeat or Shutdown.
  void watch_coupler(const std::string& doing) {
    auto envelope = control_->receive("the coupler", microseconds(0));
    if (!envelope) return;
    last_from_coupler_ = Clock::now();
    if (envelope->has_shutdown()) throw ShutdownRequested{envelope->shutdown().error()};
    if (!envelope->has_heartbeat()) unexpected(*envelope, "nothing while waiting " + doing);
  }

  // Waits for the peer's frame of step `expected`, watching the coupler meanwhile.
  void consume(std::uint64_t expected) {
    struct Waiting {
      std::atomic<bool>& flag;
      explicit Waiting(std::atomic<bool>& f) : flag(f) { flag = true; }
      ~Waiting() { flag = false; }
    } waiting(waiting_for_peer_);
    PollItem items[] = {{data_.get(), false}, {control_.get(), false}};
    const auto spin_end = Clock::now() + spin_;
    while (true) {
      const bool spinning = Clock::now() < spin_end;
      const auto timeout = spinning ? std::chrono::milliseconds(0)
                                    : std::chrono::duration_cast<std::chrono::milliseconds>(heartbeat_timeout_);
      const auto wait_start = Clock::now();
      transport_->poll(items, timeout);
      if (items[0].ready) {
        auto envelope = data_->receive("the " + peer_ + " side (data plane)", microseconds(0));
        if (!envelope) continue;
        check_frame(*envelope, expected);
        model_.receive(envelope->data());  // validates the frame (throws ProtocolError)
        if (log_) log_->write(envelope->data());
        return;
      }
      if (items[1].ready) {
        watch_coupler("for data from the " + peer_ + " side");
        continue;
      }
      if (!spinning && coupler_silent(wait_start, std::chrono::duration_cast<microseconds>(timeout))) {
        throw CouplerLost{"nothing from the coupler for " +
                          std::to_string(welcome_.scene().coupling().heartbeat_timeout_s()) +
                          " s while waiting for the " + peer_ + " side's data"};
      }
    }
  }

  void check_frame(const protocol::Envelope& envelope, std::uint64_t expected) const {
    check_data_frame(envelope, options_.role, expected);
  }

  // ---------------------------------------------------------------- faults
  void inject_fault(std::uint64_t step) {
    if (act_on_fault(options_.fault, step, role_, *control_, data_.get())) poison_next_frame_ = true;
  }

 public:
  // Rejected at the handshake: not an error of this side's making, but not a run either.
  struct ShutdownRejected {};

 private:
  SideModel& model_;
  SideOptions options_;
  std::shared_ptr<Transport> transport_;  // before the links: outlives them
  std::unique_ptr<Link> control_;
  std::unique_ptr<Link> data_;  // with a peer only
  std::string role_, peer_;
  protocol::Welcome welcome_;
  std::unique_ptr<HeartbeatThread> heartbeat_;
  std::unique_ptr<ExchangeLog> log_;
  std::atomic<std::uint64_t> heartbeat_step_{0};
  std::atomic<bool> waiting_for_peer_{false};
  Clock::time_point last_from_coupler_ = Clock::now();
  microseconds heartbeat_timeout_{3'000'000};
  microseconds spin_{0};
  std::optional<CouplingScheme> scheme_;  // from the Welcome: the order of steps, sends and waits
  double publish_compute_s_ = 0;          // s in model_.publish since the last StepReport
  std::set<std::string> notices_sent_;    // codes already reported (each once per run)
  bool poison_next_frame_ = false;
  bool set_up_ = false;
  std::string output_dir_;  // where the model writes (checkpoints under it)
  std::uint64_t step_ = 0;
  double t_ = 0;
};

}  // namespace

int run_side(SideModel& model, const SideOptions& options) {
  // A side allocates and frees the same large buffers (frames of thousands of
  // crack particles) at every exchange. Keep freed memory in the process
  // instead of returning it to the kernel and faulting it back in each time:
  // measured at 5000 crack particles this halves the exchange cost.
  static const bool tuned = [] {
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
    return true;
  }();
  (void)tuned;
  try {
    SideRuntime runtime(model, options);
    try {
      return runtime.run();
    } catch (const SideRuntime::ShutdownRejected&) {
      return kSideProtocol;
    }
  } catch (const std::exception& e) {
    std::cerr << proto::role_name(options.role) << " side: " << e.what() << "\n";
    return kSideFailed;
  }
}

}  // namespace hfmpm::coupling
