// `hfmpm-reliability flood --connections N [--fd-limit L]`: can the real
// sides join a coupler while a stranger holds N raw tcp connections to its
// port? (docs/reliability.md, "A cap on connections".)
//
// `hfmpm coupler` (CURVE, keys from `hfmpm keygen`, the default on tcp) runs
// the stand-in scene under an open-file limit of L (`ulimit -n L`; 0: this
// tool's own). This tool opens N tcp connections to its port that never send
// a byte, and holds N: a connection the coupler closes (its handshake limit,
// or the connection cap) is opened again at once. While the flood is held,
// the real sides start; the run must complete, with the same history as the
// run without the flood. Reported: the join time (sides started until
// coupler.log says both joined) with and without the flood, the coupler's CPU
// share while the flood was held before the sides started, how many
// connections the coupler closed.
//
// With --teardowns K (and usually --insecure-tcp --old-zmtp): K couplers
// that no side joins end by their join timeout while the flood goes on; each
// must exit with its message (libzmq 4.3.4 aborted in such a teardown,
// docs/reliability.md, "The libzmq abort").
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "common.hpp"
#include "coupled_support.hpp"

namespace hfmpm::reliability {
namespace {

namespace fs = std::filesystem;

// ZMTP 1.0 (no greeting): the first frame, length 6 (flags and 5 bytes), is the routing id.
const std::string kOldZmtpRoutingId("\x06\x00old10", 7);

std::string program(const FloodOptions& flood, const std::string& name) {
  return flood.bin_dir.empty() ? test::bin(name) : flood.bin_dir + "/" + name;
}

// A non-blocking tcp connection to 127.0.0.1:port (the connect may still be
// in progress), or -1.
int open_connection(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 && errno != EINPROGRESS) {
    close(fd);
    return -1;
  }
  return fd;
}

// N held connections: any that the other end closes (or that fails) is
// replaced by a new one.
class Flood {
 public:
  // old_zmtp: each connection sends a ZMTP 1.0 routing id, split over two
  // rounds, and an eighth of them is closed and opened again every round (churn).
  // Opened at most kPerRound at a time, so that the listener's backlog (100)
  // does not overflow and delay connections by the kernel's SYN retries.
  Flood(int port, std::size_t n, bool old_zmtp)
      : port_(port), old_zmtp_(old_zmtp), fds_(n, -1), rest_pending_(n, false) {}
  ~Flood() {
    for (int fd : fds_) {
      if (fd >= 0) close(fd);
    }
  }
  Flood(const Flood&) = delete;
  Flood& operator=(const Flood&) = delete;

