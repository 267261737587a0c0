#include "hfmpm/coupling/coupler.hpp"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "hfmpm/coupling/process.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/coupling/transport.hpp"
#include "hfmpm/proto/convert.hpp"
#include "run_output.hpp"

namespace hfmpm::coupling {

double RunSummary::overhead_per_step_us() const {
  if (steps == 0) return 0;
  return 1e6 * std::max(0.0, stepping_wall_s - std::max(solid_compute_s, fluid_compute_s)) / static_cast<double>(steps);
}

namespace {

namespace fs = std::filesystem;
using std::chrono::microseconds;
using std::chrono::milliseconds;

constexpr double kInf = std::numeric_limits<double>::infinity();

// A run cannot go on; the text names the side, the step and what happened.
struct RunFailure {
  std::string message;
};

struct Side {
  protocol::Role role = protocol::ROLE_UNSPECIFIED;
  std::string name;  // routing id: "solid" or "fluid"
  bool expected = false;
  bool joined = false;
  bool ready = false;
  bool stopping = false;
  std::string implementation;
  std::string log_path;
  std::unique_ptr<ChildProcess> process;
  std::thread thread;
  std::shared_ptr<std::atomic<int>> thread_exit;  // in-process side: -1 while running
  Clock::time_point last_heard = Clock::now();
  Clock::time_point last_sent = Clock::now();
  std::uint64_t heartbeat_step = 0;
  bool waiting_for_peer = false;
  double stable_dt = kInf;
  SideDiagnostics diagnostics;
  std::optional<protocol::StepReport> report;
  std::string data_endpoint;
  double compute_s = 0, exchange_s = 0;
};

std::string random_id() {
  std::random_device device;
  std::ostringstream out;
  out << std::hex << device() << device();
  return out.str().substr(0, 12);
}

std::string host_name() {
  char buffer[256] = {};
  return gethostname(buffer, sizeof(buffer) - 1) == 0 ? std::string(buffer) : std::string("localhost");
}

bool loopback(const std::string& host) {
  return host == "localhost" || host.rfind("127.", 0) == 0 || host == "::1";
}

class Coupler {
 public:
  Coupler(const scene::Scene& scene, const RunOptions& options)
      : scene_(scene), options_(options), router_(*context_, zmq::socket_type::router),
        progress_(options.progress, scene.time().end_s()) {
    sides_[0].role = protocol::SOLID;
    sides_[0].name = "solid";
    sides_[0].expected = true;
    sides_[1].role = protocol::FLUID;
    sides_[1].name = "fluid";
    sides_[1].expected = scene.has_fluid();
    heartbeat_interval_ = microseconds(static_cast<std::int64_t>(scene.coupling().heartbeat_interval_s() * 1e6));
    heartbeat_timeout_ = microseconds(static_cast<std::int64_t>(scene.coupling().heartbeat_timeout_s() * 1e6));
  }

  ~Coupler() {
    for (auto& side : sides_) {
      if (side.thread.joinable()) side.thread.join();
    }
    // Terminating a context waits for every socket to close; a detached side
    // thread may never close its own, so its context is left to process exit.
    if (leak_context_) (void)context_.release();
    if (!ipc_dir_.empty()) {
      std::error_code ignored;
      fs::remove_all(ipc_dir_, ignored);
    }
  }

  RunSummary run() {
    const auto start = Clock::now();
    RunSummary summary;
    try {
      prepare();
      handshake();
      step_loop(summary);
      stop_sides(false, "end of run");
      summary.ok = true;
      manifest_.set("status", stopped_at_max_steps_ ? "stopped at time.max_steps" : "completed");
    } catch (const RunFailure& failure) {
      summary.error = failure.message;
    } catch (const std::exception& e) {
      summary.error = std::string("coupler: ") + e.what();
    }
    if (!summary.ok) {
      log_.file_only("run failed: " + summary.error);
      stop_sides(true, summary.error);
      manifest_.set("status", "failed");
      manifest_.set("error", summary.error);
    }
    progress_.finish();
    summary.wall_s = seconds_since(start);
    summary.steps = step_;
    summary.t = t_;
    summary.solid_compute_s = sides_[0].compute_s;
    summary.fluid_compute_s = sides_[1].compute_s;
    summary.solid_exchange_s = sides_[0].exchange_s;
    summary.fluid_exchange_s = sides_[1].exchange_s;
    manifest_.set_number("steps", static_cast<double>(step_));
    manifest_.set_number("end_time_s", t_);
    manifest_.set_number("wall_s", summary.wall_s);
    if (prepared_) manifest_.save();
    return summary;
  }

