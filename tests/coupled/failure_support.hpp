// What the failure tests share (failure_test.cpp: sides that fail;
// intrusion_test.cpp: strangers, impostors and signals): fast liveness
// settings and the bounds on how long a detection may take.
#pragma once

#include <exception>
#include <string>
#include <vector>

#include "coupled_support.hpp"

namespace hfmpm::test {

// Fast liveness settings so each failure is found in about a second.
// Wall-clock bounds: a detection that works takes its timeout plus moments
// (measured: an exit 0.27 s, a hang the 2 s step timeout + 2 s, a freeze the
// 1 s heartbeat timeout + 2 s, a silent coupler 1.15 s). The bounds add
// kBusyMarginS to the timeout, so a machine busy enough to stall a process
// for many seconds does not fail them, while a detection that waits for a
// default timeout (10 s step, 3 s heartbeat, 60 s welcome) or never comes
// still does.
inline constexpr double kBusyMarginS = 20;

inline const std::vector<std::string> kFastLiveness{"--set", "coupling.heartbeat_interval_s=0.1",
                                                    "--set", "coupling.heartbeat_timeout_s=1",
                                                    "--set", "coupling.step_timeout_s=2"};

// Rows in a run's history.csv so far (0 before the coupler has created it).
inline std::size_t history_rows(const std::string& out) {
  try {
    return read_csv(out + "/history.csv").rows.size();
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace hfmpm::test
