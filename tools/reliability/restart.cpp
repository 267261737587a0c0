// `hfmpm-reliability restart --trials N [--seed S]`: kill -9 a run with
// checkpoints at a random moment, continue it with `hfmpm run --restart DIR`
// and compare everything it leaves with one uninterrupted run: history.csv
// (every column but the wall clock, as text), the exchange logs after the
// checkpoint (17 digits) and every dataset of solid.h5 and fluid.h5 (bytes).
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "common.hpp"
#include "coupled_support.hpp"

namespace hfmpm::reliability {
namespace {

namespace fs = std::filesystem;

constexpr double kDeadlineS = 60;

// The 5-s scene's derived method for its density scaling, damping and film
// (a run cut to 0.4 s would derive a slower one for its own end time).
std::vector<std::string> scene_args() {
  return test::with_kgd_viscosity_ci_method({test::source("scenarios/kgd-viscosity-ci.scene"), "--set",
                                             "time.end_s=0.4", "--set", "output.interval_s=0.05", "--set",
                                             "output.checkpoint_interval_s=0.1", "--set", "output.exchange_log=true"});
}

// history.csv without the wall-clock column, as text.
std::vector<std::string> history_text(const std::string& out) {
  std::ifstream in(out + "/history.csv");
  std::vector<std::string> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::stringstream fields(line);
    std::string field, row;
    for (int column = 0; std::getline(fields, field, ','); ++column) {
      if (column != 8) row += field + ",";  // wall_s
    }
    rows.push_back(row);
  }
  return rows;
}

std::size_t history_rows(const std::string& out) { return history_text(out).size(); }

std::vector<std::string> exchange_after(const std::string& path, std::uint64_t step) {
  std::ifstream in(path);
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    if (std::stoull(line.substr(0, line.find(','))) > step) rows.push_back(line);
  }
  return rows;
}

struct Outcome {
  bool killed = false;
  bool checkpoint = false;  // a complete checkpoint existed: the restart must continue
  bool refused_ok = false;  // none existed: the restart must be refused, naming that
  bool restarted = false, equal = false;
  std::uint64_t restart_step = 0;
  double restart_s = 0;
  std::string notes;
};

Outcome run_trial(const std::string& transport, const std::string& victim, double delay_s, const std::string& out,
                  const std::string& reference) {
  Outcome o;
  std::vector<std::string> argv{test::bin("hfmpm"), "run"};
  const auto scene = scene_args();
  argv.insert(argv.end(), scene.begin(), scene.end());
  argv.insert(argv.end(), {"--out", out, "--quiet", "--transport", transport});
  {
    Child run(argv, out + ".stdout", out + ".stderr");
    const auto started = Clock::now();
    while (run.running() && history_rows(out) < 2 && seconds_since(started) < 120) sleep_s(0.002);
    const auto first_row = Clock::now();
    while (run.running() && seconds_since(first_row) < delay_s) sleep_s(0.001);
    const std::string manifest = test::read_file(out + "/run.json");
    pid_t pid = run.pid();
    if (victim != "coupler") pid = static_cast<pid_t>(test::json_number(manifest, victim + "_pid"));
    if (!run.running() || pid <= 0) {
      o.notes = "the run ended before the kill (" + run.how_it_ended() + ")";
      return o;
    }
    ::kill(pid, SIGKILL);
    o.killed = true;
    if (!run.wait(kDeadlineS)) {
      o.notes = "the run did not end after the kill; ";
      run.kill_now();
    }
    const std::string endpoint = test::json_string(manifest, "control_endpoint");
    if (endpoint.rfind("ipc://", 0) == 0) {
      std::error_code ec;
      fs::remove_all(fs::path(endpoint.substr(6)).parent_path(), ec);  // a SIGKILLed coupler leaves it
    }
  }
  sleep_s(0.3);  // the sides die with the coupler (parent-death signal)
  bool any = false;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out + "/checkpoints", ec)) {
    any = any || fs::exists(entry.path() / "coupler.pb");
  }
  o.checkpoint = any;
  const auto start = Clock::now();
  const auto restart = test::run({test::bin("hfmpm"), "run", "--restart", out, "--quiet"}, 180);
  o.restart_s = seconds_since(start);
  if (!any) {
    o.refused_ok = restart.exit_code == 2 && restart.err.find("no complete checkpoint") != std::string::npos;
    if (!o.refused_ok) o.notes += "restart without a checkpoint: exit " + std::to_string(restart.exit_code) + "; ";
    return o;
  }
  o.restarted = restart.exit_code == 0;
  if (!o.restarted) {
    o.notes += "restart failed: exit " + std::to_string(restart.exit_code) + ": " + restart.err.substr(0, 400) + "; ";
    return o;
  }
  o.restart_step = static_cast<std::uint64_t>(test::json_number(test::read_file(out + "/run.json"), "restart_step"));
  bool equal = history_text(out) == history_text(reference);
  if (!equal) o.notes += "history.csv differs; ";
  for (const std::string role : {"solid", "fluid"}) {
    if (exchange_after(out + "/" + role + "_received.csv", o.restart_step) !=
        exchange_after(reference + "/" + role + "_received.csv", o.restart_step)) {
      equal = false;
      o.notes += role + "_received.csv differs after the checkpoint; ";
    }
    std::map<std::string, std::uint64_t> a, b;
    std::string why;
    if (!h5_digests(reference + "/" + role + ".h5", a, why) || !h5_digests(out + "/" + role + ".h5", b, why) ||
        a != b || a.empty()) {
      equal = false;
      o.notes += role + ".h5 differs " + why + "; ";
    }
    if (test::read_file(reference + "/" + role + ".xmf") != test::read_file(out + "/" + role + ".xmf")) {
      equal = false;
      o.notes += role + ".xmf differs; ";
    }
  }
  o.equal = equal;
  return o;
}

}  // namespace

