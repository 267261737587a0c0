// The named conformance checks. Each launches the program under test (once or
// more) through a Session, returns a one-line note when it passes and throws
// CheckFailure with the reason when it does not.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "harness.hpp"

namespace hfmpm::conformance {

struct Check {
  std::string name;
  std::string what;  // one line: the rule it checks
  std::function<std::string(Context&)> run;
};

std::vector<Check> lifecycle_checks();  // handshake, heartbeats, reject, version, shutdown, silence
std::vector<Check> schedule_checks();   // step commands, exchange interval, schemes, frames
std::vector<Check> error_checks();      // bad input: Error (protocol) and a non-zero exit
Check solid_growth_check();             // solid_checks.cpp
Check fluid_growth_check();             // fluid_checks.cpp

// Helpers shared by the check files.
std::string seconds_text(double seconds);  // "0.23 s"
// The side must exit within timeout_s with status 0; returns "exited with status 0 after 0.1 s".
std::string expect_clean_exit(Session& session, Clock::time_point since, double timeout_s, const std::string& after);

}  // namespace hfmpm::conformance