 private:
  // ---------------------------------------------------------------- start
  void prepare() {
    fs::create_directories(options_.output_dir);
    output_dir_ = fs::absolute(options_.output_dir).string();
    log_.open(output_dir_ + "/coupler.log", options_.progress);
    manifest_ = Manifest(output_dir_ + "/run.json");
    run_id_ = random_id();
    manifest_.set("run_id", run_id_);
    manifest_.set("scene", options_.scene_path);
    manifest_.set("scene_name", scene_.name());
    manifest_.set("status", "starting");
    std::string overrides;
    for (const auto& o : options_.overrides) overrides += (overrides.empty() ? "" : " ") + o;
    manifest_.set("overrides", overrides);
    manifest_.set_number("protocol_version", proto::kProtocolVersion);
    prepared_ = true;
    history_ = std::make_unique<History>(output_dir_ + "/history.csv");  // header now: always readable

    router_.set(zmq::sockopt::linger, kLingerMs);
    router_.set(zmq::sockopt::router_mandatory, 1);
    const auto transport = scene_.coupling().transport();
    std::string bind = options_.bind_endpoint;
    if (bind.empty()) {
      if (transport == scene::Coupling::INPROC) {
        bind = "inproc://hfmpm-" + run_id_ + "-control";
        data_bind_ = "inproc://hfmpm-" + run_id_ + "-data";
      } else if (transport == scene::Coupling::TCP) {
        bind = "tcp://" + scene_.coupling().tcp_host() + ":*";
      } else {
        char pattern[] = "/tmp/hfmpm-XXXXXX";
        if (!mkdtemp(pattern)) throw std::runtime_error("cannot create a directory for ipc sockets in /tmp");
        ipc_dir_ = pattern;
        bind = "ipc://" + ipc_dir_ + "/control";
        data_bind_ = "ipc://" + ipc_dir_ + "/data";
      }
    }
    try {
      router_.bind(bind);
    } catch (const zmq::error_t& e) {
      throw RunFailure{"cannot bind the control endpoint " + bind + ": " + e.what()};
    }
    control_endpoint_ = router_.get(zmq::sockopt::last_endpoint);
    if (data_bind_.empty()) {
      const std::string host = tcp_host(control_endpoint_);
      if (!host.empty()) {
        data_bind_ = loopback(host) ? "tcp://" + host + ":*" : "tcp://0.0.0.0:*";
      } else if (control_endpoint_.rfind("ipc://", 0) == 0) {
        data_bind_ = control_endpoint_ + "-data";
      } else {
        data_bind_ = "inproc://hfmpm-" + run_id_ + "-data";
      }
    }
    manifest_.set("control_endpoint", control_endpoint_);
    manifest_.set("output_dir", output_dir_);
    if (options_.on_bound) options_.on_bound(control_endpoint_);

    if (options_.launch) {
      launch_sides();
    } else {
      // Printed even when quiet: the person starting the sides needs the endpoint.
      std::string reachable = control_endpoint_;
      if (tcp_host(reachable) == "0.0.0.0") reachable = advertise(reachable, host_name());
      const std::string line = "waiting for sides at " + control_endpoint_ + " (start each with --connect " +
                               reachable + ")";
      std::cerr << "hfmpm: " << line << std::endl;
      log_.file_only(line);
    }
    manifest_.save();
  }

  std::string program_for(const Side& side) const {
    const std::string& chosen = side.role == protocol::SOLID ? options_.solid_program : options_.fluid_program;
    if (!chosen.empty()) return chosen;
    const std::string dir = options_.executable_dir.empty() ? executable_dir() : options_.executable_dir;
    if (side.role == protocol::SOLID) {
      return dir + (scene_.solid().has_mpm() ? "/hfmpm-solid" : "/hfmpm-prescribed-solid");
    }
    return dir + "/hfmpm-prescribed-fluid";
  }

