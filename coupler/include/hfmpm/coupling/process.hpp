// A side started by the coupler as a child process. The child dies with the
// coupler (PR_SET_PDEATHSIG), and a ChildProcess that goes out of scope kills
// and reaps what is still running: no failure leaves a process behind.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace hfmpm::coupling {

class ChildProcess {
 public:
  // Starts `program` with `args`; stdout and stderr go to `log_path`.
  // append: add to log_path (a restarted run keeps the log of the run it continues) instead of truncating it.
  ChildProcess(const std::string& program, const std::vector<std::string>& args, const std::string& log_path,
               bool append = false);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  // If the child has ended, how: "exited with status 7", "was killed by signal 9 (SIGKILL)".
  std::optional<std::string> poll();
  // Waits up to `seconds` for the child to end; true if it has.
  bool wait_for(double seconds);
  // SIGTERM, then SIGKILL after `grace_s`; reaps the child.
  void stop(double grace_s);
  const std::optional<int>& exit_status() const { return exit_status_; }

 private:
  pid_t pid_ = -1;
  std::optional<std::string> ended_;
  std::optional<int> exit_status_;  // set if it exited normally
};

// Directory of the running executable (for finding the side programs).
std::string executable_dir();

}  // namespace hfmpm::coupling