int restart_command(int trials, const CommonOptions& options) {
  const std::string root = make_dir("/tmp", "hfmpm-reliability-restart");
  std::cout << "hfmpm-reliability restart: " << trials << " trials, seed " << options.seed << ", output under " << root
            << "\n";
  const std::string reference = root + "/reference";
  std::vector<std::string> argv{test::bin("hfmpm"), "run"};
  const auto scene = scene_args();
  argv.insert(argv.end(), scene.begin(), scene.end());
  argv.insert(argv.end(), {"--out", reference, "--quiet"});
  const auto start = Clock::now();
  const auto whole = test::run(argv, 180);
  const double whole_s = seconds_since(start);
  if (whole.exit_code != 0) {
    std::cout << "the uninterrupted run failed: " << whole.err << "\n";
    return conclude(false, root, options);
  }
  std::cout << "uninterrupted run (ipc): " << fixed(whole_s, 2) << " s\n";
  int killed = 0, with_checkpoint = 0, equal = 0, refused_ok = 0, not_killed = 0, failed = 0;
  std::vector<double> restart_times;
  static const std::vector<std::string> transports{"ipc", "tcp", "inproc"};
  for (int i = 0; i < trials; ++i) {
    Rng rng(options.seed, 4, static_cast<std::uint64_t>(i));
    const std::string& transport = transports[static_cast<std::size_t>(i) % transports.size()];
    const std::string victim =
        transport == "inproc" ? "coupler" : rng.pick(std::vector<std::string>{"coupler", "coupler", "solid", "fluid"});
    const double delay = rng.uniform(0.0, 0.9 * whole_s);
    const std::string out = root + "/trial-" + std::to_string(i);
    const Outcome o = run_trial(transport, victim, delay, out, reference);
    std::cout << "trial " << i << ": " << transport << ", SIGKILL " << victim << " " << fixed(delay, 3)
              << " s after the first row: ";
    if (!o.killed) {
      ++not_killed;
      std::cout << "not killed: " << o.notes << "\n";
      continue;
    }
    ++killed;
    if (o.checkpoint) {
      ++with_checkpoint;
      equal += o.equal;
      failed += !o.equal;
      if (o.restarted) restart_times.push_back(o.restart_s);
      std::cout << "restarted from step " << o.restart_step << " in " << fixed(o.restart_s, 2)
                << " s: " << (o.equal ? "equal to the uninterrupted run" : "DIFFERENT");
    } else {
      refused_ok += o.refused_ok;
      failed += !o.refused_ok;
      std::cout << "no complete checkpoint yet: restart " << (o.refused_ok ? "refused, naming it" : "WRONG");
    }
    if (!o.notes.empty()) std::cout << " [" << o.notes << "]";
    std::cout << "\n";
  }
  std::cout << "\nsummary (restart --trials " << trials << " --seed " << options.seed << ")\n"
            << "  runs killed: " << killed
            << (not_killed ? " (" + std::to_string(not_killed) + " ended before their kill moment)" : "") << "\n"
            << "  restarted from a checkpoint: " << with_checkpoint << "; equal to the uninterrupted run bit for bit "
            << "(history.csv but wall_s, exchange logs after the checkpoint, every .h5 dataset, the .xmf): " << equal
            << " of " << with_checkpoint << "\n"
            << "  killed before the first checkpoint, restart refused naming it: " << refused_ok << " of "
            << killed - with_checkpoint << "\n"
            << "  restart wall time: median " << fixed(median(restart_times), 2)
            << " s (the uninterrupted run: " << fixed(whole_s, 2) << " s)\n";
  return conclude(failed == 0 && killed > 0, root, options);
}

}  // namespace hfmpm::reliability
