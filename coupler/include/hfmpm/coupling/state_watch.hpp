// The coupler's end-state watches of a coupled run (docs/stability.md, "When
// a run must not pass silently"): states of the fluid's reports that the
// physics forbids or that make the answer meaningless. They warn (run.json's
// "warnings" and the log); they do not stop the run. The sides watch their
// own states and send notices (protocol Notice); this one sees what only the
// reports of both show. No sockets here: the coupler feeds it diagnostics.
#pragma once

#include <string>
#include <vector>

#include "hfmpm/exchange.hpp"

namespace hfmpm::coupling {

class StateWatch {
 public:
  // end_time: the run's end (s), which sets how long a state must last.
  explicit StateWatch(double end_time) : end_time_(end_time) {}

  // After each control round; returns the notices that first hold now.
  std::vector<Notice> update(double t, const SideDiagnostics& fluid);

  // A state must hold over this many consecutive rounds, and over at least
  // kMinimumFraction of the run's end time, before it is reported. Measured
  // on kgd-two-wing-ci (rows every 5 ms): its water hammer reads a zero inlet
  // pressure in spells of up to 20 ms within the first 0.06 s, and its
  // interface mismatch exceeds the inlet pressure (up to 90 MPa) for up to
  // 30 ms around its first growth steps; a tenth of its 5 s is 0.5 s.
  static constexpr int kRounds = 3;
  static constexpr double kMinimumFraction = 0.1;

 private:
  struct Held {
    int rounds = 0;
    double since = 0;
    bool reported = false;
  };
  bool held(Held& h, bool now, double t);
  double end_time_;
  bool started_ = false;
  double injected_ = 0;       // m^2 at the last round
  double highest_inlet_ = 0;  // Pa, the largest inlet pressure so far
  Held zero_inlet_, lag_;
};

}  // namespace hfmpm::coupling
