// Helpers for tests that run the real programs: start a process with a
// timeout and captured output, read CSV files, make scratch directories.
#pragma once

#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace hfmpm::test {

std::string bin(const std::string& program);       // path of a built program
std::string source(const std::string& relative);   // path in the source tree
std::string scratch_dir(const std::string& name);  // fresh empty directory under /tmp
std::string read_file(const std::string& path);
void write_file(const std::string& path, const std::string& text);

// A program started in the background; killed (SIGKILL) if still running when destroyed.
class Process {
 public:
  explicit Process(const std::vector<std::string>& argv);
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  pid_t pid() const { return pid_; }
  // Waits up to timeout_s. Returns false on timeout (the process keeps running).
  bool wait(double timeout_s);
  bool running();
  int exit_code() const { return exit_code_; }  // -1 unless it exited normally
  int term_signal() const { return signal_; }   // 0 unless killed by a signal
  std::string out() const;
  std::string err() const;

 private:
  pid_t pid_ = -1;
  bool done_ = false;
  int exit_code_ = -1, signal_ = 0;
  std::string out_path_, err_path_;
};

struct RunResult {
  int exit_code = -1;
  int signal = 0;
  bool timed_out = false;
  std::string out, err;
};
// Runs to completion or kills it after timeout_s.
RunResult run(const std::vector<std::string>& argv, double timeout_s);

bool pid_alive(pid_t pid);

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::size_t column(const std::string& name) const;  // throws if absent
  std::vector<double> values(const std::string& name) const;
};
Csv read_csv(const std::string& path);

// A numeric field of a flat JSON object such as run.json (0 if absent).
double json_number(const std::string& json, const std::string& key);
std::string json_string(const std::string& json, const std::string& key);

}  // namespace hfmpm::test
