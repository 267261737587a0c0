// hfmpm-conformance: checks any program that claims to be a solid or a fluid
// side against the wire protocol (proto/hfmpm/protocol.proto). It plays the
// coupler and the opposite side, launches the program once per check, prints
// PASS/FAIL with a reason for each, and exits non-zero if any check fails.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "checks.hpp"

namespace hfmpm::conformance {
namespace {

namespace fs = std::filesystem;

void usage(std::ostream& out) {
  out << "usage: hfmpm-conformance --role solid|fluid --program PATH [options]\n"
         "Checks a side program against the hfmpm protocol (version 1). The program is started as\n"
         "  PATH --connect ENDPOINT --out DIR [extra arguments of a check]\n"
         "once per check; this program plays the coupler and the other side.\n\n"
         "  --role solid|fluid      what the program under test is\n"
         "  --program PATH          the program under test\n"
         "  --scene FILE            scene for Welcome (default " HFMPM_DEFAULT_SCENE
         ")\n"
         "  --set KEY=VALUE         scene override, repeatable (before each check's own)\n"
         "  --transport ipc|tcp     control and data sockets (default ipc)\n"
         "  --only NAME[,NAME...]   run only these checks\n"
         "  --list                  list the checks and exit\n"
         "  --keep                  keep the scratch directory (kept anyway if a check fails)\n"
         "  --help                  this text\n";
}

struct Arguments {
  Config config;
  std::set<std::string> only;
  bool list = false, keep = false;
};

std::set<std::string> split(const std::string& text) {
  std::set<std::string> names;
  std::stringstream in(text);
  for (std::string name; std::getline(in, name, ',');) {
    if (!name.empty()) names.insert(name);
  }
  return names;
}

// Returns nullopt after printing usage (status in `status`).
std::optional<Arguments> parse(int argc, char** argv, int& status) {
  Arguments a;
  a.config.scene_path = HFMPM_DEFAULT_SCENE;
  std::string role;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--help" || arg == "-h") {
      usage(std::cout);
      status = 0;
      return std::nullopt;
    } else if (arg == "--role") {
      role = value();
    } else if (arg == "--program") {
      a.config.program = value();
    } else if (arg == "--scene") {
      a.config.scene_path = value();
    } else if (arg == "--set") {
      a.config.overrides.push_back(value());
    } else if (arg == "--transport") {
      const std::string t = value();
      if (t != "ipc" && t != "tcp") throw std::invalid_argument("--transport '" + t + "': allowed: ipc, tcp");
      a.config.tcp = t == "tcp";
    } else if (arg == "--only") {
      a.only = split(value());
    } else if (arg == "--list") {
      a.list = true;
    } else if (arg == "--keep") {
      a.keep = true;
    } else {
      throw std::invalid_argument("unknown option '" + arg + "'; see --help");
    }
  }
  if (role == "solid") {
    a.config.role = protocol::SOLID;
  } else if (role == "fluid") {
    a.config.role = protocol::FLUID;
  } else {
    throw std::invalid_argument("--role '" + role + "': allowed: solid, fluid");
  }
  if (a.config.program.empty() && !a.list) throw std::invalid_argument("--program PATH is required");
  return a;
}

std::vector<Check> all_checks(protocol::Role role) {
  auto checks = lifecycle_checks();
  const auto schedule = schedule_checks();
  checks.insert(checks.begin() + 4, schedule.begin(), schedule.end());  // after the heartbeat checks
  checks.insert(checks.begin() + 4 + static_cast<std::ptrdiff_t>(schedule.size()),
                role == protocol::SOLID ? solid_growth_check() : fluid_growth_check());
  const auto errors = error_checks();
  checks.insert(checks.end(), errors.begin(), errors.end());
  return checks;
}

void print_log_tail(const std::string& path, std::size_t lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::cout << "        log " << path << (all.empty() ? " (empty)" : "") << "\n";
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) {
    std::cout << "        | " << all[i] << "\n";
  }
}

int run(const Arguments& arguments) {
  auto checks = all_checks(arguments.config.role);
  if (arguments.list) {
    for (const auto& c : checks) std::printf("%-26s %s\n", c.name.c_str(), c.what.c_str());
    return 0;
  }
  for (const auto& name : arguments.only) {
    if (std::none_of(checks.begin(), checks.end(), [&](const Check& c) { return c.name == name; })) {
      throw std::invalid_argument("--only: no check named '" + name + "'; see --list");
    }
  }
  Config config = arguments.config;
  config.program = fs::absolute(config.program).string();
  std::string pattern = "/tmp/hfmpm-conformance-XXXXXX";
  if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a scratch directory in /tmp");
  config.scratch = pattern;

  const std::string role(proto::role_name(config.role));
  std::cout << "hfmpm-conformance: " << role << " side " << config.program << "\n  scene " << config.scene_path
            << ", transport " << (config.tcp ? "tcp" : "ipc") << ", scratch " << config.scratch << "\n";
  const auto start = Clock::now();
  int passed = 0, failed = 0;
  std::string blocked;  // a start-up check that failed: every later check would fail the same way
  for (const auto& check : checks) {
    if (!arguments.only.empty() && !arguments.only.count(check.name)) continue;
    Context context{config, check.name, {}, 0};
    const auto check_start = Clock::now();
    std::string note, reason;
    try {
      if (!blocked.empty()) fail("not run: the side does not pass '" + blocked + "', which every check goes through");
      note = check.run(context);
    } catch (const CheckFailure& e) {
      reason = e.what();
    } catch (const std::exception& e) {
      reason = std::string("conformance program error: ") + e.what();
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - check_start).count();
    std::printf("%s  %-26s %5.2f s  %s\n", reason.empty() ? "PASS" : "FAIL", check.name.c_str(), seconds,
                reason.empty() ? note.c_str() : reason.c_str());
    if (reason.empty()) {
      ++passed;
    } else {
      ++failed;
      if (blocked.empty() && (check.name == "hello" || check.name == "startup")) blocked = check.name;
      std::fflush(stdout);
      for (const auto& log : context.logs) print_log_tail(log, 15);
    }
    std::fflush(stdout);
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("hfmpm-conformance: %s side: %d passed, %d failed (%.1f s)\n", role.c_str(), passed, failed, seconds);
  if (failed == 0 && !arguments.keep) {
    std::error_code ignored;
    fs::remove_all(config.scratch, ignored);
  } else {
    std::printf("hfmpm-conformance: logs kept in %s\n", config.scratch.c_str());
  }
  return failed == 0 ? 0 : 1;
}

}  // namespace
}  // namespace hfmpm::conformance

int main(int argc, char** argv) {
  using namespace hfmpm::conformance;
  try {
    int status = 0;
    const auto arguments = parse(argc, argv, status);
    if (!arguments) return status;
    return run(*arguments);
  } catch (const std::invalid_argument& e) {
    std::cerr << "hfmpm-conformance: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hfmpm-conformance: " << e.what() << "\n";
    return 1;
  }
}
