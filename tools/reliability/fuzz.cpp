// `hfmpm-reliability fuzz --messages N [--seed S]`.
//
// Phase 1, the coupler: `hfmpm coupler` on plain tcp (--insecure-tcp, so a
// stranger reaches it; with CURVE a peer without the sides' key is refused
// before the coupler sees a byte) receives batches of random and mutated
// messages from stranger peers and raw tcp garbage; then the real sides join.
// The coupler must complete or fail with a message: never die by a signal,
// never hang.
//
// Phase 2, a side: this tool plays the coupler (a ROUTER socket), starts
// hfmpm-prescribed-solid or -fluid against it, answers its Hello validly up
// to a random point and then with random and mutated messages. The side must
// exit with a clear error (or obey a Shutdown): never die by a signal, never hang.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <zmq.hpp>

#include "common.hpp"
#include "coupled_support.hpp"
#include "fluid_scene_rules.hpp"
#include "fuzz.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "messages.hpp"
#include "solid_scene_rules.hpp"

namespace hfmpm::reliability {

namespace fs = std::filesystem;

std::string hex(const std::string& bytes, std::size_t max) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < max; ++i) {
    out += digits[static_cast<unsigned char>(bytes[i]) >> 4];
    out += digits[static_cast<unsigned char>(bytes[i]) & 15];
  }
  return out + (bytes.size() > max ? "..." : "");
}

Message fuzz_message(Rng& rng, const MessageContext& context, const protocol::Envelope* next, std::size_t oversize,
                     double oversize_chance) {
  Message m;
  const double r = rng.uniform(0, 1);
  auto envelope_bytes = [&]() {
    const auto envelope = next && rng.chance(0.5) ? *next : random_envelope(rng, context);
    return proto::encode(envelope);
  };
  if (rng.chance(oversize_chance)) {
    m.kind = "oversized";
    m.frames.push_back(std::string(oversize + rng.between(0, 1 << 20), '\x0a'));
  } else if (r < 0.15) {
    m.kind = "random bytes";
    m.frames.push_back(rng.bytes(rng.between(1, 512)));
  } else if (r < 0.40) {
    m.kind = "valid envelope";
    m.frames.push_back(envelope_bytes());
  } else if (r < 0.90) {
    m.kind = "mutated envelope";
    m.frames.push_back(mutate(envelope_bytes(), rng));
  } else if (r < 0.97) {
    m.kind = "multi-frame";
    const auto n = rng.between(2, 4);
    for (std::uint64_t i = 0; i < n; ++i) m.frames.push_back(rng.chance(0.5) ? envelope_bytes() : rng.bytes(8));
  } else {
    m.kind = "empty frame";
    m.frames.push_back("");
  }
  return m;
}

bool send_message(zmq::socket_t& socket, const Message& m) {
  for (std::size_t i = 0; i < m.frames.size(); ++i) {
    const auto flags =
        (i + 1 < m.frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none) | zmq::send_flags::dontwait;
    if (!socket.send(zmq::buffer(m.frames[i]), flags)) return false;
  }
  return true;
}

MessageContext make_context(const std::string& dir) {
  MessageContext context;
  context.coupled_scene = coupling::parse_scene(test::prescribed_scene(0.05, 0.01), "prescribed",
                                                {solid::scene_rules(), fluid::scene_rules()});
  context.dry_scene = context.coupled_scene;
  context.dry_scene.clear_fluid();
  context.data_endpoint = "ipc://" + dir + "/nobody";
  context.output_dir = dir;
  return context;
}

