// Messages from the sides and their liveness: routing, decoding, heartbeats
// both ways, children that ended, silent sides, the last words of a side.
#include "coupler_session.hpp"

namespace hfmpm::coupling::detail {

Side* Coupler::side_named(const std::string& name) {
  for (auto& side : sides_) {
    if (side.expected && side.name == name) return &side;
  }
  return nullptr;
}

std::string Coupler::log_hint(const Side& side) const {
  return side.log_path.empty() ? "" : " (its output is in " + side.log_path + ")";
}

std::optional<std::pair<Side*, protocol::Envelope>> Coupler::pump(microseconds wait) {
  housekeeping();
  auto routed = router_->receive(wait);
  if (!routed) return std::nullopt;
  const auto dot = routed->peer.find('.');
  const std::string base = routed->peer.substr(0, dot);
  Side* side = side_named(base);
  const bool heartbeat_socket = dot != std::string::npos && routed->peer.substr(dot) == ".hb";
  if (!side || (dot != std::string::npos && !heartbeat_socket)) {
    // Logged the first time and then at most once a second, with a count.
    ++strangers_;
    const auto now = Clock::now();
    if (strangers_ == 1 || now - last_stranger_log_ > std::chrono::seconds(1)) {
      log_("ignored a message from an unknown peer '" + printable(routed->peer) + "' (" +
           std::to_string(routed->payload.size()) + " bytes; " + std::to_string(strangers_) +
           " from strangers so far); only the solid and fluid sides may talk to the coupler");
      last_stranger_log_ = now;
    }
    return std::nullopt;
  }
  protocol::Envelope envelope;
  try {
    if (!routed->well_framed) throw proto::ProtocolError("a multi-frame message; the protocol sends one frame");
    envelope = proto::decode(routed->payload.data(), routed->payload.size(), "the " + side->name + " side");
  } catch (const proto::ProtocolError& e) {
    throw RunFailure{"the " + side->name + " side broke the protocol" + at_step(*side) + ": " + e.what()};
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

void Coupler::check_stop_request() const {
  if (options_.stop_request) {
    if (const int signal = options_.stop_request->load()) throw RunInterrupted{signal};
  }
}

void Coupler::housekeeping() {
  const auto now = Clock::now();
  if (now - last_housekeeping_ < milliseconds(5)) return;
  // The coupler runs this every few milliseconds while it waits. A gap of
  // half a heartbeat timeout means the coupler itself did not run (stopped
  // with SIGSTOP, or starved by the machine): the sides' silence over it is
  // the coupler's, not theirs (with --transport inproc the side threads were
  // stopped with it), so their clocks move on by the gap.
  const auto gap = now - last_housekeeping_;
  if (last_housekeeping_ != Clock::time_point{} && gap > heartbeat_timeout_ / 2) {
    for (auto& side : sides_) side.last_heard += std::chrono::duration_cast<Clock::duration>(gap);
    stalled_ += std::chrono::duration_cast<Clock::duration>(gap);  // and the step timeout (await_reports)
    std::ostringstream out;
    out << "the coupler did not run for " << std::chrono::duration<double>(gap).count() << " s" << at_step()
        << " (stopped or starved); the sides' silence over that time is not counted against them";
    log_.file_only(out.str());
  }
  last_housekeeping_ = now;
  if (!stepping_) check_stop_request();  // while the sides join; in the loop, between rounds
  {
    std::string refusals;  // CURVE refusals, connections closed beyond the cap
    {
      std::lock_guard<std::mutex> lock(refusals_mutex_);
      refusals.swap(refusals_);
    }
    if (!refusals.empty()) log_.file_only(refusals);
  }
  for (auto& side : sides_) {
    if (!side.expected || side.stopping) continue;
    if (side.process) {
      if (auto ended = side.process->poll()) throw RunFailure{ended_message(side, *ended)};
    }
    if (side.thread_exit && side.thread_exit->load() >= 0) {
      const std::string reported = drain_error_from(side);
      throw RunFailure{"the in-process " + side.name + " side ended with code " +
                       std::to_string(side.thread_exit->load()) + at_step(side) +
                       (reported.empty() ? "" : ": " + reported)};
    }
    if (side.joined && now - side.last_heard > heartbeat_timeout_) {
      std::ostringstream out;
      out << "the " << side.name << " side stopped answering" << at_step() << ": nothing from it for "
          << scene_.coupling().heartbeat_timeout_s() << " s (its last heartbeat was at step " << side.heartbeat_step
          << ")" << log_hint(side);
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

std::string Coupler::ended_message(Side& side, const std::string& ended) {
  std::string reported = drain_error_from(side);
  if (reported.empty() && side.process->exit_status() == std::optional<int>(kSideCouplerLost)) {
    reported =
        "it lost the coupler (exit status 4: nothing from the coupler for coupling.heartbeat_timeout_s; was "
        "the coupler stopped or starved?)";
  }
  return "the " + side.name + " side (pid " + std::to_string(side.process->pid()) + ") " + ended + at_step(side) +
         (reported.empty() ? "" : ": " + reported) + log_hint(side);
}

std::string Coupler::drain_error_from(Side& side) {
  const auto until = Clock::now() + milliseconds(200);
  while (Clock::now() < until) {
    auto routed = router_->receive(milliseconds(20));
    if (!routed || routed->peer != side.name) continue;
    try {
      const auto envelope = proto::decode(routed->payload.data(), routed->payload.size(), side.name);
      if (envelope.has_error()) return envelope.error().message();
    } catch (const proto::ProtocolError&) {
    }
  }
  return "";
}

void Coupler::send_to(Side& side, const protocol::Envelope& envelope) {
  try {
    router_->send(side.name, envelope);
    side.last_sent = Clock::now();
  } catch (const std::exception& e) {
    // Usually the process has just died: say how, rather than that a send failed.
    if (side.process && side.process->wait_for(0.5)) throw RunFailure{ended_message(side, *side.process->poll())};
    throw RunFailure{"cannot reach the " + side.name + " side" + at_step(side) + ": " + e.what() + log_hint(side)};
  }
}

void Coupler::unexpected(const Side& side, const protocol::Envelope& envelope, const std::string& expected) {
  throw RunFailure{"the " + side.name + " side sent an unexpected " + std::string(proto::body_name(envelope)) +
                   " message" + at_step(side) + " where " + expected + " was due"};
}

}  // namespace hfmpm::coupling::detail