  void launch_sides() {
    const bool inproc = scene_.coupling().transport() == scene::Coupling::INPROC;
    for (auto& side : sides_) {
      if (!side.expected) continue;
      if (inproc) {
        if (!options_.inproc_factory) throw RunFailure{"the in-process transport needs a model factory"};
        auto model = std::shared_ptr<SideModel>(options_.inproc_factory(side.role, scene_));
        side.thread_exit = std::make_shared<std::atomic<int>>(-1);
        SideOptions side_options;
        side_options.role = side.role;
        side_options.control_endpoint = control_endpoint_;
        side_options.implementation = std::string("in-process ") + side.name;
        side_options.context = context_.get();
        side.thread = std::thread([model, side_options, exit = side.thread_exit] { *exit = run_side(*model, side_options); });
        manifest_.set(side.name + "_program", "in-process thread");
        continue;
      }
      std::vector<std::string> args{"--connect", control_endpoint_, "--out", output_dir_};
      const auto& extra = side.role == protocol::SOLID ? scene_.coupling().solid_args() : scene_.coupling().fluid_args();
      args.insert(args.end(), extra.begin(), extra.end());
      side.log_path = output_dir_ + "/" + side.name + ".log";
      const std::string program = program_for(side);
      try {
        side.process = std::make_unique<ChildProcess>(program, args, side.log_path);
      } catch (const std::exception& e) {
        throw RunFailure{"cannot start the " + side.name + " side: " + e.what()};
      }
      manifest_.set(side.name + "_program", program);
      manifest_.set_number(side.name + "_pid", side.process->pid());
    }
  }

  // --------------------------------------------------------- messages in
  Side* side_named(const std::string& name) {
    for (auto& side : sides_) {
      if (side.expected && side.name == name) return &side;
    }
    return nullptr;
  }

  std::string at_step() const { return " at step " + std::to_string(step_); }

  std::string log_hint(const Side& side) const {
    return side.log_path.empty() ? "" : " (its output is in " + side.log_path + ")";
  }

  // One message from a side, or nullopt after `wait`; runs the liveness checks.
  std::optional<std::pair<Side*, protocol::Envelope>> pump(microseconds wait) {
    housekeeping();
    auto routed = receive_routed(router_, wait);
    if (!routed) return std::nullopt;
    const auto dot = routed->peer.find('.');
    const std::string base = routed->peer.substr(0, dot);
    Side* side = side_named(base);
    const bool heartbeat_socket = dot != std::string::npos && routed->peer.substr(dot) == ".hb";
    if (!side || (dot != std::string::npos && !heartbeat_socket)) {
      log_("ignored a message from an unknown peer '" + routed->peer + "' (" + std::to_string(routed->payload.size()) +
           " bytes); only the solid and fluid sides may talk to the coupler");
      return std::nullopt;
    }
    protocol::Envelope envelope;
    try {
      if (!routed->well_framed) throw proto::ProtocolError("a multi-frame message; the protocol sends one frame");
      envelope = proto::decode(routed->payload.data(), routed->payload.size(), "the " + side->name + " side");
    } catch (const proto::ProtocolError& e) {
      throw RunFailure{"the " + side->name + " side broke the protocol" + at_step() + ": " + e.what()};
    }
    side->last_heard = Clock::now();
    if (envelope.has_heartbeat()) {
      if (envelope.heartbeat().role() != side->role) {
        throw RunFailure{"the " + side->name + " side sent a heartbeat claiming role " +
                         std::string(proto::role_name(envelope.heartbeat().role()))};
      }
      side->heartbeat_step = envelope.heartbeat().step();
      side->waiting_for_peer = envelope.heartbeat().waiting_for_peer();
      return std::nullopt;
    }
    if (heartbeat_socket) {
      throw RunFailure{"the " + side->name + " side sent " + std::string(proto::body_name(envelope)) +
                       " on its heartbeat socket; only Heartbeat is allowed there"};
    }
    if (envelope.has_error()) {
      const auto& error = envelope.error();
      throw RunFailure{"the " + side->name + " side failed at step " + std::to_string(error.step()) + " (" +
                       error.what() + "): " + error.message() + log_hint(*side)};
    }
    return std::make_pair(side, envelope);
  }

