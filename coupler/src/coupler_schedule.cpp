// The handshake (Hello, Welcome, Listening, Ready) and the step schedule:
// dt, blocks of steps, reports, output rows, stuck sides.
#include <algorithm>

#include "coupler_session.hpp"

namespace hfmpm::coupling {

double next_time_after(double next, double interval, double t) {
  const double limit = t * (1 + 1e-12);
  // The usual case: one interval (two after a long step), added as always.
  constexpr int kAddedOneByOne = 8;
  for (int i = 0; i < kAddedOneByOne && next <= limit; ++i) {
    const double sum = next + interval;
    if (!(sum > next)) break;  // no progress: the interval vanishes against `next` (or is not > 0)
    next = sum;
  }
  if (next > limit) return next;
  if (interval > 0) {
    // Many intervals at once (a step far longer than the interval): whole ones.
    const double jumped = next + (std::floor((limit - next) / interval) + 1) * interval;
    if (jumped > limit && std::isfinite(jumped)) return jumped;
  }
  return std::nextafter(limit, detail::kInf);
}

std::string non_finite_report_fields(const google::protobuf::Message& report) {
  std::string fields;
  for (const auto& n : proto::non_finite_numbers(report)) {
    if (n.path == "stable_dt" && n.value > 0) continue;  // +inf: the side sets no limit
    std::ostringstream value;
    value << n.value;
    fields += (fields.empty() ? "" : ", ") + n.path + " = " + value.str();
  }
  return fields;
}

}  // namespace hfmpm::coupling

