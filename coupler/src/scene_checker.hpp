// Private to the scene validator: collects rule violations with their key,
// value and allowed range. The loader adds file and line.
#pragma once

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "hfmpm/coupling/scene_loader.hpp"

namespace hfmpm::coupling {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

inline std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

class Checker {
 public:
  void missing(const std::string& key, const std::string& what) { problems_.push_back({key, "", what}); }
  void bad(const std::string& key, const std::string& value, const std::string& allowed) {
    problems_.push_back({key, value, allowed});
  }
  // lo < v (or lo <= v) and v <= hi, finite.
  void range(const std::string& key, double v, double lo, double hi, bool lo_open, const std::string& unit) {
    const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
    if (!ok) {
      std::string allowed = std::string("a finite value ") + (lo_open ? "> " : ">= ") + text(lo);
      if (std::isfinite(hi)) allowed += " and <= " + text(hi);
      if (!unit.empty()) allowed += " (" + unit + ")";
      bad(key, text(v), allowed);
    }
  }
  void positive(const std::string& key, double v, const std::string& unit) { range(key, v, 0, kInf, true, unit); }
  void non_negative(const std::string& key, double v, const std::string& unit) { range(key, v, 0, kInf, false, unit); }
  std::vector<SceneProblem> take() { return std::move(problems_); }

 private:
  std::vector<SceneProblem> problems_;
};

// Rules for a TimeFunction; `min_value` is the smallest value it may take.
void check_time_function(Checker& c, const std::string& key, const scene::TimeFunction& f, double min_value,
                         const std::string& unit);
// Rules for solid.mpm (scene_validate_mpm.cpp).
void check_mpm_solid(Checker& c, const scene::MpmSolid& m);
// scene_validate_geometry.cpp
void check_crack_geometry(Checker& c, const scene::MpmSolid& m);
void check_regions_in_grid(Checker& c, const scene::MpmSolid& m);
// The MPM solid's stable step, cfl h / c_p of its fastest material (density
// scaled) as the solid computes it; NaN if the values needed are invalid.
double mpm_solid_stable_dt(const scene::MpmSolid& m);
// Grid nodes and (an upper bound on) the particles the MPM solid makes.
double mpm_solid_nodes(const scene::MpmSolid& m);
double mpm_solid_particles(const scene::MpmSolid& m);
// Rules for fluid.mpm, including how it fits the solid's cracks (scene_validate_fluid.cpp).
void check_mpm_fluid(Checker& c, const scene::Scene& s);

}  // namespace hfmpm::coupling
