// A Session's launch, control plane and handshake: the program under test as a
// child process, the ROUTER that plays the coupler (heartbeats, routing ids,
// one-frame Envelopes), Hello/Welcome/Listening/Ready, and waiting for the exit.
// The data plane and the step schedule are in data_plane.cpp.
#include "harness.hpp"

#include <charconv>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/proto/envelope.hpp"
#include "solid_scene_rules.hpp"

namespace hfmpm::conformance {
namespace {

namespace fs = std::filesystem;
using std::chrono::microseconds;

microseconds to_us(double seconds) { return microseconds(static_cast<std::int64_t>(seconds * 1e6)); }

std::string body_name(protocol::Envelope::BodyCase body) {
  const auto* field = protocol::Envelope::descriptor()->FindFieldByNumber(static_cast<int>(body));
  return field ? field->name() : "empty";
}

// Routing ids may be binary (ZeroMQ makes one up for a socket that sets none).
std::string printable(const std::string& bytes) {
  std::ostringstream out;
  for (unsigned char c : bytes) {
    if (c >= 0x20 && c < 0x7f) {
      out << c;
    } else {
      out << "\\x" << std::hex << std::setw(2) << std::setfill('0') << static_cast<int>(c) << std::dec;
    }
  }
  return out.str();
}

}  // namespace

void fail(const std::string& why) { throw CheckFailure(why); }

std::string fmt(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof(text), value).ptr;  // shortest that reads back exactly
  return std::string(text, end);
}

std::string describe(const protocol::Envelope& envelope) {
  std::string text(proto::body_name(envelope));
  if (envelope.has_error()) {
    const auto& e = envelope.error();
    text += " (what \"" + e.what() + "\", where \"" + e.where() + "\"): " + e.message();
  } else if (envelope.has_data()) {
    text += " for step " + std::to_string(envelope.data().step());
  }
  return text;
}

Session::Session(Context& context, const LaunchOptions& options)
    : context_(context),
      role_(context.config.role),
      side_(proto::role_name(context.config.role)),
      router_(zmq_, zmq::socket_type::router) {
  const Config& config = context.config;
  ++context.launches;
  dir_ = config.scratch + "/" + context.check + (context.launches > 1 ? "-" + std::to_string(context.launches) : "");
  fs::create_directories(dir_ + "/out");

  std::vector<std::string> overrides = config.overrides;
  if (config.tcp) overrides.emplace_back("coupling.transport=TCP");
  overrides.insert(overrides.end(), options.overrides.begin(), options.overrides.end());
  try {
    scene_ = coupling::load_scene(config.scene_path, {solid::scene_rules(), fluid::scene_rules()}, overrides);
  } catch (const std::exception& e) {
    fail("the scene does not load: " + std::string(e.what()));
  }
  exchange_interval_ = std::max(1u, scene_.coupling().exchange_interval());
  gauss_seidel_ = scene_.coupling().scheme() == scene::Coupling::GAUSS_SEIDEL;
  heartbeat_interval_s_ = scene_.coupling().heartbeat_interval_s();
  peer_ = role_ == protocol::SOLID ? make_fake_fluid(scene_) : make_fake_solid(scene_);

  router_.set(zmq::sockopt::linger, 0);
  router_.set(zmq::sockopt::router_mandatory, 1);
  router_.bind(config.tcp ? "tcp://127.0.0.1:*" : "ipc://" + dir_ + "/control");
  control_endpoint_ = router_.get(zmq::sockopt::last_endpoint);

  std::vector<std::string> args{"--connect", control_endpoint_, "--out", dir_ + "/out"};
  args.insert(args.end(), options.args.begin(), options.args.end());
  const std::string log = dir_ + "/side.log";
  context.logs.push_back(log);
  try {
    process_ = std::make_unique<coupling::ChildProcess>(config.program, args, log);
  } catch (const std::exception& e) {
    fail("cannot launch the program under test: " + std::string(e.what()));
  }
}

Session::~Session() {
  if (process_ && !process_->poll()) {
    kill(process_->pid(), SIGKILL);
    process_->wait_for(5.0);
  }
  process_.reset();
  data_.reset();
  router_.close();
}

// ------------------------------------------------------------ control plane
std::optional<protocol::Envelope> Session::take(const coupling::Routed& routed) {
  const std::string hb = side_ + ".hb";
  if (routed.peer != side_ && routed.peer != hb) {
    fail("a message from routing id '" + printable(routed.peer) + "'; a " + side_ +
         " side talks from the routing ids '" + side_ + "' (control) and '" + hb + "' (heartbeats) only");
  }
  if (!routed.well_framed) {
    fail("a multi-frame message from routing id '" + routed.peer + "'; every message is exactly one frame");
  }
  protocol::Envelope envelope;
  try {
    envelope = proto::decode(routed.payload.data(), routed.payload.size(), "the " + side_ + " side");
  } catch (const proto::ProtocolError& e) {
    fail(std::string("an undecodable message on the control plane: ") + e.what());
  }
  if (envelope.has_heartbeat()) {
    if (envelope.heartbeat().role() != role_) {
      fail("a heartbeat claiming role " + std::string(proto::role_name(envelope.heartbeat().role())) + " from the " +
           side_ + " side");
    }
    beats_.push_back(Beat{Clock::now(), routed.peer, envelope.heartbeat()});
    return std::nullopt;
  }
  if (routed.peer == hb) fail(describe(envelope) + " on the heartbeat socket '" + hb + "'; only Heartbeat goes there");
  if (envelope.has_error()) errors_.push_back(envelope.error());
  return envelope;
}

