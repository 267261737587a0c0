// What the coupler writes: history.csv (one row per output interval, flushed
// at once so it stays readable after any failure), the run manifest, its log
// and the progress line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hfmpm/exchange.hpp"

namespace hfmpm::coupling {

class History {
 public:
  // append: continue an existing history (a restart; truncate_history first), without a new header;
  // last_step: the step of its last row (what truncate_history kept).
  explicit History(const std::string& path, bool append = false, std::optional<std::uint64_t> last_step = std::nullopt);
  void write(double t, std::uint64_t step, double dt, const SideDiagnostics& solid, const SideDiagnostics& fluid,
             double wall_s);
  // Whether the last row is the one of `step`: a row is written once per step (a stop by a signal
  // right after an output row writes none).
  bool ends_at(std::uint64_t step) const { return last_step_ == step; }

 private:
  std::ofstream out_;
  std::optional<std::uint64_t> last_step_;
};

// run.json: written at start, rewritten at each change of state and at the end.
// The disk a run keeps for its last run.json saves (Manifest::keep_reserve):
// run.json with every list is a few kB; its warnings are cut at 4 kB each.
inline constexpr std::size_t kManifestReserveBytes = std::size_t{256} * 1024;

class Manifest {
 public:
  explicit Manifest(std::string path) : path_(std::move(path)) {}
  void set(const std::string& key, const std::string& value) { fields_[key] = quoted(value); }
  void set_number(const std::string& key, double value);
  // Appends a string to the list `key` (a JSON array).
  void append(const std::string& key, const std::string& value);
  // Writes run.json whole or not at all: a write that fails (a full disk)
  // leaves the last good file. On a failure it frees the reserve (below) and
  // tries once more, so that the run's last state, which names the failure,
  // still reaches a full disk.
  void save();
  // Keeps `bytes` of the disk for the last saves: a file beside run.json,
  // written now, removed by save() on a failed write or by release_reserve().
  void keep_reserve(std::size_t bytes);
  void release_reserve();

 private:
  static std::string quoted(const std::string& value);
  int write() const;  // 0, or the errno that stopped it
  std::string path_;
  std::string reserve_;  // the reserve file, empty when none is held
  std::map<std::string, std::string> fields_;
  std::map<std::string, std::vector<std::string>> lists_;
};

// Log lines to stderr and to the run's coupler.log.
class Log {
 public:
  // append: continue the log of the run a restart continues.
  void open(const std::string& path, bool echo, bool append = false) {
    open_file(path, append);
    echo_ = echo;
  }
  void open(const std::string& path) { open_file(path, false); }
  void operator()(const std::string& line);
  void file_only(const std::string& line);

 private:
  void open_file(const std::string& path, bool append);
  std::ofstream file_;
  bool echo_ = true;
};

class Progress {
 public:
  explicit Progress(bool enabled, double end_time);
  void update(double t, std::uint64_t step, double wall_s);
  void finish();

 private:
  bool enabled_, tty_;
  double end_time_, last_print_ = -1e9;
  bool printed_ = false;
};

}  // namespace hfmpm::coupling
