#include "hfmpm/runtime/curve.hpp"

#include "hfmpm/runtime/transport.hpp"

#include <sys/stat.h>
#include <zmq.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace hfmpm::coupling {
namespace {

constexpr std::size_t kZ85KeyLength = 40;
constexpr const char* kKeyNames[] = {"server_public", "server_secret", "client_public", "client_secret"};

bool z85_key(const std::string& key) {
  if (key.size() != kZ85KeyLength) return false;
  std::uint8_t bytes[32];
  return zmq_z85_decode(bytes, key.c_str()) != nullptr;
}

void write_key_file(const std::string& path, const std::vector<std::pair<std::string, std::string>>& keys,
                    const std::string& comment) {
  // Created 0600 before anything secret is written to it.
  const mode_t old = umask(077);
  std::ofstream out(path, std::ios::trunc);
  umask(old);
  if (!out) throw std::runtime_error("cannot write the key file '" + path + "': " + std::strerror(errno));
  chmod(path.c_str(), 0600);
  out << "# hfmpm CURVE keys (docs/reliability.md, \"Who may join\"): " << comment << "\n";
  for (const auto& [name, value] : keys) out << name << " = " << value << "\n";
  if (!out.flush()) throw std::runtime_error("cannot write the key file '" + path + "'");
}

std::map<std::string, std::string> read_key_file(const std::string& path) {
  struct stat info {};
  if (stat(path.c_str(), &info) != 0) {
    throw std::runtime_error("key file '" + path + "': " + std::strerror(errno) + " (make one with: hfmpm keygen DIR)");
  }
  if ((info.st_mode & 077) != 0) {
    std::ostringstream mode;
    mode << std::oct << (info.st_mode & 0777);
    throw std::runtime_error("key file '" + path + "' is open to other users (mode " + mode.str() +
                             "); it holds a secret key: chmod 600 it");
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the key file '" + path + "'");
  std::map<std::string, std::string> keys;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.size() > 1000)
      throw std::runtime_error("key file '" + path + "' line " + std::to_string(number) + " is too long");
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto equals = line.find('=');
    auto trim = [](const std::string& s) {
      const auto a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
      return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    const std::string name = trim(line.substr(0, equals)),
                      value = equals == std::string::npos ? "" : trim(line.substr(equals + 1));
    bool known = false;
    for (const char* k : kKeyNames) known = known || name == k;
    if (equals == std::string::npos || !known) {
      throw std::runtime_error("key file '" + path + "' line " + std::to_string(number) +
                               ": expected 'NAME = KEY' with NAME one of server_public, server_secret, client_public, "
                               "client_secret");
    }
    if (!z85_key(value)) {
      throw std::runtime_error("key file '" + path + "' line " + std::to_string(number) + ": " + name +
                               " is not a CURVE key (40 Z85 characters)");
    }
    keys[name] = value;
  }
  return keys;
}

std::string need(const std::map<std::string, std::string>& keys, const std::string& name, const std::string& path,
                 const std::string& which) {
  const auto it = keys.find(name);
  if (it == keys.end()) {
    throw std::runtime_error("key file '" + path + "' has no " + name + "; is it the " + which +
                             " file (hfmpm keygen writes coupler.keys and side.keys)?");
  }
  return it->second;
}

// The keys a file of kind `which` must hold, read into their members.
CurveKeys read_keys(const std::string& path, std::initializer_list<std::string CurveKeys::*> members,
                    const std::string& which) {
  static const std::pair<std::string CurveKeys::*, const char*> kNames[] = {
      {&CurveKeys::server_public, "server_public"},
      {&CurveKeys::server_secret, "server_secret"},
      {&CurveKeys::client_public, "client_public"},
      {&CurveKeys::client_secret, "client_secret"}};
  const auto keys = read_key_file(path);
  CurveKeys out;
  for (const auto member : members) {
    for (const auto& [m, name] : kNames) {
      if (m == member) out.*member = need(keys, name, path, which);
    }
  }
  return out;
}

std::string z85_to_binary(const std::string& key) {
  std::string bytes(32, '\0');
  zmq_z85_decode(reinterpret_cast<std::uint8_t*>(bytes.data()), key.c_str());
  return bytes;
}

}  // namespace

CurveKeys generate_curve_keys() {
  if (!zmq_has("curve")) throw std::runtime_error("this libzmq was built without CURVE; tcp cannot be authenticated");
  char pub[41], sec[41];
  CurveKeys keys;
  if (zmq_curve_keypair(pub, sec) != 0) throw std::runtime_error("zmq_curve_keypair failed");
  keys.server_public = pub;
  keys.server_secret = sec;
  if (zmq_curve_keypair(pub, sec) != 0) throw std::runtime_error("zmq_curve_keypair failed");
  keys.client_public = pub;
  keys.client_secret = sec;
  return keys;
}