void Session::beat_if_due() {
  if (!heartbeats_ || !joined_) return;
  const auto now = Clock::now();
  if (now - last_sent_ < to_us(heartbeat_interval_s_)) return;
  protocol::Envelope envelope;
  auto* beat = envelope.mutable_heartbeat();
  beat->set_role(protocol::COUPLER);
  beat->set_sequence(++beat_sequence_);
  beat->set_step(step_);
  const std::string bytes = proto::encode(envelope);
  try {
    // Never block on a side that has gone or stopped reading: a lost beat is its problem.
    if (router_.send(zmq::buffer(side_), zmq::send_flags::sndmore | zmq::send_flags::dontwait)) {
      (void)router_.send(zmq::buffer(bytes), zmq::send_flags::dontwait);
    }
  } catch (const zmq::error_t&) {
  }
  last_sent_ = now;
}

std::chrono::milliseconds Session::wait_slice(Clock::time_point deadline) const {
  auto until = std::min(deadline, Clock::now() + std::chrono::milliseconds(50));
  if (heartbeats_ && joined_) until = std::min(until, last_sent_ + to_us(heartbeat_interval_s_));
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(until - Clock::now());
  return std::max(left, std::chrono::milliseconds(0));
}

std::optional<std::string> Session::ended() {
  auto how = process_->poll();
  if (how && !ended_at_) ended_at_ = Clock::now();
  return how;
}

std::string Session::status_note() {
  const auto how = ended();
  return how ? " (the program " + *how + ")" : "";
}

std::string Session::waited(double timeout_s) {
  const auto how = ended();
  return how ? ": the program " + *how + " (log: " + dir_ + "/side.log)" : " within " + fmt(timeout_s) + " s";
}

// A program that has ended gets a moment for its last messages to arrive, then waits stop.
bool Session::gone() { return ended() && Clock::now() - *ended_at_ > std::chrono::milliseconds(300); }

std::optional<protocol::Envelope> Session::poll_control(double timeout_s) {
  if (!pending_.empty()) {
    auto envelope = pending_.front();
    pending_.pop_front();
    return envelope;
  }
  const auto deadline = Clock::now() + to_us(timeout_s);
  while (true) {
    beat_if_due();
    auto routed = coupling::receive_routed(router_, wait_slice(deadline));
    if (routed) {
      if (auto envelope = take(*routed)) return envelope;
      continue;
    }
    if (Clock::now() >= deadline || gone()) return std::nullopt;
  }
}

protocol::Envelope Session::expect_control(protocol::Envelope::BodyCase expected, double timeout_s,
                                           const std::string& context) {
  auto envelope = poll_control(timeout_s);
  if (!envelope) {
    fail("no " + body_name(expected) + " " + context + waited(timeout_s));
  }
  if (envelope->body_case() != expected) {
    fail("the " + side_ + " side sent " + describe(*envelope) + " " + context + " where " + body_name(expected) +
         " was due");
  }
  return *envelope;
}

void Session::send_control(const protocol::Envelope& envelope) {
  try {
    coupling::send_routed(router_, side_, envelope);
  } catch (const std::exception& e) {
    fail("cannot send " + std::string(proto::body_name(envelope)) + " to routing id '" + side_ + "': " + e.what() +
         status_note());
  }
  last_sent_ = Clock::now();
}

void Session::send_control_frames(const std::vector<std::string>& frames) {
  try {
    if (!router_.send(zmq::buffer(side_), zmq::send_flags::sndmore)) fail("cannot send to '" + side_ + "'");
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const auto flags = i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      if (!router_.send(zmq::buffer(frames[i]), flags)) fail("cannot send to '" + side_ + "'");
    }
  } catch (const zmq::error_t& e) {
    fail("cannot send to routing id '" + side_ + "': " + e.what() + status_note());
  }
  last_sent_ = Clock::now();
}

// ---------------------------------------------------------------- handshake
protocol::Hello Session::expect_hello(std::uint32_t version) {
  auto envelope = poll_control(kStartTimeout);
  if (!envelope) fail("no Hello after the launch" + waited(kStartTimeout));
  if (!envelope->has_hello()) fail("the first message was " + describe(*envelope) + "; it must be Hello");
  hello_ = envelope->hello();
  joined_ = true;
  if (hello_.role() != role_) {
    fail("Hello.role is " + std::string(proto::role_name(hello_.role())) + "; a " + side_ + " side says " +
         protocol::Role_Name(role_));
  }
  if (hello_.protocol_version() != version) {
    fail("Hello.protocol_version is " + std::to_string(hello_.protocol_version()) + " where " +
         std::to_string(version) + " was due");
  }
  if (hello_.scene_schema_version() != proto::kSceneSchemaVersion) {
    fail("Hello.scene_schema_version is " + std::to_string(hello_.scene_schema_version()) + " where " +
         std::to_string(proto::kSceneSchemaVersion) + " (the scene.proto this harness was built with) was due");
  }
  if (hello_.implementation().empty()) fail("Hello.implementation is empty; it names the program");
  if (hello_.implementation_version().empty()) fail("Hello.implementation_version is empty");
  return hello_;
}

