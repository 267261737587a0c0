// `hfmpm-reliability bad-scenes`: `hfmpm validate` on every file in
// tests/data/bad_scenes/. Each must be refused: exit 2, a message that names
// the file (and, for a file that starts with "# expect: TEXT", contains TEXT),
// no signal, no hang.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common.hpp"
#include "test_support.hpp"

namespace hfmpm::reliability {

int bad_scenes_command(const CommonOptions& options) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(test::source("tests/data/bad_scenes"))) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  int refused = 0, expected = 0, with_expectation = 0, crashes = 0, hangs = 0;
  for (const auto& file : files) {
    const auto result = test::run({test::bin("hfmpm"), "validate", file.string()}, 30);
    std::ifstream in(file);
    std::string first;
    std::getline(in, first);
    const std::string prefix = "# expect: ";
    const std::string expectation = first.rfind(prefix, 0) == 0 ? first.substr(prefix.size()) : "";
    const bool names_file = result.err.find(file.filename().string()) != std::string::npos;
    const bool ok = !result.timed_out && result.signal == 0 && result.exit_code == 2 && names_file;
    crashes += result.signal != 0 && !result.timed_out;
    hangs += result.timed_out;
    refused += ok;
    if (!expectation.empty()) {
      ++with_expectation;
      expected += ok && result.err.find(expectation) != std::string::npos;
    }
    if (!ok || options.verbose) {
      std::cout << file.filename().string() << ": "
                << (result.timed_out ? "HANG"
                    : result.signal  ? "CRASH signal " + std::to_string(result.signal)
                                     : "exit " + std::to_string(result.exit_code))
                << (names_file ? "" : ", the message does not name the file") << ": " << result.err.substr(0, 300)
                << "\n";
    }
  }
  std::cout << "bad scenes refused (exit 2, message naming the file): " << refused << " of " << files.size() << "\n"
            << "  with the message their '# expect:' line names: " << expected << " of " << with_expectation << "\n"
            << "  crashes: " << crashes << ", hangs: " << hangs << "\n";
  const bool all = refused == static_cast<int>(files.size()) && expected == with_expectation && !files.empty();
  std::cout << (all ? "OK" : "PROBLEMS FOUND") << "\n";
  return all ? 0 : 1;
}

}  // namespace hfmpm::reliability
