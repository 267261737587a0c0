// Private to the fuzzer (`hfmpm-reliability fuzz`): the messages it sends,
// the two phases (fuzz_coupler.cpp, fuzz_side.cpp) and their totals.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>
#include <zmq.hpp>

#include "common.hpp"
#include "coupled_support.hpp"
#include "messages.hpp"

namespace hfmpm::reliability {

constexpr double kCouplerDeadlineS = 60;  // a round that takes longer is a hang
constexpr double kSideDeadlineS = 15;     // a side still there this long after Shutdown is a hang
constexpr std::size_t kOversize = (std::size_t{4} << 20) + 4096;       // above the coupler's 4 MiB limit
constexpr std::size_t kSideOversize = (std::size_t{64} << 20) + 4096;  // above a side's 64 MiB limit

// Hex of the first `max` bytes (for a report line).
std::string hex(const std::string& bytes, std::size_t max = 64);

// The frames of one fuzz message, and a line describing it (kept for a report).
struct Message {
  std::vector<std::string> frames;
  std::string kind;
};

// A message a stranger or the fake coupler sends: random bytes, a valid
// Envelope, a mutated one, several frames, an empty frame, or an oversized one.
Message fuzz_message(Rng& rng, const MessageContext& context, const protocol::Envelope* next, std::size_t oversize,
                     double oversize_chance);
bool send_message(zmq::socket_t& socket, const Message& m);
MessageContext make_context(const std::string& dir);

struct CouplerTotals {
  std::uint64_t messages = 0, side_named = 0, raw_connections = 0, rounds = 0;
  int completed = 0, stranger_failed = 0, other_failed = 0, crashes = 0, hangs = 0, history_differs = 0;
  int side_crashes = 0;
  std::vector<std::string> problems;
  std::map<std::string, int> failure_kinds;
};

// One coupler run: up to `budget` stranger messages, then the real sides; returns the messages sent.
std::uint64_t coupler_round(std::uint64_t round, std::uint64_t budget, const CommonOptions& options,
                            const std::string& root, const std::string& scene, const test::Csv& reference,
                            CouplerTotals& totals);

struct SideTotals {
  int trials = 0, crashes = 0, hangs = 0, clean_errors = 0, shut_down = 0, coupler_lost = 0, unclear = 0;
  int errors_reported = 0, setup_failures = 0;
  std::uint64_t messages = 0;
  std::map<int, int> exit_codes;
  std::vector<std::string> problems;
};

// One side against this tool as its coupler, answered validly to a random point, then fuzzed.
void side_trial(std::uint64_t index, const CommonOptions& options, const std::string& root, zmq::context_t& zmq_context,
                SideTotals& totals);

}  // namespace hfmpm::reliability
