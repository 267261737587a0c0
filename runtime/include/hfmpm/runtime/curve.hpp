// Authenticated, encrypted tcp: ZeroMQ CURVE with a ZAP handler that admits
// only peers holding the run's side key (docs/reliability.md, "Who may join").
//
// A run has two key pairs, each a pair of 40-character Z85 strings:
// - the coupler's (server) pair: its secret stays with the coupler;
// - the sides' (client) pair: both sides hold it. The coupler admits a peer
//   on its control socket only if it presents the sides' public key, and a
//   side's data-plane socket does the same for the other side.
// A stranger without the key file cannot complete the handshake: ZeroMQ drops
// it before any message reaches the program.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <zmq.hpp>

namespace hfmpm::coupling {

struct CurveKeys {
  std::string server_public, server_secret;  // server_secret: only in the coupler's file
  std::string client_public, client_secret;  // client_secret: only in the sides' file
  bool has_server_secret() const { return !server_secret.empty(); }
  bool has_client_secret() const { return !client_secret.empty(); }
};

// Fresh key pairs for a run (zmq_curve_keypair). Throws if libzmq has no CURVE.
CurveKeys generate_curve_keys();

// Key files: "name = value" lines (server_public, server_secret,
// client_public, client_secret), '#' comments. Written 0600.
// The coupler's file: server pair and client public key. The sides' file:
// server public key and client pair.
void write_coupler_key_file(const std::string& path, const CurveKeys& keys);
void write_side_key_file(const std::string& path, const CurveKeys& keys);
// Throws std::runtime_error naming the file and the problem (missing, unreadable,
// readable by others, a key that is not 40 Z85 characters, a missing key).
CurveKeys read_coupler_key_file(const std::string& path);
CurveKeys read_side_key_file(const std::string& path);

// Socket roles (before bind/connect).
void make_curve_server(zmq::socket_t& socket, const std::string& secret_key);
void make_curve_client(zmq::socket_t& socket, const std::string& server_public, const std::string& public_key,
                       const std::string& secret_key);

// Answers ZeroMQ's authentication requests (ZAP, RFC 27) for one context:
// CURVE peers with the allowed public key are admitted, everyone else is
// refused before the program sees a byte. One per context, alive while any
// CURVE server socket of that context is.
class ZapAuthenticator {
 public:
  // `refused` is told about refusals, at most once per second with a count.
  ZapAuthenticator(zmq::context_t& context, const std::string& allowed_public_key,
                   std::function<void(const std::string&)> refused = {});
  ~ZapAuthenticator();
  ZapAuthenticator(const ZapAuthenticator&) = delete;
  ZapAuthenticator& operator=(const ZapAuthenticator&) = delete;
  std::uint64_t refused() const { return refused_.load(); }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> refused_{0};
  std::thread thread_;
};

}  // namespace hfmpm::coupling
