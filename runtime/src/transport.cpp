#include "hfmpm/runtime/transport.hpp"

#include <algorithm>
#include <vector>

namespace hfmpm::coupling {

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void send(zmq::socket_t& socket, const protocol::Envelope& envelope) {
  const std::string bytes = proto::encode(envelope);
  if (!socket.send(zmq::buffer(bytes), zmq::send_flags::none)) {
    throw std::runtime_error("could not send a " + std::string(proto::body_name(envelope)) + " message");
  }
}

namespace {

bool wait_readable(zmq::socket_t& socket, std::chrono::microseconds timeout, std::chrono::microseconds spin) {
  const auto start = Clock::now();
  if (spin.count() > 0) {
    zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
    while (Clock::now() - start < spin) {
      if (zmq::poll(&item, 1, std::chrono::milliseconds(0)) > 0) return true;
    }
  }
  const auto left = timeout - std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start);
  zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(left + std::chrono::microseconds(999));
  return zmq::poll(&item, 1, std::max(ms, std::chrono::milliseconds(0))) > 0;
}

}  // namespace

std::optional<protocol::Envelope> receive(zmq::socket_t& socket, std::string_view from,
                                          std::chrono::microseconds timeout, std::chrono::microseconds spin) {
  if (!wait_readable(socket, timeout, spin)) return std::nullopt;
  zmq::message_t message;
  if (!socket.recv(message, zmq::recv_flags::dontwait)) return std::nullopt;
  if (message.more()) {
    zmq::message_t rest;
    do {
      (void)socket.recv(rest, zmq::recv_flags::none);
    } while (rest.more());
    throw proto::ProtocolError("malformed message from " + std::string(from) +
                               ": several frames where the protocol sends exactly one");
  }
  return proto::decode(message.data(), message.size(), from);
}

std::optional<Routed> receive_routed(zmq::socket_t& router, std::chrono::microseconds timeout) {
  if (!wait_readable(router, timeout, std::chrono::microseconds(0))) return std::nullopt;
  std::vector<zmq::message_t> parts;
  do {
    parts.emplace_back();
    if (!router.recv(parts.back(), zmq::recv_flags::dontwait)) return std::nullopt;
  } while (parts.back().more());
  Routed routed;
  routed.peer = parts.front().to_string();
  routed.well_framed = parts.size() == 2;
  if (parts.size() >= 2) routed.payload = parts[1].to_string();
  return routed;
}

void send_routed(zmq::socket_t& router, const std::string& peer, const protocol::Envelope& envelope) {
  const std::string bytes = proto::encode(envelope);
  if (!router.send(zmq::buffer(peer), zmq::send_flags::sndmore) ||
      !router.send(zmq::buffer(bytes), zmq::send_flags::none)) {
    throw std::runtime_error("could not send a " + std::string(proto::body_name(envelope)) + " message to " + peer);
  }
}

std::int64_t data_plane_message_limit(const scene::Scene& scene) {
  constexpr std::int64_t base = std::int64_t{16} << 20;
  if (!scene.solid().has_mpm()) return std::int64_t{256} << 20;
  const auto& mpm = scene.solid().mpm();
  const auto& grid = mpm.grid();
  const double h = mpm.cell_size_m();
  const double cells = h > 0 ? (grid.x_max_m() - grid.x_min_m() + grid.y_max_m() - grid.y_min_m()) / h : 0;
  const double particles = 8 * std::max(1.0, cells) * std::max(1, mpm.cracks_size());
  const double bytes = static_cast<double>(base) + 2048 * particles;
  return bytes < 1e15 ? static_cast<std::int64_t>(bytes) : std::int64_t{1} << 50;
}

std::string printable(const std::string& text, std::size_t max) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  if (text.size() > max) out += "...";
  return out;
}

std::string advertise(const std::string& bound_endpoint, const std::string& host) {
  const std::string prefix = "tcp://";
  if (bound_endpoint.rfind(prefix, 0) != 0 || host.empty()) return bound_endpoint;
  const auto colon = bound_endpoint.rfind(':');
  return prefix + host + bound_endpoint.substr(colon);
}

std::string tcp_host(const std::string& endpoint) {
  const std::string prefix = "tcp://";
  if (endpoint.rfind(prefix, 0) != 0) return "";
  const auto colon = endpoint.rfind(':');
  return endpoint.substr(prefix.size(), colon - prefix.size());
}

}  // namespace hfmpm::coupling
