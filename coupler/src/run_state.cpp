// Is the run in a directory still going (run_state.hpp)?
#include "hfmpm/coupling/run_state.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "coupler_session.hpp"

namespace hfmpm::coupling {
namespace {

// /proc/PID/stat after the command name: field 3 (state) onwards.
std::vector<std::string> stat_fields(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  if (!in) return {};
  std::ostringstream read;
  read << in.rdbuf();
  const std::string text = read.str();
  const auto paren = text.rfind(')');  // the command name may hold spaces and parentheses
  if (paren == std::string::npos || paren + 2 > text.size()) return {};
  std::istringstream rest(text.substr(paren + 2));
  std::vector<std::string> fields;
  for (std::string field; rest >> field;) fields.push_back(field);
  return fields;
}

// run.json as the coupler writes it (Manifest): one "key": value per line.
using Fields = std::map<std::string, std::string>;  // key -> the value's JSON text

Fields read_fields(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("no run.json in this directory ('" + path + "' cannot be read)");
  Fields fields;
  for (std::string line; std::getline(in, line);) {
    const auto open = line.find('"');
    const auto close = open == std::string::npos ? open : line.find("\": ", open + 1);
    if (close == std::string::npos) continue;
    std::string value = line.substr(close + 3);
    if (!value.empty() && value.back() == ',') value.pop_back();
    fields[line.substr(open + 1, close - open - 1)] = value;
  }
  return fields;
}

std::string unquote(const std::string& json) {
  if (json.size() < 2 || json.front() != '"') return json;
  std::string out;
  for (std::size_t i = 1; i + 1 < json.size(); ++i) {
    if (json[i] == '\\' && i + 2 < json.size()) ++i;  // \" and \\ (control characters stay escaped)
    out += json[i];
  }
  return out;
}

std::string quote(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

std::string get(const Fields& fields, const std::string& key) {
  const auto it = fields.find(key);
  return it == fields.end() ? std::string() : unquote(it->second);
}

std::string fields_text(const Fields& fields) {
  std::ostringstream out;
  out << "{\n";
  std::size_t i = 0;
  for (const auto& [key, value] : fields) {
    out << "  \"" << key << "\": " << value << (++i < fields.size() ? ",\n" : "\n");
  }
  out << "}\n";
  return out.str();
}

void write_fields(const std::string& path, const Fields& fields) {
  const std::string tmp = path + ".check";
  {
    std::ofstream out(tmp);
    out << fields_text(fields);
    if (!out.flush()) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot replace " + path);
}

// When this machine booted (seconds since the epoch), from /proc/stat's btime; 0 if unknown.
std::time_t boot_time() {
  std::ifstream in("/proc/stat");
  for (std::string key; in >> key;) {
    if (key == "btime") {
      long long seconds = 0;
      in >> seconds;
      return static_cast<std::time_t>(seconds);
    }
    in.ignore(1 << 20, '\n');
  }
  return 0;
}

}  // namespace

std::uint64_t process_start_ticks(pid_t pid) {
  const auto fields = stat_fields(pid);
  if (fields.size() < 20) return 0;
  try {
    return std::stoull(fields[19]);  // field 22 of /proc/PID/stat
  } catch (const std::exception&) {
    return 0;
  }
}

std::string boot_id() {
  std::ifstream in("/proc/sys/kernel/random/boot_id");
  std::string id;
  std::getline(in, id);
  return id;
}

RunState check_run_state(const std::string& run_dir, bool record) {
  const std::string path = run_dir + "/run.json";
  Fields fields = read_fields(path);
  RunState state;
  state.status = get(fields, "status");
  if (state.status.empty()) throw std::runtime_error("'" + path + "' has no status; is it an hfmpm run.json?");
  state.host = get(fields, "coupler_host");
  state.started_at = get(fields, "started_at");
  try {
    state.pid = std::stol(get(fields, "coupler_pid"));
  } catch (const std::exception&) {
    state.pid = 0;
  }
  if (state.status != "starting" && state.status != "running") return state;  // a final status
  if (state.host != host_name()) {
    state.coupler = RunState::Coupler::other_host;
    state.detail = "its coupler ran on " + (state.host.empty() ? std::string("an unnamed host") : state.host) +
                   ", not on this host (" + host_name() + "): cannot tell from here whether it still runs";
    return state;
  }
  const std::string pid = std::to_string(state.pid);
  const std::string recorded_boot = get(fields, "boot_id");
  const std::string recorded_ticks = get(fields, "coupler_start_ticks");
  const auto fields_now = state.pid > 0 ? stat_fields(static_cast<pid_t>(state.pid)) : std::vector<std::string>{};
  if (!recorded_boot.empty() && recorded_boot != boot_id()) {
    state.detail = "this machine has restarted since the run started";
  } else if (fields_now.size() < 20 || fields_now[0] == "Z" || fields_now[0] == "X") {
    state.detail = "its coupler (pid " + pid + ") no longer exists";
  } else if (!recorded_ticks.empty() && recorded_ticks != fields_now[19]) {
    state.detail = "pid " + pid + " is now another process (started at another time than the run's coupler)";
  } else if (recorded_ticks.empty()) {
    // A run.json without the start ticks: compare the process's start with started_at.
    std::tm tm{};
    std::istringstream in(state.started_at);
    in >> std::get_time(&tm, "%Y-%m-%dT%H:%M:%SZ");
    const std::time_t started = in.fail() ? 0 : timegm(&tm);
    const double process_started =
        static_cast<double>(boot_time()) + std::stod(fields_now[19]) / static_cast<double>(sysconf(_SC_CLK_TCK));
    if (started > 0 && process_started > static_cast<double>(started) + 2) {
      state.detail = "pid " + pid + " is now another process (started after the run's started_at)";
    }
  }
  if (state.detail.empty()) {
    state.coupler = RunState::Coupler::alive;
    return state;
  }
  state.coupler = RunState::Coupler::gone;
  if (record) {
    fields["status"] = quote(kStoppedWithoutFinishing);
    fields["status_before_check"] = quote(state.status);
    fields["stopped_found_at"] = quote(detail::utc_now());
    fields["stopped_reason"] = quote(state.detail);
    write_fields(path, fields);
  }
  return state;
}

std::string describe(const RunLockHolder& holder) {
  if (holder.pid <= 0) return "an hfmpm that is starting and has not yet written its pid";
  return "coupler pid " + std::to_string(holder.pid) + " on " + holder.host + ", started " + holder.started_at;
}

RunLock::RunLock(const std::string& dir) : path_(dir + "/" + kRunLockFile) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir)) {
    throw std::runtime_error("cannot create the output directory '" + dir + "'" +
                             (error ? ": " + error.message() : std::string(": a file of that name is in the way")));
  }
  // O_CREAT without O_TRUNC: a live holder's file is not touched before flock says it is free.
  fd_ = open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot open the run lock '" + path_ + "': " + std::strerror(errno));
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int why = errno;
    close(fd_);
    fd_ = -1;
    if (why != EWOULDBLOCK) {
      throw std::runtime_error("cannot lock '" + path_ + "' (flock: " + std::strerror(why) +
                               "); hfmpm needs a file system with flock(2) for its output directory, so that two "
                               "runs cannot write into one: choose another --out");
    }
    RunLockHolder holder;
    try {
      const Fields fields = read_fields(path_);
      holder.pid = std::stol(get(fields, "pid"));
      holder.host = get(fields, "host");
      holder.started_at = get(fields, "started_at");
    } catch (const std::exception&) {
      holder = {};  // taken a moment ago, its holder's name not yet written
    }
    throw DirectoryInUse(
        "the directory '" + dir + "' is in use by another run (" + describe(holder) + "; it holds " + path_ + ")",
        holder, path_);
  }
  Fields fields;
  fields["pid"] = std::to_string(getpid());
  fields["host"] = quote(host_name());
  fields["started_at"] = quote(detail::utc_now());
  const std::string bytes = fields_text(fields);
  // In place, under the lock (a rename would give the file a new inode, not covered by this lock).
  if (ftruncate(fd_, 0) != 0 || pwrite(fd_, bytes.data(), bytes.size(), 0) != static_cast<ssize_t>(bytes.size())) {
    const int why = errno;
    close(fd_);
    fd_ = -1;
    throw std::runtime_error("cannot write the run lock '" + path_ + "': " + std::strerror(why));
  }
}

RunLock::~RunLock() {
  if (fd_ >= 0) close(fd_);
}

}  // namespace hfmpm::coupling
