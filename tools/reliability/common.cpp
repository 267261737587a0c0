#include "common.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <iostream>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "test_support.hpp"

namespace hfmpm::reliability {

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void sleep_s(double seconds) { std::this_thread::sleep_for(std::chrono::duration<double>(seconds)); }

Rng::Rng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream), static_cast<std::uint32_t>(index),
                    static_cast<std::uint32_t>(index >> 32)};
  engine_.seed(seq);
}

std::uint64_t Rng::between(std::uint64_t lo, std::uint64_t hi) {
  return std::uniform_int_distribution<std::uint64_t>(lo, hi)(engine_);
}

double Rng::uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(engine_); }

std::string Rng::bytes(std::size_t n) {
  std::string out(n, '\0');
  for (auto& c : out) c = static_cast<char>(engine_() & 0xff);
  return out;
}

Child::Child(const std::vector<std::string>& argv, const std::string& out_path, const std::string& err_path,
             std::uint64_t address_space_bytes)
    : out_path_(out_path), err_path_(err_path) {
  std::vector<std::string> storage(argv);
  std::vector<char*> args;
  for (auto& a : storage) args.push_back(a.data());
  args.push_back(nullptr);
  const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out < 0 || err < 0) throw std::runtime_error("cannot create " + out_path + " or " + err_path);
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid_ == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(126);
    if (address_space_bytes > 0) {
      const rlimit limit{address_space_bytes, address_space_bytes};
      setrlimit(RLIMIT_AS, &limit);
    }
    dup2(out, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    const int devnull = open("/dev/null", O_RDONLY);
    dup2(devnull, STDIN_FILENO);
    execv(args[0], args.data());
    const std::string why = std::string("execv ") + args[0] + ": " + std::strerror(errno) + "\n";
    (void)!write(STDERR_FILENO, why.data(), why.size());
    _exit(127);
  }
  close(out);
  close(err);
}

Child::~Child() {
  if (!done_ && pid_ > 0) kill_now();
}

bool Child::running() {
  if (done_) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    done_ = true;
    ended_at_ = Clock::now();
    if (WIFEXITED(status)) exit_code_ = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) signal_ = WTERMSIG(status);
    return false;
  }
  return true;
}

bool Child::wait(double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (running()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  return true;
}

void Child::kill_now() {
  if (done_) return;
  ::kill(pid_, SIGKILL);
  int status = 0;
  waitpid(pid_, &status, 0);
  done_ = true;
  ended_at_ = Clock::now();
  signal_ = SIGKILL;
}

std::string Child::err() const { return test::read_file(err_path_); }
std::string Child::out() const { return test::read_file(out_path_); }

std::string Child::how_it_ended() const {
  if (!done_) return "running";
  if (signal_ != 0) {
    const char* abbrev = sigabbrev_np(signal_);
    return "signal " + std::to_string(signal_) + " (SIG" + (abbrev ? abbrev : "?") + ")";
  }
  return "exit " + std::to_string(exit_code_);
}

std::string make_dir(const std::string& parent, const std::string& prefix) {
  std::string pattern = parent + "/" + prefix + "-XXXXXX";
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp " + pattern + ": " + std::strerror(errno));
  return pattern;
}

bool hfmpm_process_alive(pid_t pid) {
  if (pid <= 0 || !test::pid_alive(pid)) return false;
  const std::string text = test::read_file("/proc/" + std::to_string(pid) + "/cmdline");
  return text.find("hfmpm") != std::string::npos;
}

bool history_readable(const std::string& path, std::size_t& rows, std::string& why) {
  rows = 0;
  try {
    const auto csv = test::read_csv(path);
    rows = csv.rows.size();
    if (csv.header.empty() || csv.header[0] != "time_s") {
      why = "no header";
      return false;
    }
    if (rows == 0) {
      why = "header but no row";
      return false;
    }
    return true;
  } catch (const std::exception& e) {
    why = e.what();
    return false;
  }
}

bool manifest_readable(const std::string& path, std::string& status, std::string& why) {
  if (!std::ifstream(path)) {
    why = "missing";
    return false;
  }
  const std::string text = test::read_file(path);
  const auto first = text.find_first_not_of(" \n\t");
  const auto last = text.find_last_not_of(" \n\t");
  if (first == std::string::npos || text[first] != '{' || text[last] != '}') {
    why = "not one JSON object";
    return false;
  }
  status = test::json_string(text, "status");
  if (status.empty()) {
    why = "no status";
    return false;
  }
  return true;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string fixed(double value, int decimals) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

int conclude(bool ok, const std::string& root, const CommonOptions& options) {
  std::cout << (ok ? "OK" : "PROBLEMS FOUND") << "\n";
  std::error_code ec;
  if (ok && !options.keep) {
    std::filesystem::remove_all(root, ec);
  } else {
    std::cout << "outputs kept in " << root << "\n";
  }
  return ok ? 0 : 1;
}

}  // namespace hfmpm::reliability