  void housekeeping() {
    const auto now = Clock::now();
    if (now - last_housekeeping_ < milliseconds(5)) return;
    last_housekeeping_ = now;
    for (auto& side : sides_) {
      if (!side.expected || side.stopping) continue;
      if (side.process) {
        if (auto ended = side.process->poll()) throw RunFailure{ended_message(side, *ended)};
      }
      if (side.thread_exit && side.thread_exit->load() >= 0) {
        const std::string reported = drain_error_from(side);
        throw RunFailure{"the in-process " + side.name + " side ended with code " +
                         std::to_string(side.thread_exit->load()) + at_step() +
                         (reported.empty() ? "" : ": " + reported)};
      }
      if (side.joined && now - side.last_heard > heartbeat_timeout_) {
        std::ostringstream out;
        out << "the " << side.name << " side stopped answering" << at_step() << ": nothing from it for "
            << scene_.coupling().heartbeat_timeout_s() << " s (its last heartbeat was at step "
            << side.heartbeat_step << ")" << log_hint(side);
        throw RunFailure{out.str()};
      }
      if (side.joined && now - side.last_sent > heartbeat_interval_) {
        protocol::Envelope beat;
        beat.mutable_heartbeat()->set_role(protocol::COUPLER);
        beat.mutable_heartbeat()->set_sequence(++heartbeats_sent_);
        beat.mutable_heartbeat()->set_step(step_);
        send_to(side, beat);
      }
    }
  }

  std::string ended_message(Side& side, const std::string& ended) {
    const std::string reported = drain_error_from(side);
    return "the " + side.name + " side (pid " + std::to_string(side.process->pid()) + ") " + ended + at_step() +
           (reported.empty() ? "" : ": " + reported) + log_hint(side);
  }

  // After a side ended: its last words, if it sent an Error before going.
  std::string drain_error_from(Side& side) {
    const auto until = Clock::now() + milliseconds(200);
    while (Clock::now() < until) {
      auto routed = receive_routed(router_, milliseconds(20));
      if (!routed || routed->peer != side.name) continue;
      try {
        const auto envelope = proto::decode(routed->payload.data(), routed->payload.size(), side.name);
        if (envelope.has_error()) return envelope.error().message();
      } catch (const proto::ProtocolError&) {
      }
    }
    return "";
  }

  void send_to(Side& side, const protocol::Envelope& envelope) {
    try {
      send_routed(router_, side.name, envelope);
      side.last_sent = Clock::now();
    } catch (const std::exception& e) {
      // Usually the process has just died: say how, rather than that a send failed.
      if (side.process && side.process->wait_for(0.5)) throw RunFailure{ended_message(side, *side.process->poll())};
      throw RunFailure{"cannot reach the " + side.name + " side" + at_step() + ": " + e.what() + log_hint(side)};
    }
  }

  [[noreturn]] void unexpected(const Side& side, const protocol::Envelope& envelope, const std::string& expected) {
    throw RunFailure{"the " + side.name + " side sent an unexpected " + std::string(proto::body_name(envelope)) +
                     " message" + at_step() + " where " + expected + " was due"};
  }

