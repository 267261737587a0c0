// hfmpm-reliability: shared pieces of the three subcommands (kill, fuzz,
// bad-scenes): child processes, a seeded random source, output checks.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace hfmpm::reliability {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start);
void sleep_s(double seconds);

// One random source per trial or round, derived from the seed and the index,
// so that a single trial can be told apart and re-run with the same draws.
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index);
  std::uint64_t next() { return engine_(); }
  // Uniform in [lo, hi] (integers) or [lo, hi) (reals).
  std::uint64_t between(std::uint64_t lo, std::uint64_t hi);
  double uniform(double lo, double hi);
  bool chance(double p) { return uniform(0, 1) < p; }
  std::string bytes(std::size_t n);
  template <class T>
  const T& pick(const std::vector<T>& items) {
    return items[between(0, items.size() - 1)];
  }

 private:
  std::mt19937_64 engine_;
};

// A program started in the background, its output in two files. It gets
// SIGKILL if this tool dies (parent-death signal) or the object is destroyed
// while it runs. `address_space_bytes` > 0 caps its memory (RLIMIT_AS).
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& out_path, const std::string& err_path,
        std::uint64_t address_space_bytes = 0);
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  pid_t pid() const { return pid_; }
  bool running();               // reaps it if it has ended
  bool wait(double timeout_s);  // false on timeout (still running)
  void kill_now();              // SIGKILL and reap
  bool exited() const { return done_ && signal_ == 0; }
  int exit_code() const { return exit_code_; }  // -1 unless it exited
  int term_signal() const { return signal_; }   // 0 unless a signal ended it
  Clock::time_point ended_at() const { return ended_at_; }
  std::string err() const;
  std::string out() const;
  std::string how_it_ended() const;  // "exit 1", "signal 11 (SIGSEGV)", "running"

 private:
  pid_t pid_ = -1;
  bool done_ = false;
  int exit_code_ = -1, signal_ = 0;
  Clock::time_point ended_at_{};
  std::string out_path_, err_path_;
};

// A fresh directory under `parent` (mkdtemp).
std::string make_dir(const std::string& parent, const std::string& prefix);

// Is `pid` a live process (not a zombie) whose command line mentions "hfmpm"?
// (The second test guards against a reused pid.)
bool hfmpm_process_alive(pid_t pid);

// The HDF5 C API opens the file read-only and reads every dataset in it
// (h5_check.cpp). On failure `why` says what failed.
bool h5_readable(const std::string& path, std::string& why);
// A digest (FNV-1a of the bytes) of every dataset, by path: two files with equal
// maps hold the same datasets bit for bit.
bool h5_digests(const std::string& path, std::map<std::string, std::uint64_t>& digests, std::string& why);

// history.csv parses, has its header and at least one row.
bool history_readable(const std::string& path, std::size_t& rows, std::string& why);

// run.json is one JSON object ("{ ... }") and has a "status".
bool manifest_readable(const std::string& path, std::string& status, std::string& why);

double median(std::vector<double> values);
std::string fixed(double value, int decimals);

// Subcommands; each returns the tool's exit status (0: nothing wrong found).
struct CommonOptions {
  std::uint64_t seed = 1;
  bool keep = false;  // keep the scratch directory even when all is well
  bool verbose = false;
};
int kill_command(int trials, const CommonOptions& options);
int fuzz_command(std::uint64_t messages, const CommonOptions& options);
int bad_scenes_command(const CommonOptions& options);
int restart_command(int trials, const CommonOptions& options);
struct FloodOptions {
  int fd_limit = 0;           // > 0: the coupler runs under `ulimit -n fd_limit`
  bool insecure_tcp = false;  // the coupler on plain tcp (--insecure-tcp), not CURVE
  bool old_zmtp = false;      // each connection sends a ZMTP 1.0 routing id; connections churn
  int teardowns = 0;          // > 0: that many couplers no side joins, torn down under the flood
  std::string bin_dir;        // the programs from here instead of this build's
  double max_join_s = 0;      // > 0: a join under the flood slower than this is a problem
};
int flood_command(std::uint64_t connections, const FloodOptions& flood, const CommonOptions& options);

// The end of a command: prints OK or PROBLEMS FOUND, removes `root` when all
// is well (unless --keep), else says where the outputs are; the exit status.
int conclude(bool ok, const std::string& root, const CommonOptions& options);

}  // namespace hfmpm::reliability
