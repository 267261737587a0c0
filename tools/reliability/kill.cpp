// `hfmpm-reliability kill --trials N [--seed S]`: SIGKILL one process of a
// running `hfmpm run` at a random moment and measure what is left: how fast
// the death is noticed, whether anything hangs, orphans, and whether
// history.csv, run.json and the HDF5 files are still readable.
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "common.hpp"
#include "coupled_support.hpp"

namespace hfmpm::reliability {
namespace {

namespace fs = std::filesystem;

constexpr double kDeadlineS = 30;  // longer than this to notice a death is a hang
constexpr double kOrphanGraceS = 2;

struct Trial {
  bool kgd = false;
  std::string transport;  // ipc, tcp, inproc
  std::string victim;     // solid, fluid, coupler
  int rows = 0;           // kill once history.csv has this many rows, or
  double delay_s = 0;     // this long after its first row
};

struct Outcome {
  bool killed = false;    // false: the run ended before the moment came
  bool detected = false;  // side: `hfmpm run` exited; coupler: both sides gone (within the deadline)
  bool named = false;     // side kill: the message names the side and SIGKILL
  bool hang = false;
  double detect_s = 0;
  int orphans = 0;
  bool history_ok = false, manifest_ok = false;
  std::size_t rows = 0;
  std::string status;
  int h5_files = 0, h5_bad = 0;
  bool ipc_left = false, keys_left = false;
  std::string notes;
};

Trial draw(int index, Rng& rng) {
  Trial trial;
  trial.kgd = index % 4 == 3;  // one trial in four runs the MPM solid and fluid (HDF5 output)
  static const std::vector<std::string> transports{"ipc", "tcp", "inproc"};
  trial.transport = transports[static_cast<std::size_t>(index) % transports.size()];  // each in turn
  trial.victim =
      trial.transport == "inproc" ? "coupler" : rng.pick(std::vector<std::string>{"solid", "fluid", "coupler"});
  if (rng.chance(0.5)) {
    trial.rows = static_cast<int>(trial.kgd ? rng.between(1, 4) : rng.between(1, 80));
  } else {
    trial.delay_s = trial.kgd ? rng.uniform(0.0, 2.0) : rng.uniform(0.0, 0.6);  // the runs last longer
  }
  return trial;
}

std::size_t history_rows(const std::string& out) {
  std::ifstream in(out + "/history.csv");
  std::size_t lines = 0;
  std::string line;
  while (std::getline(in, line)) ++lines;
  return lines > 0 ? lines - 1 : 0;
}

std::string key_dir_of(pid_t side) {
  const std::string text = test::read_file("/proc/" + std::to_string(side) + "/cmdline");
  const auto at = text.find("/tmp/hfmpm-keys-");
  if (at == std::string::npos) return "";
  return fs::path(text.substr(at, text.find('\0', at) - at)).parent_path().string();
}

Outcome run_trial(const Trial& trial, const std::string& out) {
  Outcome outcome;
  std::vector<std::string> argv{test::bin("hfmpm"), "run"};
  if (trial.kgd) {
    argv.insert(argv.end(), {test::source("scenarios/kgd-viscosity-ci.scene"), "--set", "time.end_s=0.3", "--set",
                             "output.interval_s=0.05"});
  } else {
    const std::string scene = out + "/scene.scene";
    test::write_file(scene, test::prescribed_scene(1.0, 0.01));
    argv.push_back(scene);
  }
  argv.insert(argv.end(), {"--out", out, "--quiet", "--transport", trial.transport});
  Child run(argv, out + "/stdout", out + "/stderr");

  // The moment: the first row, then the number of rows or the delay.
  const auto started = Clock::now();
  while (run.running() && history_rows(out) < 1 && seconds_since(started) < 120) sleep_s(0.002);
  const auto first_row = Clock::now();
  while (run.running()) {
    if (trial.rows > 0 ? history_rows(out) >= static_cast<std::size_t>(trial.rows)
                       : seconds_since(first_row) >= trial.delay_s) {
      break;
    }
    sleep_s(0.001);
  }
  const std::string manifest_before = test::read_file(out + "/run.json");
  const auto solid = static_cast<pid_t>(test::json_number(manifest_before, "solid_pid"));
  const auto fluid = static_cast<pid_t>(test::json_number(manifest_before, "fluid_pid"));
  const std::string endpoint = test::json_string(manifest_before, "control_endpoint");
  const std::string ipc_dir =
      endpoint.rfind("ipc://", 0) == 0 ? fs::path(endpoint.substr(6)).parent_path().string() : std::string();
  const std::string key_dir = trial.transport == "tcp" && solid > 0 ? key_dir_of(solid) : std::string();

  pid_t victim = run.pid();
  if (trial.victim == "solid") victim = solid;
  if (trial.victim == "fluid") victim = fluid;
  if (!run.running() || victim <= 0) {
    outcome.notes =
        run.running() ? "no pid for the " + trial.victim : "the run ended before the kill (" + run.how_it_ended() + ")";
    run.kill_now();
    return outcome;
  }
  const auto kill_time = Clock::now();
  ::kill(victim, SIGKILL);
  outcome.killed = true;

  if (trial.victim == "coupler") {
    run.wait(5);
    while ((hfmpm_process_alive(solid) || hfmpm_process_alive(fluid)) && seconds_since(kill_time) < kDeadlineS) {
      sleep_s(0.0005);
    }
    outcome.detect_s = seconds_since(kill_time);
    outcome.detected = !hfmpm_process_alive(solid) && !hfmpm_process_alive(fluid) && !run.running();
  } else {
    outcome.detected = run.wait(kDeadlineS);
    outcome.detect_s =
        outcome.detected ? std::chrono::duration<double>(run.ended_at() - kill_time).count() : seconds_since(kill_time);
    if (outcome.detected) {
      const std::string err = run.err();
      outcome.named = run.exit_code() == 1 && err.find("the " + trial.victim + " side") != std::string::npos &&
                      err.find("SIGKILL") != std::string::npos;
      if (!outcome.named) outcome.notes += "exit " + run.how_it_ended() + ": " + err.substr(0, 300) + "; ";
    }
  }
  outcome.hang = !outcome.detected;
  if (outcome.hang) run.kill_now();

  // Orphans: a side still alive a moment after the run is over.
  const auto grace = Clock::now();
  while ((hfmpm_process_alive(solid) || hfmpm_process_alive(fluid)) && seconds_since(grace) < kOrphanGraceS) {
    sleep_s(0.005);
  }
  for (pid_t pid : {solid, fluid}) {
    if (hfmpm_process_alive(pid)) {
      ++outcome.orphans;
      outcome.notes += "orphan pid " + std::to_string(pid) + "; ";
      ::kill(pid, SIGKILL);
    }
  }

  std::string why;
  outcome.history_ok = history_readable(out + "/history.csv", outcome.rows, why);
  if (!outcome.history_ok) outcome.notes += "history.csv: " + why + "; ";
  outcome.manifest_ok = manifest_readable(out + "/run.json", outcome.status, why);
  if (!outcome.manifest_ok) outcome.notes += "run.json: " + why + "; ";
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().extension() != ".h5") continue;
    ++outcome.h5_files;
    if (!h5_readable(entry.path().string(), why)) {
      ++outcome.h5_bad;
      outcome.notes += entry.path().filename().string() + ": " + why + "; ";
    }
  }
  // What a SIGKILLed coupler cannot remove; this tool removes it.
  std::error_code ec;
  if (!ipc_dir.empty() && fs::exists(ipc_dir)) {
    outcome.ipc_left = true;
    fs::remove_all(ipc_dir, ec);
  }
  if (!key_dir.empty() && fs::exists(key_dir)) {
    outcome.keys_left = true;
    fs::remove_all(key_dir, ec);
  }
  return outcome;
}

}  // namespace

