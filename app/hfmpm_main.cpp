// hfmpm: run a scene (coupler + sides), run a coupler that waits for sides
// started by hand, or validate a scene. Thin: parse, load, run, report.
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/run_cost.hpp"
#include "hfmpm/coupling/run_state.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/coupling/stop_signals.hpp"
#include "hfmpm/output/checkpoint_file.hpp"
#include "hfmpm/runtime/curve.hpp"
#include "hfmpm/solid/mpm/solver.hpp"
#include "mpm_fluid_side.hpp"
#include "mpm_solid_side.hpp"
#include "prescribed_fluid_side.hpp"
#include "prescribed_solid_side.hpp"
#include "scene_builder.hpp"
#include "solid_scene_rules.hpp"

namespace {

using namespace hfmpm;

constexpr const char* kUsage = R"(usage:
  hfmpm run SCENE [--out DIR] [--set KEY=VALUE]... [--transport ipc|tcp|inproc] [--quiet]
      Start the coupler and both sides, run SCENE to its end time, write DIR/history.csv.
  hfmpm run --restart DIR [SCENE [--set KEY=VALUE]...] [--transport ...] [--quiet]
      Continue the run in DIR from its last complete checkpoint (the scene needs
      output.checkpoint_interval_s > 0), also after kill -9. Without SCENE the
      checkpoint's own scene is used; a SCENE (with its --set) must be the same scene.
  hfmpm coupler SCENE --bind ENDPOINT [--keys FILE] [--out DIR] [--set KEY=VALUE]... [--quiet]
      Run the coupler only and wait for the sides to join, e.g. from other hosts:
        hfmpm keygen keys      (once; copy keys/side.keys to the sides' hosts)
        hfmpm coupler s.scene --bind tcp://0.0.0.0:5555 --keys keys/coupler.keys
        hfmpm-solid --connect tcp://COUPLER_HOST:5555 --keys side.keys   (on the solid's host)
        hfmpm-fluid --connect tcp://COUPLER_HOST:5555 --keys side.keys   (on the fluid's host)
  hfmpm coupler --restart DIR [SCENE [--set KEY=VALUE]...] --bind ENDPOINT [--keys FILE] [--quiet]
      Continue the run in DIR from its last complete checkpoint with sides started
      by hand: start each side as before, with the same --out as in the first run
      (each side reads its own checkpoint file under it; without --out, DIR).
  hfmpm keygen DIR
      Write a CURVE key pair for the coupler and one for the sides: DIR/coupler.keys
      and DIR/side.keys (0600, DIR 0700). A coupler on tcp admits only sides that
      hold side.keys; nothing secret goes into run.json or onto a command line.
  hfmpm status DIR
      Say whether the run in DIR is running, finished, or stopped without
      finishing: a run.json left at "running" by a coupler that was killed
      (kill -9, a crash, a reboot) gets the status: stopped without finishing
      (coupler killed?). 'hfmpm run --restart DIR' does the same.
  hfmpm scene PROBLEM [--out FILE]
      Build a full scene from a hydraulic-fracture problem given by its physics alone
      (rock, in-situ stress, fluid, injection, duration, notch; proto/hfmpm/problem.proto,
      e.g. scenarios/problems/*.problem). Every numerical setting is derived from the
      physics and commented with its reason; the scene goes to FILE or standard output.
  hfmpm validate SCENE [--set KEY=VALUE]... [--json]
      Check SCENE and print it with every default filled in (--json: as JSON, for
      scripts; every run also writes it to OUT/scene.json), after what the run will
      cost: particles, grid nodes, the step, the steps to end_s, an estimated wall time.

options:
  --out DIR            output directory (default: hfmpm-out/SCENE_NAME); one live run per
                       directory: a run, coupler or --restart into a directory another
                       live run holds (DIR/.lock) is refused (exit 2) before writing in it
  --set KEY=VALUE      override one scene value, e.g. --set time.end_s=2
                       --set coupling.transport=TCP; repeated fields take [a, b];
                       one element of a list by index or name (docs/scenes.md):
                       --set 'solid.mpm.cracks[0].x_m[1]=0.4'
                       --set 'solid.mpm.materials[rock].youngs_modulus_pa=2e10'
  --transport T        same as --set coupling.transport=T (ipc, tcp or inproc)
  --keys FILE          coupler on tcp: its key file (coupler.keys from hfmpm keygen)
  --insecure-tcp       plain tcp without CURVE, for sides that cannot do it: anyone
                       who can reach the port can join. 'run' makes keys itself.
  --solid-program P    run another solid implementation (speaks docs/protocol.md)
  --fluid-program P    run another fluid implementation
  --restart DIR        run, coupler: continue the run in DIR from its last complete checkpoint
  --quiet              no progress line
  --help, -h           this text (also after a command: hfmpm run --help)
exit status: 0 success, 1 run failed, 2 bad scene or command line, 3 stopped
  before its end time by the physics (a crack reached the body's edge; run.json
  "stopped" with the reason, outputs kept),
  128 + N stopped by signal N (130 SIGINT/Ctrl-C, 143 SIGTERM, 129 SIGHUP).
  The first SIGINT, SIGTERM or SIGHUP stops the run at its next control
  round: the sides shut down, outputs are flushed, run.json says
  "interrupted" with the step. A second one ends everything at once.
)";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::unique_ptr<coupling::SideModel> make_inproc_side(protocol::Role role, const scene::Scene& scene) {
  if (role == protocol::SOLID) {
    return scene.solid().has_mpm() ? solid::make_mpm_solid_side() : solid::make_prescribed_solid_side();
  }
  return scene.fluid().has_mpm() ? fluid::make_mpm_fluid_side() : fluid::make_prescribed_fluid_side();
}

int keygen(const std::vector<std::string>& args) {
  if (args.size() != 1 || args[0].empty() || args[0][0] == '-') {
    throw UsageError("'hfmpm keygen' takes one directory: hfmpm keygen DIR");
  }
  const std::filesystem::path dir = args[0];
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir)) {
    throw std::runtime_error("cannot create the directory '" + dir.string() + "': " + error.message());
  }
  std::filesystem::permissions(dir, std::filesystem::perms::owner_all, error);
  for (const char* name : {"coupler.keys", "side.keys"}) {
    if (std::filesystem::exists(dir / name)) {
      throw std::runtime_error("'" + (dir / name).string() + "' exists; keygen does not overwrite keys");
    }
  }
  const auto keys = coupling::generate_curve_keys();
  coupling::write_coupler_key_file((dir / "coupler.keys").string(), keys);
  coupling::write_side_key_file((dir / "side.keys").string(), keys);
  std::cout << "hfmpm: wrote " << (dir / "coupler.keys").string() << " (keep it with the coupler: --keys) and "
            << (dir / "side.keys").string() << " (copy it to each side's host: --keys)\n";
  return 0;
}

std::string describe(const coupling::RunState& state) {
  return "coupler pid " + std::to_string(state.pid) + " on " + state.host + ", started " + state.started_at;
}

std::string how_to_stop(const coupling::RunLockHolder& holder) {
  return holder.pid > 0 ? "Ctrl-C, or kill " + std::to_string(holder.pid) : std::string("Ctrl-C");
}

// `hfmpm status DIR`; 0 when run.json was read, 2 for a bad command line.
int status(const std::vector<std::string>& args) {
  if (args.size() != 1 || args[0].empty() || args[0][0] == '-') {
    throw UsageError("'hfmpm status' takes one run directory: hfmpm status DIR");
  }
  const std::string& dir = args[0];
  coupling::RunState state;
  try {
    state = coupling::check_run_state(dir, true);
  } catch (const std::runtime_error& e) {
    std::cerr << "hfmpm: " << dir << ": " << e.what() << "\n";
    return 2;
  }
  using Coupler = coupling::RunState::Coupler;
  switch (state.coupler) {
    case Coupler::finished:
      std::cout << dir << ": " << state.status << "\n";
      break;
    case Coupler::alive:
      std::cout << dir << ": " << state.status << " (" << describe(state) << ")\n";
      break;
    case Coupler::other_host:
      std::cout << dir << ": " << state.status << " according to run.json, but " << state.detail << "\n";
      break;
    case Coupler::gone:
      std::cout << dir << ": " << coupling::kStoppedWithoutFinishing << ": run.json said \"" << state.status
                << "\", but " << state.detail << " (" << describe(state) << "); recorded in run.json\n";
      break;
  }
  return 0;
}

// hfmpm scene PROBLEM [--out FILE]: a scene from physics alone.
int build_scene_command(const std::vector<std::string>& args) {
  std::string problem_path, out;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--out") {
      if (i + 1 >= args.size() || args[i + 1].empty()) throw UsageError("--out needs a file name");
      out = args[++i];
    } else if (!args[i].empty() && args[i][0] == '-') {
      throw UsageError("unknown option '" + args[i] + "' for 'hfmpm scene'; allowed: --out FILE");
    } else if (problem_path.empty()) {
      problem_path = args[i];
    } else {
      throw UsageError("more than one problem given ('" + problem_path + "' and '" + args[i] + "')");
    }
  }
  if (problem_path.empty()) throw UsageError("'hfmpm scene' needs a problem file");
  std::ifstream in(problem_path);
  if (!in) {
    std::cerr << "hfmpm: cannot read the problem file " << problem_path << "\n";
    return 2;
  }
  std::stringstream text;
  text << in.rdbuf();
  app::BuiltScene built;
  try {
    built = app::build_scene(app::parse_problem(text.str(), problem_path));
  } catch (const app::ProblemError& e) {
    std::cerr << "hfmpm: invalid problem:\n";
    for (const auto& line : e.problems) std::cerr << "  " << problem_path << ": " << line << "\n";
    return 2;
  }
  // The scene built must be one the coupler and both sides accept: checked
  // here with their rules, so that a builder bug cannot reach a run.
  const coupling::SceneRules rules{solid::scene_rules(), fluid::scene_rules()};
  const scene::Scene checked = coupling::parse_scene(built.text, problem_path + " (built scene)", rules);
  for (const auto& caution : built.derived.cautions) std::cerr << "hfmpm: caution: " << caution << "\n";
  if (out.empty()) {
    std::cout << built.text;
    return 0;
  }
  std::ofstream file(out);
  file << built.text;
  file.close();
  if (!file) {
    std::cerr << "hfmpm: cannot write " << out << "\n";
    return 1;
  }
  std::cout << "hfmpm: wrote " << out << " (" << checked.name() << "): Km = " << built.derived.km << ", "
            << (built.derived.viscosity_dominated ? "viscosity" : "toughness") << "-dominated, cell "
            << built.derived.cell << " m; 'hfmpm validate " << out << "' gives the cost\n";
  return 0;
}

int run(const std::string& command, const std::vector<std::string>& args) {
  std::string scene_path, out, bind, restart;
  std::vector<std::string> overrides;
  bool json = false;  // validate: print JSON
  coupling::RunOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError("option " + arg + " needs a value");
      return args[++i];
    };
    if (arg == "--out") {
      out = value();
      if (out.empty()) {
        throw UsageError("--out needs a directory; an empty one is not allowed (omit --out for hfmpm-out/SCENE_NAME)");
      }
    } else if (arg == "--set")
      overrides.push_back(value());
    else if (arg == "--restart") {
      restart = value();
      if (restart.empty()) throw UsageError("--restart needs the run directory to continue");
    } else if (arg == "--bind")
      bind = value();
    else if (arg == "--quiet")
      options.progress = false;
    else if (arg == "--json")
      json = true;
    else if (arg == "--keys")
      options.keys_file = value();
    else if (arg == "--insecure-tcp")
      options.insecure_tcp = true;
    else if (arg == "--solid-program")
      options.solid_program = value();
    else if (arg == "--fluid-program")
      options.fluid_program = value();
    else if (arg == "--transport") {
      static const std::map<std::string, std::string> names{{"ipc", "IPC"}, {"tcp", "TCP"}, {"inproc", "INPROC"}};
      const std::string t = value();
      if (!names.count(t)) throw UsageError("--transport " + t + ": allowed: ipc, tcp, inproc");
      overrides.push_back("coupling.transport=" + names.at(t));
    } else if (!arg.empty() && arg[0] == '-')
      throw UsageError("unknown option '" + arg + "'");
    else if (scene_path.empty())
      scene_path = arg;
    else
      throw UsageError("more than one scene given ('" + scene_path + "' and '" + arg + "')");
  }
  std::shared_ptr<coupling::RestartPoint> restart_point;
  // One live run per output directory, held until this process ends
  // (run_state.hpp, RunLock): taken before anything in the directory is
  // read for a restart or written.
  std::optional<coupling::RunLock> lock;
  if (!restart.empty()) {
    if (command == "validate") throw UsageError("--restart is for 'hfmpm run' and 'hfmpm coupler'");
    if (!out.empty()) throw UsageError("--restart DIR continues in DIR; --out is not allowed with it");
    if (scene_path.empty() && !overrides.empty()) {
      throw UsageError(
          "--set and --transport need the scene file: hfmpm run --restart DIR SCENE --set ... (the run's own scene "
          "and overrides; without SCENE the checkpoint's scene is used as it is)");
    }
    std::error_code exists_error;  // no directory: find_restart below says so
    if (std::filesystem::is_directory(restart, exists_error)) {
      try {
        lock.emplace(restart);
      } catch (const coupling::DirectoryInUse& e) {
        std::cerr << "hfmpm: the run in " << restart << " is still running (" << describe(e.holder) << "; it holds "
                  << e.lock_path << "); stop it first (" << how_to_stop(e.holder)
                  << "), then restart: one live run per directory\n";
        return 2;
      }
    }
    // The run being continued must not be running; a coupler that was killed
    // left run.json at "running", which is recorded as stopped now.
    try {
      const auto state = coupling::check_run_state(restart, true);
      using Coupler = coupling::RunState::Coupler;
      if (state.coupler == Coupler::alive) {
        std::cerr << "hfmpm: the run in " << restart << " is still running (" << describe(state)
                  << "); stop it first (Ctrl-C, or kill " << state.pid << "), then restart\n";
        return 2;
      }
      if (state.coupler == Coupler::other_host) {
        std::cerr << "hfmpm: warning: run.json says \"" << state.status << "\" and " << state.detail
                  << "; continuing: make sure it has stopped (two couplers must not share a directory)\n";
      }
      if (state.coupler == Coupler::gone) {
        std::cerr << "hfmpm: the run in " << restart << " " << coupling::kStoppedWithoutFinishing << ": "
                  << state.detail << "; continuing it from its last complete checkpoint\n";
        options.previous_status = coupling::kStoppedWithoutFinishing;
      } else {
        options.previous_status = state.status;
      }
    } catch (const std::runtime_error&) {
      // No readable run.json: find_restart below says what is missing.
    }
    try {
      // Each side's file is checked here too, so that a damaged one sends the restart to the
      // checkpoint before it instead of failing the side that reads it.
      restart_point = std::make_shared<coupling::RestartPoint>(
          coupling::find_restart(restart, [](const std::string& path) { output::verify_checkpoint(path); }));
    } catch (const coupling::RestartError& e) {
      std::cerr << "hfmpm: " << e.what() << "\n";
      return 2;
    }
    for (const auto& damaged : restart_point->damaged) {
      std::cerr << "hfmpm: warning: passing over the damaged checkpoint " << damaged << "\n";
    }
    if (!restart_point->damaged.empty()) {
      std::cerr << "hfmpm: continuing from the complete checkpoint before it, " << restart_point->directory << " (step "
                << restart_point->state.step() << ")\n";
    }
  }
  if (scene_path.empty() && !restart_point) throw UsageError("no scene file given");
  // The coupler's validation with each side's rules for its block: this
  // command links both sides, the coupler library neither.
  const coupling::SceneRules rules{solid::scene_rules(), fluid::scene_rules()};
  // A scene file's unset method keys are derived from its physics (docs/scenes.md,
  // "The derived method"); a checkpoint's own scene is continued with the method it ran.
  std::vector<method::Setting> derived;
  const scene::Scene scene =
      scene_path.empty() ? restart_point->state.scene() : coupling::load_scene(scene_path, rules, overrides, &derived);
  if (restart_point && scene_path.empty()) {
    // The checkpoint's own scene, checked as a scene file is: a checkpoint this
    // program wrote holds a valid one, but a damaged or foreign one must be
    // refused here, with its problems named, not by a side after the start.
    std::vector<std::string> lines;
    for (const auto& p : coupling::validate(scene, rules)) {
      lines.push_back(restart + "/" + restart_point->directory + "/coupler.pb: " + proto::problem_text(p));
    }
    if (!lines.empty()) throw coupling::SceneError(lines);
  }
  if (restart_point) {
    try {
      coupling::check_restart_scene(*restart_point, scene);
    } catch (const coupling::RestartError& e) {
      std::cerr << "hfmpm: " << e.what() << "\n";
      return 2;
    }
    out = restart;
    options.restart = restart_point;
    if (scene_path.empty()) scene_path = restart + "/" + restart_point->directory + "/coupler.pb";
  }
  if (json && command != "validate") throw UsageError("--json is for 'hfmpm validate'");
  if (command == "validate") {
    const scene::Scene filled = coupling::with_defaults(scene);
    if (json) {  // for scripts: the same, as Protobuf's JSON with the schema's field names
      std::string text;
      google::protobuf::util::JsonPrintOptions print;
      print.add_whitespace = true;
      print.preserve_proto_field_names = true;
      if (!google::protobuf::util::MessageToJsonString(filled, &text, print).ok()) {
        throw std::runtime_error("cannot print the scene as JSON");
      }
      std::cout << text;
      return 0;
    }
    std::string text;
    google::protobuf::TextFormat::PrintToString(filled, &text);
    double particles = 0;  // the MPM solid's own count (regions may overlap)
    if (filled.solid().has_mpm()) {
      const solid::mpm::Solver solver(solid::to_solid_config(filled.solid().mpm()));
      particles = static_cast<double>(solver.particles().size());
    }
    std::cout << "# " << scene_path << ": valid\n"
              << coupling::describe(coupling::estimate_run_cost(filled, rules, particles));
    if (!derived.empty()) {
      std::cout << "# The method derived from the scene's physics for the keys it leaves unset\n"
                << "# (docs/scenes.md, \"The derived method\"; set a key to choose another value):\n"
                << method::describe(derived, "#   ");
    }
    std::cout << text;
    return 0;
  }
  if (!options.keys_file.empty() && command != "coupler") {
    throw UsageError("--keys is for 'hfmpm coupler'; 'hfmpm run' makes keys for the sides it starts");
  }
  if (command == "coupler") {
    if (bind.empty()) throw UsageError("'hfmpm coupler' needs --bind ENDPOINT (e.g. tcp://0.0.0.0:5555)");
    options.launch = false;
    options.bind_endpoint = bind;
    if (!options.solid_program.empty() || !options.fluid_program.empty()) {
      throw UsageError(
          "--solid-program and --fluid-program are for 'hfmpm run'; with 'hfmpm coupler' you start "
          "the sides yourself");
    }
  } else if (!bind.empty()) {
    throw UsageError("--bind is for 'hfmpm coupler'; 'hfmpm run' chooses its own endpoints");
  }
  options.output_dir = out.empty() ? "hfmpm-out/" + (scene.name().empty() ? std::string("run") : scene.name()) : out;
  if (!lock) {
    try {
      lock.emplace(options.output_dir);
    } catch (const coupling::DirectoryInUse& e) {
      std::cerr << "hfmpm: " << e.what() << ": one live run per output directory; wait for it to end, stop it ("
                << how_to_stop(e.holder) << "), or choose another --out\n";
      return 2;
    }
  }
  options.scene_path = scene_path;
  options.overrides = overrides;
  options.inproc_factory = make_inproc_side;
  options.stop_request = &coupling::install_stop_signals();
  const auto summary = coupling::run_coupled(scene, options);
  if (summary.interrupted_by) {
    std::cerr << "hfmpm: " << summary.error << "; the sides were shut down\n"
              << "hfmpm: output written so far is in " << options.output_dir << " (run.json: \"interrupted\")\n";
    return coupling::exit_status_for_signal(summary.interrupted_by);
  }
  if (!summary.ok) {
    std::cerr << "hfmpm: run failed: " << summary.error << "\n";
    std::error_code exists_error;  // only point at a directory that is there
    if (std::filesystem::is_directory(options.output_dir, exists_error)) {
      std::cerr << "hfmpm: output written so far is in " << options.output_dir << "\n";
    } else {
      std::cerr << "hfmpm: no output: the directory " << options.output_dir << " was not created\n";
    }
    return 1;
  }
  if (!summary.warnings.empty()) {
    std::cerr << "hfmpm: the run passed through " << summary.warnings.size()
              << " state(s) its answer must be read with (run.json \"warnings\"):\n";
    for (const auto& w : summary.warnings) std::cerr << "hfmpm:   " << w.substr(0, w.find(':')) << "\n";
  }
  if (!summary.stopped.empty()) {
    std::cerr << "hfmpm: stopped at t = " << summary.t << " s: " << summary.stopped << "\n"
              << "hfmpm: output written so far is in " << options.output_dir << " (run.json: \"stopped\")\n";
    return 3;
  }
  std::cout << std::setprecision(4) << "hfmpm: done: " << summary.steps << " steps to t = " << summary.t << " s in "
            << summary.wall_s << " s wall (" << static_cast<double>(summary.steps) / summary.stepping_wall_s
            << " steps/s)\n"
            << "  compute: solid " << summary.solid_compute_s << " s, fluid " << summary.fluid_compute_s
            << " s; coupling overhead " << summary.overhead_per_step_us() << " us/step\n"
            << "  results: " << options.output_dir << "/history.csv (run manifest: " << options.output_dir
            << "/run.json)\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << kUsage;
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  for (const auto& arg : args) {
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
  }
  try {
    if (command == "keygen") return keygen(args);
    if (command == "status") return status(args);
    if (command == "scene") return build_scene_command(args);
    if (command != "run" && command != "coupler" && command != "validate") {
      throw UsageError("unknown command '" + command + "'; allowed: run, coupler, scene, status, validate, keygen");
    }
    return run(command, args);
  } catch (const UsageError& e) {
    std::cerr << "hfmpm: " << e.what() << "\n" << kUsage;
    return 2;
  } catch (const coupling::SceneError& e) {
    std::cerr << "hfmpm: invalid scene:\n" << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hfmpm: " << e.what() << "\n";
    return 1;
  }
}
