#include "hfmpm/runtime/transport.hpp"

#include <unistd.h>

#include <algorithm>
#include <stdexcept>

namespace hfmpm::coupling {

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::string host_name() {
  char buffer[256] = {};
  return gethostname(buffer, sizeof(buffer) - 1) == 0 ? std::string(buffer) : std::string("localhost");
}

void Link::send(const protocol::Envelope& envelope) {
  if (!send_bytes(proto::encode(envelope), true)) {
    throw std::runtime_error("could not send a " + std::string(proto::body_name(envelope)) + " message");
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