int kill_command(int trials, const CommonOptions& options) {
  const std::string root = make_dir("/tmp", "hfmpm-reliability-kill");
  std::cout << "hfmpm-reliability kill: " << trials << " trials, seed " << options.seed << ", output under " << root
            << "\n";
  int kills = 0, detected = 0, side_kills = 0, named = 0, hangs = 0, orphans = 0, not_killed = 0;
  int histories_bad = 0, manifests_bad = 0, h5_files = 0, h5_bad = 0, ipc_left = 0, keys_left = 0;
  int coupler_kills = 0;
  std::vector<double> times, side_times, coupler_times;
  for (int i = 0; i < trials; ++i) {
    Rng rng(options.seed, 1, static_cast<std::uint64_t>(i));
    const Trial trial = draw(i, rng);
    const std::string out = make_dir(root, "trial-" + std::to_string(i));
    const Outcome o = run_trial(trial, out);
    std::cout << "trial " << i << ": " << (trial.kgd ? "kgd-viscosity-ci" : "prescribed") << " " << trial.transport
              << ", SIGKILL " << trial.victim << " "
              << (trial.rows > 0 ? "at history row " + std::to_string(trial.rows)
                                 : fixed(trial.delay_s, 3) + " s after the first row")
              << ": ";
    if (!o.killed) {
      ++not_killed;
      std::cout << "not killed: " << o.notes << "\n";
      continue;
    }
    ++kills;
    if (trial.victim == "coupler") ++coupler_kills;
    if (trial.victim != "coupler") ++side_kills;
    if (o.named) ++named;
    if (o.detected) {
      ++detected;
      times.push_back(o.detect_s);
      (trial.victim == "coupler" ? coupler_times : side_times).push_back(o.detect_s);
    }
    hangs += o.hang;
    orphans += o.orphans;
    histories_bad += !o.history_ok;
    manifests_bad += !o.manifest_ok;
    h5_files += o.h5_files;
    h5_bad += o.h5_bad;
    ipc_left += o.ipc_left;
    keys_left += o.keys_left;
    std::cout << (o.detected ? "detected in " + fixed(o.detect_s, 3) + " s" : "HANG (nothing after 30 s)")
              << ", orphans " << o.orphans << ", history.csv " << (o.history_ok ? "ok" : "UNREADABLE") << " (" << o.rows
              << " rows), run.json " << (o.manifest_ok ? "status \"" + o.status + "\"" : "UNREADABLE");
    if (o.h5_files > 0) std::cout << ", .h5 " << o.h5_files - o.h5_bad << " of " << o.h5_files << " readable";
    if (o.ipc_left || o.keys_left) {
      std::cout << ", left behind:" << (o.ipc_left ? " ipc directory" : "") << (o.keys_left ? " key directory" : "");
    }
    if (!o.notes.empty()) std::cout << " [" << o.notes << "]";
    std::cout << "\n";
    if (options.verbose) std::cout << "  output: " << out << "\n";
  }
  const int unreadable = histories_bad + manifests_bad + h5_bad;
  auto largest = [](const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); };
  std::cout << "\nsummary (kill --trials " << trials << " --seed " << options.seed << ")\n"
            << "  kills detected: " << detected << " of " << kills
            << (not_killed ? " (" + std::to_string(not_killed) + " runs ended before their kill moment)" : "") << "\n"
            << "  side kills named in the run's error (the side and SIGKILL): " << named << " of " << side_kills
            << "; coupler kills: " << coupler_kills << "\n"
            << "  detection time: median " << fixed(median(times), 3) << " s, max " << fixed(largest(times), 3)
            << " s (side kills, until `hfmpm run` exits: median " << fixed(median(side_times), 3) << " s, max "
            << fixed(largest(side_times), 3) << " s; coupler kills, until both sides are gone: median "
            << fixed(median(coupler_times), 3) << " s, max " << fixed(largest(coupler_times), 3) << " s)\n"
            << "  hangs: " << hangs << "\n"
            << "  orphans: " << orphans << "\n"
            << "  unreadable outputs: " << unreadable << " (history.csv " << histories_bad << ", run.json "
            << manifests_bad << ", .h5 " << h5_bad << " of " << h5_files
            << " opened read-only and read in full with the HDF5 C API)\n"
            << "  left behind by a SIGKILLed coupler (removed by this tool): ipc directories " << ipc_left
            << ", CURVE key directories " << keys_left << "\n";
  const bool ok = detected == kills && kills > 0 && hangs == 0 && orphans == 0 && unreadable == 0;
  return conclude(ok, root, options);
}

}  // namespace hfmpm::reliability