  // Polls for `seconds`, reopening closed connections.
  void hold(double seconds) {
    const auto start = Clock::now();
    std::vector<pollfd> items(fds_.size());
    do {
      if (old_zmtp_) {
        for (std::size_t k = 0; k < fds_.size() / 8 + 1; ++k, next_ = (next_ + 1) % fds_.size()) {
          if (fds_[next_] >= 0) close(fds_[next_]);
          fds_[next_] = -1;
        }
      }
      if (old_zmtp_) {
        // The rest of the routing id frames begun last round.
        for (std::size_t i = 0; i < fds_.size(); ++i) {
          if (fds_[i] < 0 || !rest_pending_[i]) continue;
          rest_pending_[i] = false;
          (void)::send(fds_[i], kOldZmtpRoutingId.data() + 2, kOldZmtpRoutingId.size() - 2,
                       MSG_NOSIGNAL | MSG_DONTWAIT);
        }
      }
      constexpr std::size_t kPerRound = 50;
      std::size_t opened = 0;
      for (std::size_t i = 0; i < fds_.size(); ++i) {
        if (fds_[i] < 0 && opened < kPerRound) {
          fds_[i] = connect_one();
          rest_pending_[i] = old_zmtp_ && fds_[i] >= 0;
          ++opened;
        }
        items[i] = {fds_[i], POLLIN, 0};
      }
      if (poll(items.data(), items.size(), 10) > 0) {
        for (std::size_t i = 0; i < items.size(); ++i) {
          if (items[i].fd < 0 || (items[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
          char bytes[512];  // a ZeroMQ greeting, or the close
          const ssize_t n = recv(items[i].fd, bytes, sizeof(bytes), MSG_DONTWAIT);
          if (n > 0) continue;  // a ZeroMQ greeting: keep holding, never answer
          close(fds_[i]);
          fds_[i] = -1;
          ++closed_;
        }
      }
    } while (seconds_since(start) < seconds);
  }
  std::size_t held() const {
    std::size_t n = 0;
    for (int fd : fds_) n += fd >= 0 ? 1 : 0;
    return n;
  }
  std::uint64_t closed() const { return closed_; }

 private:
  int connect_one() {
    const int fd = open_connection(port_);
    if (fd >= 0 && old_zmtp_) {
      // Wait briefly for the connection, then send the routing id frame's
      // length and flags; the rest follows next round (a frame split across
      // tcp segments, as a slow peer's is).
      pollfd item{fd, POLLOUT, 0};
      if (poll(&item, 1, 20) > 0) (void)::send(fd, kOldZmtpRoutingId.data(), 2, MSG_NOSIGNAL | MSG_DONTWAIT);
    }
    return fd;
  }

  int port_;
  bool old_zmtp_;
  std::size_t next_ = 0;
  std::vector<int> fds_;
  std::vector<bool> rest_pending_;  // old_zmtp: the rest of the routing id is still to be sent
  std::uint64_t closed_ = 0;
};

// utime + stime of a process, in seconds (/proc/PID/stat), or -1.
double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::ostringstream read;
  read << in.rdbuf();
  const std::string text = read.str();
  const auto paren = text.rfind(')');
  if (paren == std::string::npos) return -1;
  std::istringstream fields(text.substr(paren + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; fields >> field; ++i) {  // field 3 is the state
    if (i == 14) utime = std::stod(field);
    if (i == 15) {
      stime = std::stod(field);
      break;
    }
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

struct Trial {
  bool completed = false, same_history = false, joined = false;
  double join_s = -1, run_s = -1, coupler_cpu_share = -1;
  std::uint64_t closed = 0;
  std::size_t held = 0;
  std::string how, err, dir;
};

// One run of `hfmpm coupler` and the two stand-in sides, with `connections`
// held connections (0: none) from before the sides start to the run's end.
std::unique_ptr<Child> start_coupler(const FloodOptions& flood, const std::string& dir, const std::string& scene,
                                     const test::KeyFiles& keys, double join_timeout_s) {
  const std::string limit = flood.fd_limit > 0 ? "ulimit -n " + std::to_string(flood.fd_limit) + " && " : "";
  std::vector<std::string> argv{"/bin/sh",
                                "-c",
                                limit + "exec \"$0\" \"$@\"",
                                program(flood, "hfmpm"),
                                "coupler",
                                scene,
                                "--bind",
                                "tcp://127.0.0.1:*",
                                "--out",
                                dir,
                                "--quiet",
                                "--set",
                                "coupling.join_timeout_s=" + fixed(join_timeout_s, 1)};
  if (flood.insecure_tcp) {
    argv.push_back("--insecure-tcp");
  } else {
    argv.insert(argv.end(), {"--keys", keys.coupler});
  }
  return std::make_unique<Child>(argv, dir + "/coupler.stdout", dir + "/coupler.stderr");
}

Trial trial(const FloodOptions& flood, const std::string& root, const std::string& name, const std::string& scene,
            const test::KeyFiles& keys, std::size_t connections, double hold_before_s) {
  Trial result;
  const std::string dir = make_dir(root, name);
  result.dir = dir;
  auto coupler_child = start_coupler(flood, dir, scene, keys, 60);
  Child& coupler = *coupler_child;
  const std::string endpoint = test::wait_for_endpoint(dir + "/run.json", 20);
  if (endpoint.empty()) {
    result.how = "the coupler did not start: " + coupler.err();
    return result;
  }
  const int port = std::stoi(endpoint.substr(endpoint.rfind(':') + 1));
  auto holder = connections > 0 ? std::make_unique<Flood>(port, connections, flood.old_zmtp) : nullptr;
  if (holder) {
    holder->hold(0.5);  // the connections are open
    const double cpu0 = cpu_seconds(coupler.pid());
    holder->hold(hold_before_s);
    result.coupler_cpu_share = (cpu_seconds(coupler.pid()) - cpu0) / hold_before_s;
  }
  const auto sides_started = Clock::now();
  std::vector<std::string> solid_argv{program(flood, "hfmpm-prescribed-solid"),
                                      "--connect",
                                      endpoint,
                                      "--out",
                                      dir,
                                      "--advertise-host",
                                      "127.0.0.1",
                                      "--welcome-timeout",
                                      "60"};
  std::vector<std::string> fluid_argv{
      program(flood, "hfmpm-prescribed-fluid"), "--connect", endpoint, "--out", dir, "--welcome-timeout", "60"};
  if (!flood.insecure_tcp) {
    for (auto* argv : {&solid_argv, &fluid_argv}) argv->insert(argv->end(), {"--keys", keys.side});
  }
  Child solid(solid_argv, dir + "/solid.stdout", dir + "/solid.stderr");
  Child fluid(fluid_argv, dir + "/fluid.stdout", dir + "/fluid.stderr");
  constexpr double kDeadlineS = 90;
  while (coupler.running() && seconds_since(sides_started) < kDeadlineS) {
    if (holder)
      holder->hold(0.005);
    else
      sleep_s(0.005);
    // Joined: both Hellos taken (coupler.log stays open; run.json is written
    // anew each time, which a coupler out of descriptors cannot do).
    const std::string log = result.joined ? std::string() : test::read_file(dir + "/coupler.log");
    if (!result.joined && log.find("solid side joined") != std::string::npos &&
        log.find("fluid side joined") != std::string::npos) {
      result.joined = true;
      result.join_s = seconds_since(sides_started);
    }
  }
  if (holder) {
    result.held = holder->held();
    result.closed = holder->closed();
  }
  if (coupler.running()) {
    result.how = "HANG: the coupler still runs after " + fixed(kDeadlineS, 0) + " s";
    coupler.kill_now();
  } else {
    result.how = coupler.how_it_ended();
    result.run_s = seconds_since(sides_started);
    result.completed = coupler.exited() && coupler.exit_code() == 0;
  }
  result.err = coupler.err();
  for (auto* side : {&solid, &fluid}) {
    if (!side->wait(10)) side->kill_now();
  }
  return result;
}

bool same_rows(const test::Csv& a, const test::Csv& b) {
  if (a.header != b.header || a.rows.size() != b.rows.size()) return false;
  const std::size_t wall = a.column("wall_s");
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    for (std::size_t c = 0; c < a.header.size(); ++c) {
      if (c != wall && a.rows[i][c] != b.rows[i][c]) return false;
    }
  }
  return true;
}

// `teardowns` couplers that no side joins (join timeout 0.5 s) while the
// flood goes on: each must exit 1 with its message, never die by a signal.
int teardown_trials(const FloodOptions& flood, std::uint64_t connections, const std::string& root,
                    const std::string& scene, const test::KeyFiles& keys, const CommonOptions& options) {
  int crashes = 0, clean = 0, other = 0;
  std::map<std::string, int> endings;
  for (int i = 0; i < flood.teardowns; ++i) {
    const std::string dir = make_dir(root, "teardown-" + std::to_string(i));
    auto coupler = start_coupler(flood, dir, scene, keys, 0.5);
    const std::string endpoint = test::wait_for_endpoint(dir + "/run.json", 20);
    if (endpoint.empty()) {
      ++other;
      continue;
    }
    Flood holder(std::stoi(endpoint.substr(endpoint.rfind(':') + 1)), connections, flood.old_zmtp);
    const auto start = Clock::now();
    while (coupler->running() && seconds_since(start) < 30) holder.hold(0.005);
    if (coupler->running()) coupler->kill_now();
    const std::string how = coupler->how_it_ended();
    ++endings[how];
    if (coupler->term_signal() != 0) {
      ++crashes;
      std::cout << "teardown " << i << ": CRASH: " << how << ": " << coupler->err().substr(0, 300) << "\n";
    } else if (coupler->exit_code() == 1 && coupler->err().find("join_timeout_s") != std::string::npos) {
      ++clean;
      if (!options.keep) fs::remove_all(dir);
    } else {
      ++other;
      std::cout << "teardown " << i << ": " << how << ": " << coupler->err().substr(0, 300) << "\n";
    }
  }
  std::cout << "teardowns under the flood: " << flood.teardowns << "; exit 1 with the join-timeout message: " << clean
            << ", crashes (a signal): " << crashes << ", other: " << other << " (";
  bool first = true;
  for (const auto& [how, n] : endings) {
    std::cout << (first ? "" : ", ") << how << " x" << n;
    first = false;
  }
  std::cout << ")\n";
  return conclude(crashes == 0 && other == 0, root, options);
}

}  // namespace

int flood_command(std::uint64_t connections, const FloodOptions& flood, const CommonOptions& options) {
  const std::string root = make_dir("/tmp", "hfmpm-reliability-flood");
  std::cout << "hfmpm-reliability flood: " << connections << " held tcp connections"
            << (flood.old_zmtp ? " (ZMTP 1.0 routing ids, churned)" : "")
            << (flood.teardowns > 0 ? ", " + std::to_string(flood.teardowns) + " couplers that no side joins"
                                    : std::string(" during a join"))
            << ", " << (flood.insecure_tcp ? "plain tcp" : "CURVE") << ", coupler's "
            << (flood.fd_limit > 0 ? "open-file limit " + std::to_string(flood.fd_limit)
                                   : std::string("own open-file limit"))
            << (flood.bin_dir.empty() ? "" : ", programs from " + flood.bin_dir) << ", output under " << root << "\n";
  const std::string scene = root + "/prescribed.scene";
  test::write_file(scene, test::prescribed_scene(0.1, 0.02));
  test::KeyFiles keys;
  try {
    keys = test::make_keys(root);
  } catch (const std::exception& e) {
    std::cout << e.what() << "\n";
    return 1;
  }
  if (flood.teardowns > 0) return teardown_trials(flood, connections, root, scene, keys, options);
  const Trial quiet = trial(flood, root, "without-flood", scene, keys, 0, 0);
  if (!quiet.completed) {
    std::cout << "the run without the flood did not complete (" << quiet.how << "): " << quiet.err << "\n";
    return conclude(false, root, options);
  }
  const Trial flooded = trial(flood, root, "with-flood", scene, keys, connections, 2.0);
  bool same = false;
  if (flooded.completed) {
    try {
      same = same_rows(test::read_csv(quiet.dir + "/history.csv"), test::read_csv(flooded.dir + "/history.csv"));
    } catch (const std::exception&) {
      same = false;
    }
  }
  std::cout << "without the flood: completed, join " << fixed(quiet.join_s, 3) << " s, run " << fixed(quiet.run_s, 2)
            << " s after the sides started\n"
            << "with " << connections << " held connections: " << (flooded.completed ? "completed" : "NOT COMPLETED")
            << " (" << flooded.how << ")"
            << (flooded.completed ? (same ? ", same history" : ", HISTORY DIFFERS") : std::string()) << ", join "
            << (flooded.joined ? fixed(flooded.join_s, 3) + " s" : std::string("never")) << ", run "
            << fixed(flooded.run_s, 2) << " s after the sides started\n"
            << "  coupler CPU while the flood was held (2 s before the sides started): "
            << fixed(100 * flooded.coupler_cpu_share, 0) << "% of a core\n"
            << "  connections the coupler closed (reopened by this tool): " << flooded.closed
            << "; held at the end: " << flooded.held << "\n";
  if (!flooded.completed) {
    std::cout << "  coupler's stderr: " << flooded.err.substr(0, 600) << "\n";
  }
  if (options.verbose) std::cout << "  coupler log: " << flooded.dir << "/coupler.log\n";
  const bool slow = flood.max_join_s > 0 && (!flooded.joined || flooded.join_s > flood.max_join_s);
  if (slow) std::cout << "  the join took longer than --max-join " << fixed(flood.max_join_s, 1) << " s\n";
  return conclude(flooded.completed && same && !slow, root, options);
}

}  // namespace hfmpm::reliability
