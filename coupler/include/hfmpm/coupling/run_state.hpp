// Is the run in a directory still going? run.json names the coupler that
// writes it (coupler_pid, coupler_host, coupler_start_ticks, boot_id); a
// coupler killed with SIGKILL (or a machine that went down) leaves run.json at
// "starting" or "running". The next `hfmpm` that reads the directory
// (`hfmpm status DIR`, `hfmpm run --restart DIR`) checks whether that
// process still exists and records the run as stopped when it does not
// (docs/reliability.md, "A coupler killed with SIGKILL").
#pragma once

#include <sys/types.h>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace hfmpm::coupling {

// What run.json's status becomes when its coupler is found gone.
inline constexpr const char* kStoppedWithoutFinishing = "stopped without finishing (coupler killed?)";

// /proc/PID/stat's start time (clock ticks after boot), 0 if there is no such process.
std::uint64_t process_start_ticks(pid_t pid);
// /proc/sys/kernel/random/boot_id: changes at every boot ("" if unreadable).
std::string boot_id();

struct RunState {
  enum class Coupler {
    finished,    // the status is a final one (completed, failed, interrupted, ...)
    alive,       // the recorded coupler is running on this host
    gone,        // on this host, and no such process (or another one with its pid)
    other_host,  // recorded on another host: cannot tell from here
  };
  std::string status;  // run.json's status, as found (before any update)
  Coupler coupler = Coupler::finished;
  long pid = 0;
  std::string host, started_at;
  std::string detail;  // why `gone` or `other_host`, for a message
};

// Reads DIR/run.json; throws std::runtime_error naming the file if it is
// missing or has no status. `record`: a run whose coupler is gone gets
// status kStoppedWithoutFinishing in run.json (the status it had goes to
// "status_before_check", and "stopped_found_at" says when it was noticed).
RunState check_run_state(const std::string& run_dir, bool record);

// One live run per output directory (docs/reliability.md, "One live run per
// output directory"): `hfmpm run` and `hfmpm coupler` (with or without
// --restart) hold DIR/.lock with flock(2) for the whole run. The kernel
// releases it when the process ends in any way (kill -9 included), so a lock
// file left by a dead run does not block; the file stays and names its last
// holder. The descriptor is close-on-exec: the sides a coupler starts never
// hold it.
inline constexpr const char* kRunLockFile = ".lock";

// Who holds (or last held) a directory's lock, as its lock file says.
struct RunLockHolder {
  long pid = 0;  // 0 while the holder has not yet written its name
  std::string host, started_at;
};

// The directory's lock is held by a live process (what() names it and the directory).
struct DirectoryInUse : std::runtime_error {
  DirectoryInUse(const std::string& message, RunLockHolder by, std::string file)
      : std::runtime_error(message), holder(std::move(by)), lock_path(std::move(file)) {}
  RunLockHolder holder;
  std::string lock_path;
};

// "coupler pid N on HOST, started T" (as `hfmpm status` names a running coupler).
std::string describe(const RunLockHolder& holder);

class RunLock {
 public:
  // Creates DIR if needed and takes DIR/.lock, writing this process's pid,
  // host and start time into it. Throws DirectoryInUse (nothing in DIR
  // written) if a live process holds it, std::runtime_error if DIR or the
  // lock cannot be made or the file system has no flock.
  explicit RunLock(const std::string& dir);
  ~RunLock();  // releases the lock; the file stays
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace hfmpm::coupling
