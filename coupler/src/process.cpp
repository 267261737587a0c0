#include "hfmpm/coupling/process.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace hfmpm::coupling {

ChildProcess::ChildProcess(const std::string& program, const std::vector<std::string>& args,
                           const std::string& log_path, bool append) {
  if (access(program.c_str(), X_OK) != 0) {
    throw std::runtime_error("cannot run '" + program + "': " + std::strerror(errno));
  }
  // Everything the child needs is prepared before fork: between fork and exec
  // only async-signal-safe calls are allowed.
  std::vector<std::string> storage{program};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  const int log = open(log_path.c_str(), O_WRONLY | O_CREAT | (append ? O_APPEND : O_TRUNC) | O_CLOEXEC, 0644);
  if (log < 0) throw std::runtime_error("cannot write '" + log_path + "': " + std::strerror(errno));
  const pid_t parent = getpid();

  pid_ = fork();
  if (pid_ < 0) {
    close(log);
    throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  }
  if (pid_ == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the coupler died before prctl
    // The coupler takes SIGINT/SIGTERM/SIGHUP (stop_signals.hpp) and shuts
    // the sides down in order: a side runs with the signals unblocked (the
    // mask survives exec) and in its own process group, so that Ctrl-C at
    // the terminal reaches the coupler only.
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    setpgid(0, 0);
    dup2(log, STDOUT_FILENO);
    dup2(log, STDERR_FILENO);
    execv(program.c_str(), argv.data());
    _exit(127);
  }
  close(log);
}

ChildProcess::~ChildProcess() {
  if (!ended_) stop(0.0);
}

std::optional<std::string> ChildProcess::poll() {
  if (ended_) return ended_;
  int status = 0;
  const pid_t r = waitpid(pid_, &status, WNOHANG);
  if (r == pid_) {
    if (WIFEXITED(status)) {
      exit_status_ = WEXITSTATUS(status);
      ended_ = "exited with status " + std::to_string(*exit_status_);
    } else if (WIFSIGNALED(status)) {
      const int sig = WTERMSIG(status);
      const char* name = sigabbrev_np(sig);
      ended_ = "was killed by signal " + std::to_string(sig) + (name ? std::string(" (SIG") + name + ")" : "");
    } else {
      ended_ = "ended";
    }
  } else if (r < 0 && errno == ECHILD) {
    ended_ = "ended (already reaped)";
  }
  return ended_;
}

bool ChildProcess::wait_for(double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!poll()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

void ChildProcess::stop(double grace_s) {
  if (poll()) return;
  kill(pid_, SIGCONT);  // a stopped (frozen) child cannot act on SIGTERM
  kill(pid_, SIGTERM);
  if (wait_for(grace_s)) return;
  kill(pid_, SIGKILL);
  wait_for(5.0);
}

std::string executable_dir() {
  std::error_code error;
  const auto path = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string(".") : path.parent_path().string();
}

}  // namespace hfmpm::coupling