void Session::send_welcome() {
  protocol::Envelope envelope;
  auto* welcome = envelope.mutable_welcome();
  welcome->set_protocol_version(proto::kProtocolVersion);
  welcome->set_scene_schema_version(proto::kSceneSchemaVersion);
  welcome->set_run_id("conformance-" + context_.check);
  *welcome->mutable_scene() = scene_;
  welcome->set_output_dir(dir_ + "/out");
  data_.emplace(zmq_, zmq::socket_type::pair);
  data_->set(zmq::sockopt::linger, 0);
  data_->set(zmq::sockopt::sndtimeo, static_cast<int>(kMessageTimeout * 1000));
  const std::string bind = context_.config.tcp ? "tcp://127.0.0.1:*" : "ipc://" + dir_ + "/data";
  if (role_ == protocol::SOLID) {
    welcome->mutable_data_plane()->set_mode(protocol::DataPlane::BIND);
    welcome->mutable_data_plane()->set_endpoint(bind);
  } else {
    data_->bind(bind);
    data_endpoint_ = data_->get(zmq::sockopt::last_endpoint);
    welcome->mutable_data_plane()->set_mode(protocol::DataPlane::CONNECT);
    welcome->mutable_data_plane()->set_endpoint(data_endpoint_);
  }
  send_control(envelope);
  welcome_sent_at_ = last_sent_;
}

void Session::connect_to_listening() {
  const auto envelope = expect_control(protocol::Envelope::kListening, kMessageTimeout, "after Welcome (BIND)");
  const std::string endpoint = envelope.listening().data_endpoint();
  const std::string where = "Listening.data_endpoint '" + endpoint + "'";
  if (endpoint.rfind("ipc://", 0) != 0 && endpoint.rfind("tcp://", 0) != 0) {
    fail(where + " is not an ipc:// or tcp:// address the fluid can connect to");
  }
  const std::string host = coupling::tcp_host(endpoint);
  const std::string port = endpoint.substr(endpoint.rfind(':') + 1);
  if (endpoint.rfind("tcp://", 0) == 0 &&
      (host.empty() || host == "*" || host == "0.0.0.0" || port == "*" || port == "0")) {
    fail(where + " is a wildcard, not an address a peer can connect to");
  }
  data_endpoint_ = endpoint;
  try {
    data_->connect(endpoint);
  } catch (const zmq::error_t& e) {
    fail(where + " is not connectable: " + e.what());
  }
}

void Session::start(bool strict) {
  expect_hello();
  if (strict) {  // the coupler's heartbeats may reach a side before its Welcome
    protocol::Envelope beat;
    beat.mutable_heartbeat()->set_role(protocol::COUPLER);
    beat.mutable_heartbeat()->set_sequence(++beat_sequence_);
    send_control(beat);
  }
  send_welcome();
  if (role_ == protocol::SOLID) {
    connect_to_listening();
    expect_frame(0, 0.0);
    if (strict) {
      if (auto early = poll_control(0.3)) {
        fail("the solid sent " + describe(*early) +
             " before it had the fluid's step-0 frame; Ready comes after the initial exchange");
      }
    }
    send_frame(peer_->make(0, 0.0));
  } else {
    if (strict) {
      if (auto early = poll_frame(0.3)) {
        fail("the fluid sent its DataFrame for step " + std::to_string(early->step()) +
             " before the solid's step-0 CrackState; at step 0 the fluid waits for the solid first");
      }
      if (!pending_.empty()) {
        fail("the fluid sent " + describe(pending_.front()) +
             " before the solid's step-0 CrackState; Ready comes after the initial exchange");
      }
    }
    send_frame(peer_->make(0, 0.0));
    expect_frame(0, 0.0);
  }
  ready_ = expect_control(protocol::Envelope::kReady, kMessageTimeout, "after the step-0 exchange").ready();
  const double stable = ready_.stable_dt();
  if (!(stable > 0)) fail("Ready.stable_dt = " + fmt(stable) + " s; it must be > 0 (+inf if unlimited)");
  dt_ = scene_.time().safety_factor() * (std::isfinite(stable) ? stable : 2e-4);
}

// ------------------------------------------------------------------ process
bool Session::wait_exit(double timeout_s) {
  const auto deadline = Clock::now() + to_us(timeout_s);
  while (true) {
    if (ended()) return true;
    if (Clock::now() >= deadline) return false;
    (void)poll_control(0.02);
  }
}

double Session::seconds_to_exit(Clock::time_point since) const {
  return ended_at_ ? std::chrono::duration<double>(*ended_at_ - since).count() : -1;
}

}  // namespace hfmpm::conformance
