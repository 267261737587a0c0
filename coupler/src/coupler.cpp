// The coupler's run: start (output, endpoints, launching the sides), the
// run as a whole, and shutdown. See coupler_session.hpp for the parts.
#include <google/protobuf/util/json_util.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "coupler_session.hpp"
#include "hfmpm/coupling/run_state.hpp"

namespace hfmpm::coupling {

double RunSummary::overhead_per_step_us() const {
  if (steps == 0) return 0;
  const double compute =
      sides_in_sequence ? solid_compute_s + fluid_compute_s : std::max(solid_compute_s, fluid_compute_s);
  return 1e6 * std::max(0.0, stepping_wall_s - compute) / static_cast<double>(steps);
}

RunSummary run_coupled(const scene::Scene& scene, const RunOptions& options) {
  detail::Coupler coupler(scene, options);
  return coupler.run();
}

namespace detail {

Coupler::Coupler(const scene::Scene& scene, const RunOptions& options)
    : scene_(scene),
      options_(options),
      transport_(options.transport ? options.transport : make_zmq_transport()),
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

Coupler::~Coupler() {
  if (options_.stop_request) set_abort_cleanup({});
  for (auto& side : sides_) {
    if (side.thread.joinable()) side.thread.join();
  }
  if (!ipc_dir_.empty()) {
    std::error_code ignored;
    fs::remove_all(ipc_dir_, ignored);
  }
  if (!keys_dir_.empty()) {
    std::error_code ignored;
    fs::remove_all(keys_dir_, ignored);
  }
}

RunSummary Coupler::run() {
  const auto start = Clock::now();
  RunSummary summary;
  try {
    prepare();
    handshake();
    step_loop(summary);
    stop_sides(false, "end of run");
    summary.ok = true;
    if (!done_reason_.empty()) {
      summary.stopped = done_reason_;
      manifest_.set("status", "stopped");
      manifest_.set("stop_reason", done_reason_);
    } else {
      manifest_.set("status", stopped_at_max_steps_ ? "stopped at time.max_steps" : "completed");
    }
    report_rest();
    for (const auto& [code, text] : warnings_) summary.warnings.push_back(text);
  } catch (const RunInterrupted& interrupted) {
    // Asked to stop: the sides end as at the end of a run (their outputs
    // flushed and closed), and the manifest says where the run stopped.
    const std::string name = signal_name(interrupted.signal);
    std::ostringstream out;
    out << "interrupted by " << name << " at step " << step_ << " (t = " << t_ << " s)";
    summary.error = out.str();
    summary.interrupted_by = interrupted.signal;
    log_.file_only(summary.error + "; stopping the sides");
    stop_sides(false, summary.error);
    manifest_.set("status", "interrupted");
    manifest_.set("interrupted_by", name);
    manifest_.set_number("interrupted_at_step", static_cast<double>(step_));
  } catch (const RunFailure& failure) {
    summary.error = failure.message;
  } catch (const std::exception& e) {
    summary.error = std::string("coupler: ") + e.what();
  }
  if (!summary.ok && !summary.interrupted_by) {
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
  summary.sides_in_sequence = CouplingScheme::of(scene_).sides_in_sequence();
  manifest_.set_number("steps", static_cast<double>(step_));
  manifest_.set_number("end_time_s", t_);
  manifest_.set_number("wall_s", summary.wall_s);
  // Where the time went: each side's own compute, and the coupling overhead
  // (stepping wall time less the slower side's compute, per step).
  manifest_.set_number("stepping_wall_s", summary.stepping_wall_s);
  manifest_.set_number("solid_compute_s", summary.solid_compute_s);
  if (sides_[1].expected) manifest_.set_number("fluid_compute_s", summary.fluid_compute_s);
  if (step_ > 0) manifest_.set_number("coupling_overhead_us_per_step", summary.overhead_per_step_us());
  if (!dt_limit_steps_.empty()) {
    // The step: time.safety_factor x the smaller side's stable step, chosen
    // anew after every command; the term that set it for most steps.
    const auto most = std::max_element(dt_limit_steps_.begin(), dt_limit_steps_.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    manifest_.set("dt_limited_by", most->first);
    manifest_.set_number("dt_limited_by_fraction", static_cast<double>(most->second) / static_cast<double>(step_));
    manifest_.set_number("dt_min_s", dt_min_);
    manifest_.set_number("dt_max_s", dt_max_);
  }
  if (energy_) {
    manifest_.set_number("inlet_work_j", energy_->inlet_work());
    manifest_.set_number("initial_fill_energy_j", energy_->initial_energy());
    manifest_.set_number("released_in_situ_energy_j", energy_->released_energy());
    manifest_.set_number("max_kinetic_energy_over_inlet_work", energy_->largest_ratio());
    manifest_.set_number("max_kinetic_energy_over_inlet_work_t_s", energy_->largest_ratio_time());
    // The fluid's pressure change at frozen crack width (docs/stability.md, "The stiff-fluid lag").
    manifest_.set_number("max_coupling_lag_pa", max_coupling_lag_);
    manifest_.set_number("max_coupling_lag_t_s", max_coupling_lag_t_);
  }
  if (prepared_) {
    manifest_.save();
    manifest_.release_reserve();
  }
  return summary;
}

// An end state found by a side (its notice) or by the coupler's own watch:
// once per code, in run.json's "warnings" and the log (stderr).
void Coupler::warn(const std::string& who, const std::string& code, const std::string& message) {
  if (warnings_.count(code)) return;
  const std::string text = code + " (" + who + ", t = " + std::to_string(t_) + " s): " + message.substr(0, 4000);
  warnings_[code] = text;
  manifest_.append("warnings", text);
  manifest_.save();
  log_("warning: " + text);
}

// A dry run that ends with its solid still moving says so (RestWatch).
void Coupler::report_rest() {
  if (!rest_ || !rest_->measured()) return;
  manifest_.set_number("solid_final_kinetic_energy_j", rest_->mean_kinetic_energy());
  manifest_.set_number("solid_final_strain_energy_j", rest_->mean_strain_energy());
  manifest_.set_number("solid_final_kinetic_over_strain_energy", rest_->ratio());
  if (const auto warning = rest_->warning()) {
    manifest_.set("warning", *warning);
    warn("coupler", "not-at-rest", *warning);
  }
}

void Coupler::prepare() {
  fs::create_directories(options_.output_dir);
  output_dir_ = fs::absolute(options_.output_dir).string();
  log_.open(output_dir_ + "/coupler.log", options_.progress, options_.restart != nullptr);
  manifest_ = Manifest(output_dir_ + "/run.json");
  // Disk kept for run.json's last saves: on a full disk they still name the failure.
  manifest_.keep_reserve(kManifestReserveBytes);
  run_id_ = random_id();
  manifest_.set("run_id", run_id_);
  manifest_.set("scene", options_.scene_path);
  manifest_.set("scene_name", scene_.name());
  for (const auto& caution : scene_.cautions()) {
    manifest_.append("cautions", caution);
    log_("caution: " + caution);
  }
  manifest_.set("status", "starting");
  // Who runs it, since when: a run.json left at "running" by a coupler that
  // was killed (kill -9, a second signal) names a process that no longer exists.
  manifest_.set_number("coupler_pid", static_cast<double>(getpid()));
  manifest_.set("coupler_host", host_name());
  manifest_.set("started_at", utc_now());
  // The pid's start time and the boot: a later reader tells this coupler
  // from another process that got its pid (check_run_state).
  manifest_.set("coupler_start_ticks", std::to_string(process_start_ticks(getpid())));
  manifest_.set("boot_id", boot_id());
  std::string overrides;
  for (const auto& o : options_.overrides) overrides += (overrides.empty() ? "" : " ") + o;
  manifest_.set("overrides", overrides);
  manifest_.set_number("protocol_version", proto::kProtocolVersion);
  prepared_ = true;
  if (options_.restart) {
    // Continue the run's history after the checkpoint's row (the rows a killed
    // run wrote after it go; the restart writes them again).
    const auto& r = *options_.restart;
    step_ = r.state.step();
    t_ = r.state.t();
    const auto last_row = truncate_history(output_dir_ + "/history.csv", step_);
    history_ = std::make_unique<History>(output_dir_ + "/history.csv", true, last_row);
    manifest_.set("restarted_from", r.directory);
    manifest_.set_number("restart_step", static_cast<double>(step_));
    manifest_.set_number("restart_time_s", t_);
    manifest_.set("restarted_run_id", r.state.run_id());
    if (!options_.previous_status.empty()) manifest_.set("previous_status", options_.previous_status);
    for (const auto& damaged : r.damaged) {
      manifest_.append("damaged_checkpoints", damaged);
      log_.file_only("passed over the damaged checkpoint " + damaged);
    }
    log_("restarting from " + r.directory + " (step " + std::to_string(step_) + ", t = " + std::to_string(t_) + " s)");
  } else {
    history_ = std::make_unique<History>(output_dir_ + "/history.csv");  // header now: always readable
  }
  if (scene_.output().checkpoint_interval_s() > 0) {
    manifest_.set_number("checkpoint_interval_s", scene_.output().checkpoint_interval_s());
  }
  {
    // The scene the run uses, every default filled in, as JSON: what a plot
    // or a script reads instead of repeating the scene's values.
    std::string json;
    google::protobuf::util::JsonPrintOptions print;
    print.add_whitespace = true;
    print.preserve_proto_field_names = true;
    if (google::protobuf::util::MessageToJsonString(with_defaults(scene_), &json, print).ok()) {
      std::ofstream(output_dir_ + "/scene.json") << json;
    }
  }

  const auto transport = scene_.coupling().transport();
  if (options_.transport && (transport != scene::Coupling::INPROC || !options_.launch)) {
    throw RunFailure{
        "a transport given to the coupler serves only sides it starts as threads (coupling.transport: "
        "INPROC)"};
  }
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
  std::string side_keys;  // the key file the launched sides get
  RouterSecurity security;
  if (bind.rfind("tcp://", 0) == 0) {
    if (options_.insecure_tcp) {
      manifest_.set("tcp_security", "none (--insecure-tcp): anyone who reaches the port can join");
      log_.file_only("warning: plain tcp (--insecure-tcp): anyone who can reach " + bind + " can join as a side");
    } else {
      CurveKeys keys;
      if (!options_.keys_file.empty()) {
        keys = read_coupler_key_file(options_.keys_file);
      } else if (options_.launch) {
        keys = generate_curve_keys();  // this run's own
      } else {
        throw RunFailure{
            "a coupler on tcp needs --keys FILE (the coupler.keys that 'hfmpm keygen DIR' writes; "
            "the sides take side.keys), or --insecure-tcp for plain tcp"};
      }
      if (options_.launch) {
        char pattern[] = "/tmp/hfmpm-keys-XXXXXX";  // 0700
        if (!mkdtemp(pattern)) throw RunFailure{"cannot create a private directory for the run's keys in /tmp"};
        keys_dir_ = pattern;
        side_keys = keys_dir_ + "/side.keys";
        write_side_key_file(side_keys, keys);
      }
      security.curve = keys;
      curve_ = true;
      manifest_.set("tcp_security", "CURVE");
    }
  }
  side_keys_ = side_keys;
  // Refused peers (CURVE) and connections closed beyond the cap (tcp), told
  // by the transport's threads and logged by housekeeping().
  security.refused = [this](const std::string& line) {
    std::lock_guard<std::mutex> lock(refusals_mutex_);
    refusals_ += (refusals_.empty() ? "" : "\n") + line;
  };
  try {
    router_ = transport_->bind_router(bind, security);
  } catch (const zmq::error_t& e) {
    throw RunFailure{"cannot bind the control endpoint " + bind + ": " + e.what()};
  } catch (const std::runtime_error& e) {
    throw RunFailure{"cannot bind the control endpoint " + bind + ": " + e.what()};
  }
  control_endpoint_ = router_->endpoint();
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
  if (options_.stop_request) {
    // A second stop signal ends the process at once: leave no socket
    // directory behind, and no run.json that says "running".
    set_abort_cleanup([ipc = ipc_dir_, keys = keys_dir_, manifest = output_dir_ + "/run.json"](int signal) {
      for (const auto& dir : {ipc, keys}) {
        std::error_code ignored;
        if (!dir.empty()) fs::remove_all(dir, ignored);
      }
      std::ifstream in(manifest);
      std::ostringstream read;
      read << in.rdbuf();
      std::string text = read.str();
      const auto at = text.find("\"status\": \"");
      if (at == std::string::npos) return;
      const auto end = text.find('"', at + 11);
      text.replace(at, end + 1 - at, "\"status\": \"aborted by " + signal_name(signal) + "\"");
      const std::string tmp = manifest + ".abort";
      std::remove((manifest + ".reserve").c_str());  // the space kept for this (Manifest::keep_reserve)
      std::ofstream out(tmp);
      out << text;
      // Only a whole file replaces the last good one.
      if (out.flush()) {
        std::rename(tmp.c_str(), manifest.c_str());
      } else {
        std::remove(tmp.c_str());
      }
    });
  }
  if (options_.on_bound) options_.on_bound(control_endpoint_);

  if (options_.launch) {
    launch_sides();
  } else {
    // Printed even when quiet: the person starting the sides needs the endpoint.
    std::string reachable = control_endpoint_;
    if (tcp_host(reachable) == "0.0.0.0") reachable = advertise(reachable, host_name());
    const std::string line =
        "waiting for sides at " + control_endpoint_ + " (start each with --connect " + reachable + ")";
    std::cerr << "hfmpm: " << line << std::endl;
    log_.file_only(line);
  }
  manifest_.save();
}

std::string Coupler::program_for(const Side& side) const {
  const std::string& chosen = side.role == protocol::SOLID ? options_.solid_program : options_.fluid_program;
  if (!chosen.empty()) return chosen;
  const std::string dir = options_.executable_dir.empty() ? executable_dir() : options_.executable_dir;
  if (side.role == protocol::SOLID) {
    return dir + (scene_.solid().has_mpm() ? "/hfmpm-solid" : "/hfmpm-prescribed-solid");
  }
  return dir + (scene_.fluid().has_mpm() ? "/hfmpm-fluid" : "/hfmpm-prescribed-fluid");
}

void Coupler::launch_sides() {
  const bool inproc = scene_.coupling().transport() == scene::Coupling::INPROC;
  // The sides' OpenMP threads sleep at a barrier instead of spinning
  // (docs/performance.md, "Waiting without spinning"): the solid, the fluid
  // and the coupler share the cores, and a spinning thread takes the core
  // a descheduled partner needs (kgd-viscosity-ci's solid took 4.5 times
  // as long spinning on a loaded 2-core machine). A user's own
  // OMP_WAIT_POLICY or GOMP_SPINCOUNT is kept. Set before any fork: the
  // runtime reads it when the side starts (in-process sides share the
  // coupler's runtime, which has read it already).
  if (!inproc) {
    if (!std::getenv("OMP_WAIT_POLICY") && !std::getenv("GOMP_SPINCOUNT")) setenv("OMP_WAIT_POLICY", "passive", 0);
    if (const char* policy = std::getenv("OMP_WAIT_POLICY")) manifest_.set("omp_wait_policy", policy);
  }
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
      side_options.transport = transport_;
      side.thread =
          std::thread([model, side_options, exit = side.thread_exit] { *exit = run_side(*model, side_options); });
      manifest_.set(side.name + "_program", "in-process thread");
      continue;
    }
    std::vector<std::string> args{"--connect", control_endpoint_, "--out", output_dir_};
    if (!side_keys_.empty()) {
      args.push_back("--keys");
      args.push_back(side_keys_);
    }
    const auto& extra = side.role == protocol::SOLID ? scene_.coupling().solid_args() : scene_.coupling().fluid_args();
    args.insert(args.end(), extra.begin(), extra.end());
    side.log_path = output_dir_ + "/" + side.name + ".log";
    const std::string program = program_for(side);
    try {
      side.process = std::make_unique<ChildProcess>(program, args, side.log_path, options_.restart != nullptr);
    } catch (const std::exception& e) {
      throw RunFailure{"cannot start the " + side.name + " side: " + e.what()};
    }
    manifest_.set(side.name + "_program", program);
    manifest_.set_number(side.name + "_pid", side.process->pid());
  }
}

void Coupler::stop_sides(bool error, const std::string& reason) {
  protocol::Envelope envelope;
  envelope.mutable_shutdown()->set_reason(reason);
  envelope.mutable_shutdown()->set_error(error);
  for (auto& side : sides_) {
    if (!side.expected || side.stopping) continue;
    side.stopping = true;
    if (router_ && (side.joined || side.thread_exit)) {  // an in-process side may be connected before its Hello is read
      try {
        router_->send(side.name, envelope);
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
        side.thread.detach();  // it holds the transport (transport_)
      }
    }
  }
}

}  // namespace detail
}  // namespace hfmpm::coupling