void write_coupler_key_file(const std::string& path, const CurveKeys& keys) {
  write_key_file(path,
                 {{"server_public", keys.server_public},
                  {"server_secret", keys.server_secret},
                  {"client_public", keys.client_public}},
                 "the coupler's (hfmpm coupler --keys FILE); keep it on the coupler's host");
}

void write_side_key_file(const std::string& path, const CurveKeys& keys) {
  write_key_file(path,
                 {{"server_public", keys.server_public},
                  {"client_public", keys.client_public},
                  {"client_secret", keys.client_secret}},
                 "the sides' (--keys FILE on each side); copy it to the sides' hosts only");
}

CurveKeys read_coupler_key_file(const std::string& path) {
  return read_keys(path, {&CurveKeys::server_public, &CurveKeys::server_secret, &CurveKeys::client_public},
                   "coupler.keys");
}

CurveKeys read_side_key_file(const std::string& path) {
  return read_keys(path, {&CurveKeys::server_public, &CurveKeys::client_public, &CurveKeys::client_secret},
                   "side.keys");
}

void make_curve_server(zmq::socket_t& socket, const std::string& secret_key) {
  socket.set(zmq::sockopt::curve_server, 1);
  socket.set(zmq::sockopt::curve_secretkey, secret_key);
  socket.set(zmq::sockopt::zap_domain, std::string("hfmpm"));
}

void make_curve_client(zmq::socket_t& socket, const std::string& server_public, const std::string& public_key,
                       const std::string& secret_key) {
  socket.set(zmq::sockopt::curve_serverkey, server_public);
  socket.set(zmq::sockopt::curve_publickey, public_key);
  socket.set(zmq::sockopt::curve_secretkey, secret_key);
}

ZapAuthenticator::ZapAuthenticator(zmq::context_t& context, const std::string& allowed_public_key,
                                   std::function<void(const std::string&)> refused) {
  // Bound here, before any server socket of the context accepts a peer:
  // without a handler ZeroMQ would admit every CURVE client.
  auto socket = std::make_shared<zmq::socket_t>(context, zmq::socket_type::rep);
  socket->set(zmq::sockopt::linger, 0);
  socket->bind("inproc://zeromq.zap.01");
  const std::string allowed = z85_to_binary(allowed_public_key);
  thread_ = std::thread([this, socket, allowed, refused = std::move(refused)] {
    std::chrono::steady_clock::time_point last_told{};
    std::uint64_t untold = 0;
    std::string last_address;
    while (!stop_.load()) {
      zmq::pollitem_t item{socket->handle(), 0, ZMQ_POLLIN, 0};
      try {
        if (zmq::poll(&item, 1, std::chrono::milliseconds(100)) <= 0) continue;
        std::vector<zmq::message_t> request;
        do {
          request.emplace_back();
          if (!socket->recv(request.back(), zmq::recv_flags::none)) break;
        } while (request.back().more() && request.size() < 16);
        // version, request id, domain, address, routing id, mechanism, credentials...
        const bool well_formed = request.size() >= 6 && request[0].to_string() == "1.0";
        const bool admitted = well_formed && request[5].to_string() == "CURVE" && request.size() >= 7 &&
                              request[6].to_string() == allowed;
        std::vector<std::string> reply{"1.0",
                                       request.size() > 1 ? request[1].to_string() : "",
                                       admitted ? "200" : "400",
                                       admitted ? "OK" : "not a side of this run",
                                       admitted ? "side" : "",
                                       ""};
        for (std::size_t i = 0; i < reply.size(); ++i) {
          socket->send(zmq::buffer(reply[i]), i + 1 < reply.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
        }
        if (!admitted) {
          ++refused_;
          ++untold;
          last_address = request.size() > 3 ? request[3].to_string() : "?";
          const auto now = std::chrono::steady_clock::now();
          if (refused && now - last_told > std::chrono::seconds(1)) {
            refused("refused " + std::to_string(untold) + " connection" + (untold == 1 ? "" : "s") +
                    " without this run's side key (the last from " + printable(last_address) + ")");
            last_told = now;
            untold = 0;
          }
        }
      } catch (const zmq::error_t&) {
        if (stop_.load()) break;
      }
    }
  });
}

ZapAuthenticator::~ZapAuthenticator() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

}  // namespace hfmpm::coupling
