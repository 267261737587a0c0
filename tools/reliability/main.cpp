// hfmpm-reliability: kill -9 at random moments, a fuzzer of the control
// plane, and the bad-scene files (docs/reliability.md, "Measured (the
// reliability tool)"). Exit status 0 when nothing wrong was found, 1 when
// something was (a crash, a hang, an orphan, an unreadable output, ...),
// 2 for a bad command line.
#include <cstdlib>
#include <iostream>
#include <string>

#include "common.hpp"
#include "google/protobuf/stubs/logging.h"

namespace {

constexpr const char* kUsage = R"(usage:
  hfmpm-reliability kill --trials N [--seed S] [--keep] [--verbose]
      N runs of `hfmpm run` (prescribed scene; every fourth kgd-viscosity-ci, short);
      SIGKILL a random process (solid, fluid or coupler; inproc: the coupler) at a
      random moment; measure detection time, hangs, orphans, readable outputs.
  hfmpm-reliability fuzz --messages N [--seed S] [--keep] [--verbose]
      N random and mutated messages from strangers to `hfmpm coupler --insecure-tcp`,
      then the real sides join; then a fake coupler fuzzes the sides.
  hfmpm-reliability restart --trials N [--seed S] [--keep] [--verbose]
      One uninterrupted kgd-viscosity-ci run with checkpoints, then N runs of it
      (ipc, tcp, inproc in turn) SIGKILLed (the coupler, or a side) at a random
      moment and continued with `hfmpm run --restart`: history.csv, the exchange
      logs and every HDF5 dataset must equal the uninterrupted run's bit for bit.
  hfmpm-reliability flood --connections N [--fd-limit L] [--insecure-tcp] [--old-zmtp]
                          [--teardowns K] [--max-join S] [--bin DIR] [--keep] [--verbose]
      `hfmpm coupler` (CURVE, stand-in scene, under `ulimit -n L` if given) while
      this tool holds N raw tcp connections to its port that never send a byte
      (reopening any the coupler closes); then the real sides join. The run must
      complete with the same history as without the flood; prints the join time
      with and without it and the coupler's CPU share during the flood.
      --insecure-tcp: plain tcp. --old-zmtp: each connection sends a ZMTP 1.0
      routing id, an eighth of them reopened every 10 ms. --teardowns K: instead,
      K couplers that no side joins (join timeout 0.5 s) end under the flood;
      counts crashes. --max-join S: a join slower than S seconds under the flood
      is a problem. --bin DIR: hfmpm and the stand-in sides from DIR.
  hfmpm-reliability bad-scenes [--verbose]
      `hfmpm validate` on every file in tests/data/bad_scenes/.
exit status: 0 nothing wrong found, 1 problems found, 2 bad command line.
)";

}  // namespace

int main(int argc, char** argv) {
  using namespace hfmpm::reliability;
  // Mutated strings are not UTF-8; the decoder refuses them, and Protobuf would log each.
  google::protobuf::SetLogHandler(nullptr);
  if (argc < 2) {
    std::cerr << kUsage;
    return 2;
  }
  const std::string command = argv[1];
  CommonOptions options;
  long long trials = -1, messages = -1, connections = -1;
  FloodOptions flood;
  try {
    for (int i = 2; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--trials")
        trials = std::stoll(value());
      else if (arg == "--messages")
        messages = std::stoll(value());
      else if (arg == "--connections")
        connections = std::stoll(value());
      else if (arg == "--fd-limit")
        flood.fd_limit = std::stoi(value());
      else if (arg == "--insecure-tcp")
        flood.insecure_tcp = true;
      else if (arg == "--old-zmtp")
        flood.old_zmtp = true;
      else if (arg == "--teardowns")
        flood.teardowns = std::stoi(value());
      else if (arg == "--max-join")
        flood.max_join_s = std::stod(value());
      else if (arg == "--bin")
        flood.bin_dir = value();
      else if (arg == "--seed")
        options.seed = std::stoull(value());
      else if (arg == "--keep")
        options.keep = true;
      else if (arg == "--verbose")
        options.verbose = true;
      else
        throw std::invalid_argument("unknown option '" + arg + "'");
    }
  } catch (const std::exception& e) {
    std::cerr << "hfmpm-reliability: " << e.what() << "\n" << kUsage;
    return 2;
  }
  if (command == "kill" && trials > 0) return kill_command(static_cast<int>(trials), options);
  if (command == "fuzz" && messages > 0) return fuzz_command(static_cast<std::uint64_t>(messages), options);
  if (command == "flood" && connections > 0 && flood.fd_limit >= 0 && flood.teardowns >= 0) {
    return flood_command(static_cast<std::uint64_t>(connections), flood, options);
  }
  if (command == "bad-scenes") return bad_scenes_command(options);
  if (command == "restart" && trials > 0) return restart_command(static_cast<int>(trials), options);
  std::cerr << kUsage;
  return 2;
}
