#include "hfmpm/coupling/state_watch.hpp"

#include <algorithm>
#include <sstream>

namespace hfmpm::coupling {

bool StateWatch::held(Held& h, bool now, double t) {
  if (!now) {
    h.rounds = 0;
    return false;
  }
  if (h.rounds++ == 0) h.since = t;
  return !h.reported && h.rounds >= kRounds && t - h.since >= kMinimumFraction * end_time_;
}

std::vector<Notice> StateWatch::update(double t, const SideDiagnostics& fluid) {
  std::vector<Notice> out;
  const bool injecting = started_ && fluid.injected_volume > injected_;
  started_ = true;
  injected_ = fluid.injected_volume;
  highest_inlet_ = std::max(highest_inlet_, fluid.inlet_pressure);
  // Fluid flowing in with no pressure at the inlet to drive it: the crack
  // opens faster than the fluid can follow (a void), or the inlet is not
  // where the fluid enters.
  if (held(zero_inlet_, injecting && !(fluid.inlet_pressure > 0), t)) {
    zero_inlet_.reported = true;
    std::ostringstream m;
    m << "the inlet pressure has read " << fluid.inlet_pressure << " Pa since t = " << zero_inlet_.since
      << " s while fluid is injected (" << fluid.injected_volume
      << " m^2 so far): an injection needs a pressure to drive it, so the crack is opening by something other "
         "than the fluid (check the crack's path and opening in solid.h5)";
    out.push_back({"zero-inlet-pressure", m.str()});
  }
  // The coupling lag (the pressure the faces did not carry over an exchange,
  // or the implicit interface's mismatch) larger than the pressure that
  // drives the crack now, the inlet's: the solid and the fluid no longer
  // describe one state. The inlet pressure of the round, not the run's
  // largest: a start-up or growth-step spike of the inlet (0.87 MPa in the
  // inclined well's first 0.1 s, against 0.13 MPa after) would otherwise
  // hide a lag of 0.9-1.2 MPa held over the run's last 0.4 s.
  if (held(lag_, fluid.inlet_pressure > 0 && fluid.coupling_lag > fluid.inlet_pressure, t)) {
    lag_.reported = true;
    std::ostringstream m;
    m << "the coupling lag has exceeded the inlet pressure since t = " << lag_.since << " s, now " << fluid.coupling_lag
      << " Pa against " << fluid.inlet_pressure << " Pa at the inlet (the run's largest " << highest_inlet_
      << " Pa): the faces and the fluid no longer describe one state, so the coupled answer is not the physics' "
         "(docs/stability.md, \"When a run must not pass silently\")";
    out.push_back({"coupling-lag", m.str()});
  }
  return out;
}

}  // namespace hfmpm::coupling