  // ------------------------------------------------------------ handshake
  void handshake() {
    using Pending = std::function<bool(const Side&)>;
    // Waits until no expected side is `pending`; the error lists those that still are.
    auto wait_until = [&](const Pending& pending, const std::string& what, const std::string& timeout_key,
                          double timeout_s) {
      const auto deadline = Clock::now() + microseconds(static_cast<std::int64_t>(timeout_s * 1e6));
      while (true) {
        std::string missing;
        for (const auto& side : sides_) {
          if (!side.expected || !pending(side)) continue;
          if (!missing.empty()) missing += ", ";
          missing += side.name;
        }
        if (missing.empty()) return;
        if (Clock::now() > deadline) {
          std::ostringstream out;
          out << "no " << what << " within " << timeout_key << " = " << timeout_s << " s (still waiting for: " << missing
              << ")";
          throw RunFailure{out.str()};
        }
        auto message = pump(milliseconds(20));
        if (message) on_handshake_message(*message->first, message->second);
      }
    };
    const auto& coupling = scene_.coupling();
    wait_until([](const Side& s) { return !s.joined; }, "Hello", "coupling.join_timeout_s", coupling.join_timeout_s());

    // Setup (building each model) happens between Welcome and Ready; heartbeats
    // prove the sides alive meanwhile, so this limit can be generous.
    Side& solid = sides_[0];
    Side& fluid = sides_[1];
    protocol::Envelope welcome = welcome_for(fluid.expected ? protocol::DataPlane::BIND : protocol::DataPlane::NONE,
                                             data_bind_);
    send_to(solid, welcome);
    if (fluid.expected) {
      wait_until([](const Side& s) { return s.role == protocol::SOLID && s.data_endpoint.empty(); },
                 "Listening from the solid side", "coupling.setup_timeout_s", coupling.setup_timeout_s());
      send_to(fluid, welcome_for(protocol::DataPlane::CONNECT, solid.data_endpoint));
    }
    wait_until([](const Side& s) { return !s.ready; }, "Ready", "coupling.setup_timeout_s", coupling.setup_timeout_s());
    manifest_.set("status", "running");
    manifest_.save();
  }

  protocol::Envelope welcome_for(protocol::DataPlane::Mode mode, const std::string& endpoint) const {
    protocol::Envelope envelope;
    auto* welcome = envelope.mutable_welcome();
    welcome->set_protocol_version(proto::kProtocolVersion);
    welcome->set_run_id(run_id_);
    *welcome->mutable_scene() = scene_;
    welcome->set_output_dir(output_dir_);
    welcome->mutable_data_plane()->set_mode(mode);
    if (mode != protocol::DataPlane::NONE) welcome->mutable_data_plane()->set_endpoint(endpoint);
    return envelope;
  }

  void on_handshake_message(Side& side, const protocol::Envelope& envelope) {
    if (!side.joined) {
      if (!envelope.has_hello()) unexpected(side, envelope, "Hello");
      const auto& hello = envelope.hello();
      const std::string who = "the " + side.name + " side (" + hello.implementation() + " " +
                              hello.implementation_version() + ")";
      if (hello.role() != side.role) {
        reject(side, who + " connected as '" + side.name + "' but says it is " +
                         std::string(proto::role_name(hello.role())));
      }
      if (hello.protocol_version() != proto::kProtocolVersion) {
        reject(side, who + " speaks protocol version " + std::to_string(hello.protocol_version()) +
                         "; this coupler speaks version " + std::to_string(proto::kProtocolVersion));
      }
      side.joined = true;
      side.implementation = hello.implementation() + " " + hello.implementation_version();
      manifest_.set(side.name + "_implementation", side.implementation);
      manifest_.set(side.name + "_host", hello.host());
      log_(side.name + " side joined: " + side.implementation + " on " + hello.host() + ", pid " +
           std::to_string(hello.pid()));
      return;
    }
    if (envelope.has_listening() && side.role == protocol::SOLID && side.data_endpoint.empty()) {
      side.data_endpoint = envelope.listening().data_endpoint();
      manifest_.set("data_endpoint", side.data_endpoint);
      return;
    }
    if (envelope.has_ready() && !side.ready) {
      side.ready = true;
      side.stable_dt = envelope.ready().stable_dt();
      side.diagnostics = proto::from_proto(envelope.ready().diagnostics());
      return;
    }
    unexpected(side, envelope, "Listening or Ready");
  }

  [[noreturn]] void reject(Side& side, const std::string& reason) {
    protocol::Envelope envelope;
    envelope.mutable_reject()->set_reason(reason);
    envelope.mutable_reject()->set_coupler_protocol_version(proto::kProtocolVersion);
    try {
      send_routed(router_, side.name, envelope);
    } catch (const std::exception&) {
    }
    throw RunFailure{"rejected " + reason + " (handshake, step 0)"};
  }