int fuzz_command(std::uint64_t messages, const CommonOptions& options) {
  const std::string root = make_dir("/tmp", "hfmpm-reliability-fuzz");
  std::cout << "hfmpm-reliability fuzz: " << messages << " messages to the coupler, seed " << options.seed
            << ", output under " << root << "\n";
  const std::string scene = root + "/prescribed.scene";
  test::write_file(scene, test::prescribed_scene(0.05, 0.01));
  const auto reference_run = test::run({test::bin("hfmpm"), "run", scene, "--out", root + "/reference", "--quiet"}, 60);
  if (reference_run.exit_code != 0) {
    std::cout << "the run without strangers failed: " << reference_run.err << "\n";
    return 1;
  }
  const test::Csv reference = test::read_csv(root + "/reference/history.csv");

  const auto start = Clock::now();
  CouplerTotals coupler;
  for (std::uint64_t round = 0, sent = 0; sent < messages; ++round) {
    sent += coupler_round(round, messages - sent, options, root, scene, reference, coupler);
  }
  const double coupler_s = seconds_since(start);

  SideTotals side;
  const std::uint64_t trials = std::clamp<std::uint64_t>(messages / 100, 10, 1000);
  {
    zmq::context_t zmq_context;
    for (std::uint64_t i = 0; i < trials; ++i) side_trial(i, options, root, zmq_context, side);
  }
  const double side_s = seconds_since(start) - coupler_s;

  std::cout << "\nsummary (fuzz --messages " << messages << " --seed " << options.seed << ")\n"
            << "phase 1, the coupler (hfmpm coupler --insecure-tcp; " << fixed(coupler_s, 1) << " s):\n"
            << "  messages sent by strangers: " << coupler.messages << " in " << coupler.rounds << " runs ("
            << coupler.side_named
            << " stranger sockets took a side's routing id), raw tcp garbage connections: " << coupler.raw_connections
            << "\n"
            << "  crashes: " << coupler.crashes << ", hangs: " << coupler.hangs << "\n"
            << "  completed runs: " << coupler.completed
            << " (history differs from the run without strangers: " << coupler.history_differs << ")\n"
            << "  runs failed cleanly by a stranger message under a side's name: " << coupler.stranger_failed;
  if (!coupler.failure_kinds.empty()) {
    std::cout << " (";
    bool first = true;
    for (const auto& [kind, n] : coupler.failure_kinds) {
      std::cout << (first ? "" : ", ") << "\"" << kind << "\" " << n;
      first = false;
    }
    std::cout << ")";
  }
  std::cout << "\n"
            << "  other failures: " << coupler.other_failed
            << "; real sides killed by a signal: " << coupler.side_crashes << "\n"
            << "  (with CURVE, the default on tcp, none of these peers gets a message to the coupler)\n"
            << "phase 2, a side (this tool as the coupler; " << fixed(side_s, 1) << " s):\n"
            << "  trials: " << side.trials << ", messages sent: " << side.messages << "\n"
            << "  crashes: " << side.crashes << ", hangs: " << side.hangs << "\n"
            << "  clean failures (exit with a message): " << side.clean_errors
            << ", exits for no answer from the coupler: " << side.coupler_lost
            << ", exit 0 or 5 on a Shutdown: " << side.shut_down << ", nonzero exit without a message: " << side.unclear
            << "\n"
            << "  sides that also told the coupler with an Error message: " << side.errors_reported << "\n"
            << "  exit codes:";
  for (const auto& [code, n] : side.exit_codes) std::cout << " " << code << " x" << n;
  std::cout << "\n  valid exchanges before the fuzz that failed: " << side.setup_failures << "\n"
            << "messages sent in all: " << coupler.messages + side.messages
            << "; crashes: " << coupler.crashes + side.crashes + coupler.side_crashes
            << "; hangs: " << coupler.hangs + side.hangs << "\n";
  const bool ok = coupler.crashes == 0 && coupler.hangs == 0 && coupler.other_failed == 0 &&
                  coupler.history_differs == 0 && coupler.side_crashes == 0 && coupler.problems.empty() &&
                  side.problems.empty();
  for (const auto& p : coupler.problems) std::cout << "problem: " << p << "\n";
  for (const auto& p : side.problems) std::cout << "problem: " << p << "\n";
  return conclude(ok, root, options);
}

}  // namespace hfmpm::reliability
