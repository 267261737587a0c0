// What a scene will cost before it runs (`hfmpm validate`): the MPM solid's
// particles and nodes, the coupled step and the number of steps to
// time.end_s, and a wall-time estimate from measured throughputs.
#pragma once

#include <string>

#include "hfmpm/proto/scene_rules.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

struct RunCost {
  double particles = 0;  // MPM solid particles (0: no MPM solid)
  double nodes = 0;      // MPM solid grid nodes
  double dt = 0;         // s, time.safety_factor x the smallest stable step known before the run (0: unknown)
  std::string dt_from;   // which side's step that is
  double steps = 0;      // to time.end_s at dt
  double wall_s = 0;     // estimated wall time on a quiet 2-core machine (0: unknown)
  std::string basis;     // what the estimate assumes
};

// The estimate for a valid scene (call validate() first), with the sides'
// steps and sizes from `rules`. `particles`: the MPM solid's particle count
// if the caller made them (the scene alone gives an upper bound that counts
// overlapping regions twice); 0 for that bound.
RunCost estimate_run_cost(const scene::Scene& scene, const proto::SceneRules& rules, double particles = 0);

// The estimate as comment lines ("# ..."), for `hfmpm validate`.
std::string describe(const RunCost& cost);

}  // namespace hfmpm::coupling