  // ------------------------------------------------------------- stepping
  double next_dt() {
    double stable = kInf;
    for (const auto& side : sides_) {
      if (!side.expected) continue;
      if (std::isnan(side.stable_dt) || side.stable_dt <= 0) {
        throw RunFailure{"the " + side.name + " side reported a stable time step of " +
                         std::to_string(side.stable_dt) + " s" + at_step() + "; it must be > 0"};
      }
      stable = std::min(stable, side.stable_dt);
    }
    if (!std::isfinite(stable)) throw RunFailure{"neither side reports a finite stable time step"};
    return scene_.time().safety_factor() * stable;
  }

  void step_loop(RunSummary& summary) {
    History& history = *history_;
    const auto start = Clock::now();
    const double end = scene_.time().end_s();
    const double interval = output_interval(scene_);
    const std::uint32_t k = sides_[1].expected ? scene_.coupling().exchange_interval() : 1;
    const std::uint64_t block = (std::uint64_t{scene_.coupling().control_interval()} + k - 1) / k * k;
    double dt = next_dt();
    history.write(t_, step_, dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
    std::uint64_t frame = 1;
    double next_output = interval;
    double mean_command_s = 0;
    const std::uint64_t max_steps = scene_.time().max_steps();
    while (t_ < end * (1 - 1e-12)) {
      // Steps to reach the next output time (and the end), rounded up to whole exchange windows.
      auto steps_to = [&](double target) {
        const double n = std::ceil((target - t_) / dt * (1 - 1e-12));
        const auto steps = static_cast<std::uint64_t>(std::max(1.0, n));
        return (steps + k - 1) / k * k;
      };
      // time.max_steps, in whole exchange windows (a command never splits one).
      const std::uint64_t to_max = (max_steps - step_) / k * k;
      if (to_max == 0) break;
      const std::uint64_t n = std::min({block, steps_to(std::min(next_output, end)), to_max});
      const double t_end = t_ + static_cast<double>(n) * dt;
      const bool last_allowed = n == to_max && max_steps - step_ - n < k;
      const bool output = t_end >= next_output * (1 - 1e-12) || t_end >= end * (1 - 1e-12) || last_allowed;

      protocol::Envelope envelope;
      auto* command = envelope.mutable_step_command();
      command->set_first_step(step_);
      command->set_num_steps(static_cast<std::uint32_t>(n));
      command->set_t(t_);
      command->set_dt(dt);
      command->set_write_output(output);
      command->set_output_frame(output ? frame : 0);
      const auto command_start = Clock::now();
      for (auto& side : sides_) {
        if (!side.expected) continue;
        side.report.reset();
        send_to(side, envelope);
      }
      // The sides accumulate t the same way, so the times agree bit for bit.
      double t_expected = t_;
      for (std::uint64_t i = 0; i < n; ++i) t_expected += dt;
      await_reports(step_ + n, t_expected, std::max(scene_.coupling().step_timeout_s(), 20 * mean_command_s));
      const double command_s = seconds_since(command_start);
      mean_command_s = summary.commands == 0 ? command_s : 0.9 * mean_command_s + 0.1 * command_s;
      ++summary.commands;
      step_ += n;
      t_ = t_expected;
      for (auto& side : sides_) {
        if (!side.expected) continue;
        side.stable_dt = side.report->stable_dt();
        side.diagnostics = proto::from_proto(side.report->diagnostics());
        side.compute_s += side.report->compute_s();
        side.exchange_s += side.report->exchange_s();
      }
      if (output) {  // dt_s: the step that led to this row
        history.write(t_, step_, dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
        ++frame;
        while (next_output <= t_ * (1 + 1e-12)) next_output += interval;
      }
      if (t_ < end * (1 - 1e-12)) dt = next_dt();
      progress_.update(t_, step_, seconds_since(start));
    }
    summary.stepping_wall_s = seconds_since(start);
    if (t_ < end * (1 - 1e-12)) {
      stopped_at_max_steps_ = true;
      log_("stopped at step " + std::to_string(step_) + " (time.max_steps = " + std::to_string(max_steps) +
           ", in whole exchange windows) before time.end_s");
    }
  }

  void await_reports(std::uint64_t step, double t, double timeout_s) {
    const auto deadline = Clock::now() + microseconds(static_cast<std::int64_t>(timeout_s * 1e6));
    auto pending = [&] {
      for (auto& side : sides_) {
        if (side.expected && !side.report) return true;
      }
      return false;
    };
    while (pending()) {
      if (Clock::now() > deadline) throw RunFailure{hung_message(timeout_s)};
      auto message = pump(milliseconds(20));
      if (!message) continue;
      auto& [side, envelope] = *message;
      if (!envelope.has_step_report() || side->report) unexpected(*side, envelope, "StepReport");
      const auto& report = envelope.step_report();
      if (report.step() != step || report.t() != t) {
        std::ostringstream out;
        out << std::setprecision(17) << "the " << side->name << " side reports step " << report.step() << " at t = " << report.t()
            << " s, but step " << step << " at t = " << t << " s was commanded";
        throw RunFailure{out.str()};
      }
      side->report = report;
    }
  }

  std::string hung_message(double timeout_s) const {
    std::string blamed;
    for (const auto& side : sides_) {
      if (side.expected && !side.report && !side.waiting_for_peer) blamed += (blamed.empty() ? "" : " and ") + side.name;
    }
    if (blamed.empty()) blamed = "solid and fluid";
    std::ostringstream out;
    out << "the " << blamed << " side" << (blamed.find(" and ") != std::string::npos ? "s" : "")
        << " stopped making progress" << at_step() << ": no StepReport within " << timeout_s
        << " s (coupling.step_timeout_s) although heartbeats still arrive";
    return out.str();
  }

  // ------------------------------------------------------------- shutdown
  void stop_sides(bool error, const std::string& reason) {
    protocol::Envelope envelope;
    envelope.mutable_shutdown()->set_reason(reason);
    envelope.mutable_shutdown()->set_error(error);
    for (auto& side : sides_) {
      if (!side.expected || side.stopping) continue;
      side.stopping = true;
      if (side.joined || side.thread_exit) {  // an in-process side may be connected before its Hello is read
        try {
          send_routed(router_, side.name, envelope);
        } catch (const std::exception&) {
        }
      }
    }
    for (auto& side : sides_) {
      if (side.process) {
        if (!side.process->wait_for(!side.joined ? 0.5 : error ? 2.0 : 10.0)) {
          log_(side.joined ? "the " + side.name + " side did not exit after Shutdown; terminating it"
                           : "the " + side.name + " side never joined; terminating it");
          side.process->stop(1.0);
        }
      }
      if (side.thread.joinable()) {
        // A thread cannot be killed: wait a bounded time, then leave it behind
        // (it ends with the process) rather than hang the coupler.
        const auto deadline = Clock::now() + std::chrono::seconds(error ? 5 : 60);
        while (side.thread_exit->load() < 0 && Clock::now() < deadline) {
          std::this_thread::sleep_for(milliseconds(2));
        }
        if (side.thread_exit->load() >= 0) {
          side.thread.join();
        } else {
          log_("the in-process " + side.name + " side did not stop; leaving it to end with the process");
          side.thread.detach();
          leak_context_ = true;
        }
      }
    }
  }

  scene::Scene scene_;
  RunOptions options_;
  std::unique_ptr<zmq::context_t> context_ = std::make_unique<zmq::context_t>(1);
  zmq::socket_t router_;
  Side sides_[2];
  std::string run_id_, output_dir_, control_endpoint_, data_bind_, ipc_dir_;
  Manifest manifest_{""};
  std::unique_ptr<History> history_;
  bool prepared_ = false;
  bool leak_context_ = false;
  bool stopped_at_max_steps_ = false;
  Log log_;
  Progress progress_;
  microseconds heartbeat_interval_{500000}, heartbeat_timeout_{3000000};
  Clock::time_point start_ = Clock::now(), last_housekeeping_{};
  std::uint64_t step_ = 0;
  std::uint64_t heartbeats_sent_ = 0;
  double t_ = 0;
};

}  // namespace

RunSummary run_coupled(const scene::Scene& scene, const RunOptions& options) {
  Coupler coupler(scene, options);
  return coupler.run();
}

}  // namespace hfmpm::coupling
