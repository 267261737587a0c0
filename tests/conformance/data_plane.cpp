// The data plane and the step schedule of a Session: the side's frames taken
// and checked in the order the scheme prescribes, our frames sent back, and one
// StepCommand end to end with its StepReport checked against the command.
#include <cmath>

#include "harness.hpp"
#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::conformance {
namespace {

using std::chrono::microseconds;

microseconds to_us(double seconds) { return microseconds(static_cast<std::int64_t>(seconds * 1e6)); }

}  // namespace

// --------------------------------------------------------------- data plane
std::optional<protocol::DataFrame> Session::poll_frame(double timeout_s) {
  if (!data_) fail("internal: no data plane before Welcome");
  const auto deadline = Clock::now() + to_us(timeout_s);
  while (true) {
    beat_if_due();
    zmq::pollitem_t items[] = {{data_->handle(), 0, ZMQ_POLLIN, 0}, {router_.handle(), 0, ZMQ_POLLIN, 0}};
    zmq::poll(items, 2, wait_slice(deadline));
    if (items[1].revents & ZMQ_POLLIN) {
      if (auto routed = coupling::receive_routed(router_, microseconds(0))) {
        if (auto envelope = take(*routed)) {
          // Sockets do not order messages between them: a Ready or StepReport sent after
          // this frame may come first. Keep it for poll_control; an Error ends the wait.
          if (envelope->has_error()) {
            fail("the " + side_ + " side sent " + describe(*envelope) + " while a DataFrame was due");
          }
          pending_.push_back(*envelope);
        }
      }
    }
    if (items[0].revents & ZMQ_POLLIN) {
      zmq::message_t message;
      if (data_->recv(message, zmq::recv_flags::dontwait)) {
        if (message.more()) fail("a multi-frame message on the data plane; every message is exactly one frame");
        protocol::Envelope envelope;
        try {
          envelope = proto::decode(message.data(), message.size(), "the " + side_ + " side (data plane)");
        } catch (const proto::ProtocolError& e) {
          fail(std::string("an undecodable message on the data plane: ") + e.what());
        }
        if (!envelope.has_data()) fail(describe(envelope) + " on the data plane; only DataFrame goes there");
        return envelope.data();
      }
    }
    if (Clock::now() >= deadline || gone()) return std::nullopt;
  }
}

protocol::DataFrame Session::expect_frame(std::uint64_t step, double t) {
  auto frame = poll_frame(kMessageTimeout);
  if (!frame) {
    std::string meanwhile;
    for (const auto& envelope : pending_) meanwhile += (meanwhile.empty() ? "" : ", ") + describe(envelope);
    fail("no DataFrame for step " + std::to_string(step) + waited(kMessageTimeout) +
         (meanwhile.empty() ? "" : "; meanwhile on the control plane: " + meanwhile));
  }
  if (frame->step() != step) {
    fail("a DataFrame for step " + std::to_string(frame->step()) + " where step " + std::to_string(step) +
         " was due (Jacobi: one frame per exchange step, in order)");
  }
  const bool right = role_ == protocol::SOLID ? frame->has_crack() : frame->has_fluid();
  if (!right) {
    fail("the DataFrame for step " + std::to_string(step) + " carries " +
         (frame->has_crack()   ? "a CrackState"
          : frame->has_fluid() ? "a FluidState"
                               : "no payload") +
         "; a " + side_ + " side sends " + (role_ == protocol::SOLID ? "CrackState" : "FluidState"));
  }
  if (!(std::abs(frame->t() - t) <= 1e-9 * std::max(1.0, std::abs(t)))) {
    fail("the DataFrame for step " + std::to_string(step) + " has t = " + fmt(frame->t()) +
         " s; after that step t = " + fmt(t) + " s");
  }
  peer_->check(*frame);
  return *frame;
}

void Session::send_frame(const protocol::DataFrame& frame) {
  protocol::Envelope envelope;
  *envelope.mutable_data() = frame;
  send_data_bytes(proto::encode(envelope));
}

void Session::send_data_bytes(const std::string& bytes) {
  if (!data_) fail("internal: no data plane before Welcome");
  if (!data_->send(zmq::buffer(bytes), zmq::send_flags::none)) {
    fail("cannot send on the data plane within " + fmt(kMessageTimeout) + " s: the side never connected" +
         status_note());
  }
}

bool Session::peer_sends_first(std::uint64_t step) const {
  return role_ == protocol::FLUID && (step == 0 || gauss_seidel_);
}

void Session::exchange(std::uint64_t step, double t) {
  if (peer_sends_first(step) || peer_early_) {
    send_frame(peer_->make(step, t));
    expect_frame(step, t);
  } else {
    expect_frame(step, t);  // Jacobi: the side sends its frame for step n before it waits for ours
    send_frame(peer_->make(step, t));
  }
}

// ----------------------------------------------------------------- schedule
std::vector<double> Session::send_command(std::uint32_t num_steps, bool write_output) {
  protocol::Envelope envelope;
  auto* command = envelope.mutable_step_command();
  command->set_first_step(step_);
  command->set_num_steps(num_steps);
  command->set_t(t_);
  command->set_dt(dt_);
  command->set_write_output(write_output);
  command->set_output_frame(write_output ? ++output_frame_ : 0);
  send_control(envelope);
  std::vector<double> times;
  double t = t_;
  for (std::uint32_t i = 0; i < num_steps; ++i) times.push_back(t += dt_);
  return times;
}

protocol::StepReport Session::run_command(std::uint32_t num_steps, bool write_output) {
  const std::string what = "StepCommand{first_step " + std::to_string(step_) + ", num_steps " +
                           std::to_string(num_steps) + ", dt " + fmt(dt_) + (write_output ? ", write_output" : "") +
                           "}";
  const auto times = send_command(num_steps, write_output);
  for (std::uint32_t i = 0; i < num_steps; ++i) {
    const std::uint64_t step = step_ + i + 1;
    if (step % exchange_interval_ == 0) exchange(step, times[i]);
  }
  const auto report = expect_control(protocol::Envelope::kStepReport, kMessageTimeout, "after " + what).step_report();
  const std::uint64_t step = step_ + num_steps;
  const double t = times.back();
  if (report.step() != step) {
    fail("StepReport.step = " + std::to_string(report.step()) + " after " + what + "; step " + std::to_string(step) +
         " was due");
  }
  if (report.t() != t) {
    fail("StepReport.t = " + fmt(report.t()) + " s after " + what + "; t accumulated as t += dt is " + fmt(t) +
         " s, and the coupler compares bit for bit");
  }
  if (!(report.stable_dt() > 0)) fail("StepReport.stable_dt = " + fmt(report.stable_dt()) + " s; it must be > 0");
  if (report.status() != protocol::StepReport::OK && report.status() != protocol::StepReport::DONE) {
    fail("StepReport.status is " + protocol::StepReport::Status_Name(report.status()) + "; OK or DONE is due");
  }
  for (double v : {report.compute_s(), report.exchange_s()}) {
    if (!(std::isfinite(v) && v >= 0)) fail("StepReport compute_s/exchange_s = " + fmt(v) + "; wall seconds are >= 0");
  }
  step_ = step;
  t_ = t;
  if (std::isfinite(report.stable_dt())) dt_ = scene_.time().safety_factor() * report.stable_dt();
  if (auto extra = poll_frame(0.005)) {
    fail("an extra DataFrame for step " + std::to_string(extra->step()) + " after the StepReport of " + what);
  }
  return report;
}

}  // namespace hfmpm::conformance
