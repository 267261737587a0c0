#include "test_support.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

namespace hfmpm::test {
namespace {

// Scratch directories are removed when the test program ends with every test
// passed (kept after a failure, or with HFMPM_KEEP_TEST_OUTPUT set, for a look).
class ScratchDirs {
 public:
  void add(const std::string& path) { paths_.push_back(path); }
  ~ScratchDirs() {
    if (std::getenv("HFMPM_KEEP_TEST_OUTPUT") != nullptr) return;
    if (!::testing::UnitTest::GetInstance()->Passed()) return;
    for (const auto& p : paths_) {
      std::error_code ec;
      std::filesystem::remove_all(p, ec);
    }
  }

 private:
  std::vector<std::string> paths_;
};

ScratchDirs& scratch_dirs() {
  static ScratchDirs dirs;
  return dirs;
}

}  // namespace

std::string bin(const std::string& program) { return std::string(HFMPM_BIN_DIR) + "/" + program; }
std::string source(const std::string& relative) { return std::string(HFMPM_SOURCE_DIR) + "/" + relative; }

std::string scratch_dir(const std::string& name) {
  std::string pattern = "/tmp/hfmpm-test-" + name + "-XXXXXX";
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  static std::mutex registry;  // tests may start processes from several threads
  const std::lock_guard<std::mutex> lock(registry);
  scratch_dirs().add(pattern);
  return pattern;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

Process::Process(const std::vector<std::string>& argv) {
  const std::string dir = scratch_dir("proc");
  out_path_ = dir + "/stdout";
  err_path_ = dir + "/stderr";
  std::vector<std::string> storage(argv);
  std::vector<char*> args;
  for (auto& a : storage) args.push_back(a.data());
  args.push_back(nullptr);
  const int out = open(out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int err = open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_ = fork();
  if (pid_ == 0) {
    dup2(out, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    const int devnull = open("/dev/null", O_RDONLY);
    dup2(devnull, STDIN_FILENO);
    execv(args[0], args.data());
    _exit(127);
  }
  close(out);
  close(err);
}

Process::~Process() {
  if (!done_ && pid_ > 0) {
    kill(pid_, SIGKILL);
    wait(5);
  }
}

bool Process::running() {
  if (done_) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    done_ = true;
    if (WIFEXITED(status)) exit_code_ = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) signal_ = WTERMSIG(status);
    return false;
  }
  return true;
}

bool Process::wait(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (running()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

std::string Process::out() const { return read_file(out_path_); }
std::string Process::err() const { return read_file(err_path_); }

RunResult run(const std::vector<std::string>& argv, double timeout_s) {
  Process process(argv);
  RunResult result;
  if (!process.wait(timeout_s)) {
    result.timed_out = true;
    kill(process.pid(), SIGKILL);
    process.wait(5);
  }
  result.exit_code = process.exit_code();
  result.signal = process.term_signal();
  result.out = process.out();
  result.err = process.err();
  return result;
}

bool pid_alive(pid_t pid) {
  if (kill(pid, 0) != 0) return false;
  // A zombie (exited, not yet reaped by its parent) counts as gone.
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const auto close = line.rfind(')');
  return close == std::string::npos || line.size() < close + 3 || line[close + 2] != 'Z';
}

std::size_t Csv::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  throw std::runtime_error("no column '" + name + "'");
}

std::vector<double> Csv::values(const std::string& name) const {
  const std::size_t c = column(name);
  std::vector<double> out;
  for (const auto& row : rows) out.push_back(row.at(c));
  return out;
}

Csv read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  Csv csv;
  std::string line;
  if (std::getline(in, line)) {
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) csv.header.push_back(field);
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::stringstream fields(line);
    std::string field;
    std::vector<double> row;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    if (row.size() != csv.header.size()) throw std::runtime_error("ragged row in " + path + ": " + line);
    csv.rows.push_back(row);
  }
  return csv;
}

double json_number(const std::string& json, const std::string& key) {
  std::smatch m;
  if (std::regex_search(json, m, std::regex("\"" + key + "\": ([-0-9.eE+]+)"))) return std::stod(m[1].str());
  return 0;
}

std::string json_string(const std::string& json, const std::string& key) {
  std::smatch m;
  if (std::regex_search(json, m, std::regex("\"" + key + "\": \"([^\"]*)\""))) return m[1].str();
  return "";
}

}  // namespace hfmpm::test