namespace hfmpm::coupling::detail {

constexpr const char* kFiniteReports =
    "every number a side reports must be finite (stable_dt may also be +inf: no limit); the run stops here with its "
    "output so far";

void Coupler::handshake() {
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
  // Every side has read the key file before its Hello: remove the sides'
  // secret from /tmp now, not at the end, so a coupler killed later (kill -9
  // leaves no chance to clean up) does not leave it behind.
  if (!keys_dir_.empty()) {
    std::error_code ignored;
    fs::remove_all(keys_dir_, ignored);
    keys_dir_.clear();
  }

  // Setup (building each model) happens between Welcome and Ready; heartbeats
  // prove the sides alive meanwhile, so this limit can be generous.
  Side& solid = sides_[0];
  Side& fluid = sides_[1];
  protocol::Envelope welcome =
      welcome_for(fluid.expected ? protocol::DataPlane::BIND : protocol::DataPlane::NONE, data_bind_);
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

protocol::Envelope Coupler::welcome_for(protocol::DataPlane::Mode mode, const std::string& endpoint) const {
  protocol::Envelope envelope;
  auto* welcome = envelope.mutable_welcome();
  welcome->set_protocol_version(proto::kProtocolVersion);
  welcome->set_scene_schema_version(proto::kSceneSchemaVersion);
  welcome->set_run_id(run_id_);
  *welcome->mutable_scene() = scene_;
  welcome->set_output_dir(output_dir_);
  welcome->mutable_data_plane()->set_mode(mode);
  if (mode != protocol::DataPlane::NONE) welcome->mutable_data_plane()->set_endpoint(endpoint);
  if (options_.restart) {
    auto* restart = welcome->mutable_restart();
    restart->set_step(options_.restart->state.step());
    restart->set_t(options_.restart->state.t());
    restart->set_directory(options_.restart->directory);
  }
  return envelope;
}

void Coupler::on_handshake_message(Side& side, const protocol::Envelope& envelope) {
  if (!side.joined) {
    if (!envelope.has_hello()) unexpected(side, envelope, "Hello");
    const auto& hello = envelope.hello();
    const std::string who =
        "the " + side.name + " side (" + hello.implementation() + " " + hello.implementation_version() + ")";
    if (hello.role() != side.role) {
      reject(side,
             who + " connected as '" + side.name + "' but says it is " + std::string(proto::role_name(hello.role())));
    }
    if (hello.protocol_version() != proto::kProtocolVersion) {
      reject(side, who + " speaks protocol version " + std::to_string(hello.protocol_version()) +
                       "; this coupler speaks version " + std::to_string(proto::kProtocolVersion));
    }
    if (hello.scene_schema_version() != proto::kSceneSchemaVersion) {
      reject(side, who + " was built with scene schema version " + std::to_string(hello.scene_schema_version()) +
                       (hello.scene_schema_version() == 0 ? " (before scenes were versioned)" : "") +
                       "; this coupler's scenes are version " + std::to_string(proto::kSceneSchemaVersion) +
                       ": build the side from the same scene.proto (docs/protocol.md, \"Versions\")");
    }
    side.can_checkpoint = std::find(hello.capabilities().begin(), hello.capabilities().end(),
                                    std::string(kCheckpointCapability)) != hello.capabilities().end();
    if (!side.can_checkpoint && (options_.restart || scene_.output().checkpoint_interval_s() > 0)) {
      reject(side, who + " cannot " +
                       (options_.restart ? std::string("restart from a checkpoint")
                                         : std::string("write checkpoints (output.checkpoint_interval_s = ") +
                                               std::to_string(scene_.output().checkpoint_interval_s()) + ")") +
                       ": its Hello does not list the capability \"checkpoint\"");
    }
    side.joined = true;
    side.implementation = hello.implementation() + " " + hello.implementation_version();
    manifest_.set(side.name + "_implementation", side.implementation);
    manifest_.set(side.name + "_host", hello.host());
    log_(side.name + " side joined: " + side.implementation + " on " + hello.host() + ", pid " +
         std::to_string(hello.pid()));
    return;
  }
  if (envelope.has_hello() && envelope.hello().role() == side.role && !side.ready) {
    // A side repeats its Hello until it has its Welcome (the first can be
    // lost on a refused connection); the Welcome is on its way.
    if (side.repeated_hellos++ == 0) log_(side.name + " side: a repeated Hello ignored (it has joined)");
    return;
  }
  if (envelope.has_listening() && side.role == protocol::SOLID && side.data_endpoint.empty()) {
    side.data_endpoint = envelope.listening().data_endpoint();
    manifest_.set("data_endpoint", side.data_endpoint);
    return;
  }
  if (envelope.has_ready() && !side.ready) {
    if (const std::string bad = non_finite_report_fields(envelope.ready()); !bad.empty()) {
      throw RunFailure{"the " + side.name + " side reported " + bad + " in its Ready (step " + std::to_string(step_) +
                       "); " + kFiniteReports};
    }
    side.ready = true;
    side.stable_dt = envelope.ready().stable_dt();
    side.stable_dt_limit = envelope.ready().stable_dt_limit().substr(0, 200);
    side.diagnostics = proto::from_proto(envelope.ready().diagnostics());
    return;
  }
  unexpected(side, envelope, "Listening or Ready");
}

void Coupler::reject(Side& side, const std::string& reason) {
  protocol::Envelope envelope;
  envelope.mutable_reject()->set_reason(reason);
  envelope.mutable_reject()->set_coupler_protocol_version(proto::kProtocolVersion);
  envelope.mutable_reject()->set_coupler_scene_schema_version(proto::kSceneSchemaVersion);
  try {
    router_->send(side.name, envelope);
  } catch (const std::exception&) {
  }
  throw RunFailure{"rejected " + reason + " (handshake, step 0)"};
}

double Coupler::next_dt() {
  double stable = kInf;
  for (const auto& side : sides_) {
    if (!side.expected) continue;
    if (std::isnan(side.stable_dt) || side.stable_dt <= 0) {
      throw RunFailure{"the " + side.name + " side reported a stable time step of " + std::to_string(side.stable_dt) +
                       " s" + at_step() + "; it must be > 0"};
    }
    if (side.stable_dt < stable) {
      stable = side.stable_dt;
      dt_limit_ = side.name + (side.stable_dt_limit.empty() ? std::string() : ": " + side.stable_dt_limit);
    }
  }
  if (!std::isfinite(stable)) throw RunFailure{"neither side reports a finite stable time step"};
  return scene_.time().safety_factor() * stable;
}

namespace {

// The first step against time.end_s: a run of more than kMaxRunSteps steps
// (or of a number of steps a double cannot count) is refused, naming the
// step, where it comes from and the end time. Returns a warning when a single
// step reaches past end_s (the run then ends at t + dt, not at end_s; the
// validator refuses that when it can see every side's step, but an MPM
// fluid reports its step only now); empty otherwise.
std::string check_step_count(const scene::Scene& scene, double t, double dt, double end, const std::string& limit,
                             const std::string& at_step) {
  const double steps = (end - t) / dt;
  std::ostringstream where;
  where << "dt = " << dt << " s (time.safety_factor " << scene.time().safety_factor() << " x the stable step of the "
        << limit << ") and time.end_s = " << end << " s";
  if (!std::isfinite(steps) || steps > kMaxRunSteps) {
    std::ostringstream out;
    out << "the run would need " << steps << " steps to reach time.end_s: " << where.str() << "; at most "
        << kMaxRunSteps << " steps are allowed (check the scene's moduli, densities and cell sizes, or shorten "
        << "time.end_s)" << at_step;
    throw RunFailure{out.str()};
  }
  if (dt > end - t) {
    std::ostringstream out;
    out << "warning: a single step reaches the end: " << where.str()
        << "; the run is one step and ends at t = " << t + dt << " s, past time.end_s";
    return out.str();
  }
  return {};
}

}  // namespace

void Coupler::step_loop(RunSummary& summary) {
  History& history = *history_;
  const auto start = Clock::now();
  stepping_start_ = start;
  const double end = scene_.time().end_s();
  const double interval = output_interval(scene_);
  const std::uint32_t k = CouplingScheme::of(scene_).exchange_interval();  // 1 in a dry run
  const std::uint64_t block = (std::uint64_t{scene_.coupling().control_interval()} + k - 1) / k * k;
  const double checkpoint_interval = scene_.output().checkpoint_interval_s();
  Schedule schedule;
  if (sides_[1].expected) {
    energy_ = std::make_unique<EnergyWatch>(scene_.coupling().energy_bound());
    state_watch_ = std::make_unique<StateWatch>(end);
  } else {
    rest_ = std::make_unique<RestWatch>(end);
  }
  if (options_.restart) {
    restore_checkpoint(schedule, summary);  // the step loop's state as it was after the checkpoint's block
  } else {
    schedule.dt = next_dt();
    if (const auto warning = check_step_count(scene_, t_, schedule.dt, end, dt_limit_, at_step()); !warning.empty()) {
      log_(warning);
    }
    history.write(t_, step_, schedule.dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
    if (energy_) energy_->start(sides_[1].diagnostics);
    schedule.next_output = interval;
    schedule.next_checkpoint = checkpoint_interval > 0
                                   ? checkpoint_interval
                                   : kInf;  // NOLINT(bugprone-narrowing-conversions): clang-tidy 14 misreads inf
  }
  double& dt = schedule.dt;
  std::uint64_t& frame = schedule.frame;
  double& next_output = schedule.next_output;
  double& mean_command_s = schedule.mean_command_s;
  const std::uint64_t max_steps = scene_.time().max_steps();
  stepping_ = true;
  while (t_ < end * (1 - 1e-12)) {
    if (options_.stop_request && options_.stop_request->load()) {
      summary.stepping_wall_s = stepping_before_ + seconds_since(start);
      // The row of the step it stops at, unless the last output row (a checkpoint's, or the one
      // a restart continues after) is that step's: a row is written once per step, and a
      // restart keeps the rows up to its checkpoint, so a second one would stay doubled.
      if (!history.ends_at(step_)) {
        history.write(t_, step_, dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
      }
      check_stop_request();
    }
    // Steps to reach the next output time (and the end), rounded up to whole exchange windows.
    auto steps_to = [&](double target) {
      // Clamped before the cast: a double above 2^64 (or inf) converts to garbage, often 0.
      const double n = std::min(std::ceil((target - t_) / dt * (1 - 1e-12)), 1e18);
      const auto steps = static_cast<std::uint64_t>(std::max(1.0, n));
      return (steps + k - 1) / k * k;
    };
    // time.max_steps, in whole exchange windows (a command never splits one).
    const std::uint64_t to_max = (max_steps - step_) / k * k;
    if (to_max == 0) break;
    // Commands end at every multiple of the control block (counted from step 0,
    // not from the last output) and at output times. The step is re-chosen and
    // the energy checked only at the block's multiples and at the end, so
    // neither the answer nor a run's verdict depends on the output interval
    // (an output time used to restart the block and add a sample: a layered
    // run's energy check stopped it with output every 20 ms and not with
    // every 1 ms, its exchanges bit-for-bit the same; docs/protocol.md).
    const std::uint64_t to_control = block - step_ % block;
    const std::uint64_t n = std::min({to_control, steps_to(std::min(next_output, end)), to_max});
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
    // A checkpoint at the first output row at or after each multiple of the
    // interval (not at the end: nothing would continue from it).
    const bool checkpoint =
        output && t_end >= schedule.next_checkpoint * (1 - 1e-12) && t_end < end * (1 - 1e-12) && !last_allowed;
    const std::string checkpoint_dir = checkpoint ? checkpoint_directory(step_ + n) : std::string();
    command->set_checkpoint(checkpoint);
    command->set_checkpoint_directory(checkpoint_dir);
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
    dt_limit_steps_[dt_limit_] += n;
    dt_min_ = std::min(dt_min_, dt);
    dt_max_ = std::max(dt_max_, dt);
    for (auto& side : sides_) {
      if (!side.expected) continue;
      side.stable_dt = side.report->stable_dt();
      side.stable_dt_limit = side.report->stable_dt_limit().substr(0, 200);
      side.diagnostics = proto::from_proto(side.report->diagnostics());
      side.compute_s += side.report->compute_s();
      side.exchange_s += side.report->exchange_s();
    }
    if (sides_[1].diagnostics.coupling_lag > max_coupling_lag_) {
      max_coupling_lag_ = sides_[1].diagnostics.coupling_lag;
      max_coupling_lag_t_ = t_;
    }
    const bool at_control = step_ % block == 0 || t_ >= end * (1 - 1e-12) || last_allowed;
    for (auto& side : sides_) {
      if (!side.expected) continue;
      for (const auto& notice : side.report->notices()) warn(side.name, notice.code(), notice.message());
      if (side.report->status() == protocol::StepReport::DONE && done_reason_.empty()) {
        done_reason_ = side.report->done_reason().empty() ? "the " + side.name + " side has nothing more to do"
                                                          : side.report->done_reason().substr(0, 2000);
      }
    }
    if (state_watch_ && at_control) {
      for (const auto& notice : state_watch_->update(t_, sides_[1].diagnostics)) {
        warn("coupler", notice.code, notice.message);
      }
    }
    if (rest_ && at_control) rest_->update(t_, sides_[0].diagnostics);
    if (energy_ && at_control) {
      if (auto failure = energy_->update(t_, step_, sides_[0].diagnostics, sides_[1].diagnostics)) {
        history.write(t_, step_, dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
        throw RunFailure{*failure};
      }
    }
    if (output) {  // dt_s: the step that led to this row
      history.write(t_, step_, dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
      ++frame;
      next_output = next_time_after(next_output, interval, t_);
    }
    if (at_control && t_ < end * (1 - 1e-12)) dt = next_dt();
    if (checkpoint) {
      for (const auto& side : sides_) {
        if (side.expected && !side.report->checkpoint_written()) {
          throw RunFailure{"the " + side.name + " side did not write the checkpoint" + at_step() + " it was asked for"};
        }
      }
      schedule.next_checkpoint = next_time_after(schedule.next_checkpoint, checkpoint_interval, t_);
      // Both sides have theirs on disk: the coupler's file completes the checkpoint.
      save_checkpoint(schedule, summary);
      log_.file_only("checkpoint " + checkpoint_dir + " complete (t = " + std::to_string(t_) + " s)");
    }
    progress_.update(t_, step_, seconds_since(start));
    if (!done_reason_.empty()) {  // a side has nothing more to do: the run stops here, its rows kept
      if (!output) history.write(t_, step_, dt, sides_[0].diagnostics, sides_[1].diagnostics, seconds_since(start_));
      log_("stopped at step " + std::to_string(step_) + " (t = " + std::to_string(t_) + " s): " + done_reason_);
      break;
    }
  }
  summary.stepping_wall_s = stepping_before_ + seconds_since(start);
  if (done_reason_.empty() && t_ < end * (1 - 1e-12)) {
    stopped_at_max_steps_ = true;
    log_("stopped at step " + std::to_string(step_) + " (time.max_steps = " + std::to_string(max_steps) +
         ", in whole exchange windows) before time.end_s");
  }
}

void Coupler::save_checkpoint(const Schedule& schedule, const RunSummary& summary) {
  checkpoint::CouplerState s;
  s.set_format(kCouplerCheckpointFormat);
  s.set_program_version(proto::kProgramVersion);
  s.set_protocol_version(proto::kProtocolVersion);
  s.set_scene_schema_version(proto::kSceneSchemaVersion);
  s.set_scene_hash(proto::scene_hash(scene_));
  *s.mutable_scene() = scene_;
  s.set_step(step_);
  s.set_t(t_);
  s.set_dt(schedule.dt);
  s.set_dt_limit(dt_limit_);
  s.set_frame(schedule.frame);
  s.set_next_output(schedule.next_output);
  s.set_next_checkpoint(schedule.next_checkpoint);
  for (int i = 0; i < 2; ++i) {
    const Side& side = sides_[i];
    auto* out = i == 0 ? s.mutable_solid() : s.mutable_fluid();
    out->set_expected(side.expected);
    out->set_stable_dt(side.stable_dt);
    out->set_stable_dt_limit(side.stable_dt_limit);
    proto::to_proto(side.diagnostics, out->mutable_diagnostics());
    out->set_compute_s(side.compute_s);
    out->set_exchange_s(side.exchange_s);
    out->set_implementation(side.implementation);
  }
  if (energy_) {
    const auto e = energy_->state();
    s.set_energy_e0(e.e0);
    s.set_energy_p(e.p);
    s.set_energy_v(e.v);
    s.set_energy_work(e.work);
    s.set_energy_largest(e.largest);
    s.set_energy_largest_t(e.largest_t);
  }
  if (rest_) {
    const auto r = rest_->state();
    s.set_rest_kinetic(r.kinetic);
    s.set_rest_strain(r.strain);
    s.set_rest_reports(r.reports);
  }
  s.set_max_coupling_lag(max_coupling_lag_);
  s.set_max_coupling_lag_t(max_coupling_lag_t_);
  for (const auto& [limit, steps] : dt_limit_steps_) (*s.mutable_dt_limit_steps())[limit] = steps;
  s.set_dt_min(dt_min_);
  s.set_dt_max(dt_max_);
  s.set_commands(summary.commands);
  s.set_mean_command_s(schedule.mean_command_s);
  s.set_run_id(run_id_);
  s.set_stepping_wall_s(stepping_before_ + seconds_since(stepping_start_));
  write_coupler_checkpoint(output_dir_, checkpoint_directory(step_), s);
}

void Coupler::restore_checkpoint(Schedule& schedule, RunSummary& summary) {
  const auto& s = options_.restart->state;
  schedule.dt = s.dt();
  schedule.frame = s.frame();
  schedule.next_output = s.next_output();
  schedule.next_checkpoint = s.next_checkpoint();
  schedule.mean_command_s = s.mean_command_s();
  dt_limit_ = s.dt_limit();
  for (int i = 0; i < 2; ++i) {
    Side& side = sides_[i];
    const auto& in = i == 0 ? s.solid() : s.fluid();
    if (in.expected() != side.expected) {
      throw RunFailure{"the checkpoint " + options_.restart->directory + (in.expected() ? " has" : " has no") + " " +
                       side.name + " side; this run " + (side.expected ? "has one" : "has none")};
    }
    // The sides' Ready after a restart carries their restored state; the
    // coupler continues with what it had from the reports at the checkpoint.
    side.stable_dt = in.stable_dt();
    side.stable_dt_limit = in.stable_dt_limit();
    side.diagnostics = proto::from_proto(in.diagnostics());
    side.compute_s = in.compute_s();
    side.exchange_s = in.exchange_s();
  }
  if (energy_) {
    energy_->restore(
        {s.energy_e0(), s.energy_p(), s.energy_v(), s.energy_work(), s.energy_largest(), s.energy_largest_t()});
  }
  if (rest_) rest_->restore({s.rest_kinetic(), s.rest_strain(), s.rest_reports()});
  max_coupling_lag_ = s.max_coupling_lag();
  max_coupling_lag_t_ = s.max_coupling_lag_t();
  for (const auto& [limit, steps] : s.dt_limit_steps()) dt_limit_steps_[limit] = steps;
  dt_min_ = s.dt_min();
  dt_max_ = s.dt_max();
  summary.commands = s.commands();
  stepping_before_ = s.stepping_wall_s();  // run.json's totals cover the whole run, before and after the restart
}

void Coupler::await_reports(std::uint64_t step, double t, double timeout_s) {
  const auto deadline = Clock::now() + microseconds(static_cast<std::int64_t>(timeout_s * 1e6));
  auto pending = [&] {
    for (auto& side : sides_) {
      if (side.expected && !side.report) return true;
    }
    return false;
  };
  const auto stalled_before = stalled_;
  while (pending()) {
    auto message = pump(milliseconds(20));
    if (!message) {
      // Time the coupler itself was stopped does not count against the sides
      // (housekeeping() measures it; again here, as the stop may have come
      // during the wait that pump() has just finished).
      housekeeping();
      if (Clock::now() - (stalled_ - stalled_before) > deadline) throw RunFailure{hung_message(timeout_s)};
      continue;
    }
    auto& [side, envelope] = *message;
    if (!envelope.has_step_report() || side->report) unexpected(*side, envelope, "StepReport");
    const auto& report = envelope.step_report();
    // Before anything of it is used: a NaN or an infinity would otherwise go
    // on into history.csv, run.json, the energy check and the next step.
    if (const std::string bad = non_finite_report_fields(report); !bad.empty()) {
      std::ostringstream out;
      out << "the " << side->name << " side reported " << bad << " in its StepReport for step " << step << " (t = " << t
          << " s); " << kFiniteReports;
      throw RunFailure{out.str()};
    }
    if (report.step() != step || report.t() != t) {
      std::ostringstream out;
      out << std::setprecision(17) << "the " << side->name << " side reports step " << report.step()
          << " at t = " << report.t() << " s, but step " << step << " at t = " << t << " s was commanded";
      throw RunFailure{out.str()};
    }
    side->report = report;
  }
}

std::string Coupler::hung_message(double timeout_s) const {
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

}  // namespace hfmpm::coupling::detail
