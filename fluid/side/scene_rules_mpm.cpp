// Rules for fluid.mpm: fluid constants, inlet, outlet, initial fill, and
// which of the solid's cracks hold fluid.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "fluid_scene_rules.hpp"

namespace hfmpm::fluid {

using proto::check_time_function;
using proto::Checker;
using proto::kInf;
using proto::text;

namespace {

// What the fluid needs to know about each crack of the solid in the scene.
struct SceneCrack {
  bool mouth = false;  // the fluid can enter: the first point is a mouth, or an inlet vertex is set
  double length = 0;   // m, initial length along the crack from where the fluid enters (the shorter wing)
};

std::vector<SceneCrack> scene_cracks(const scene::Solid& solid) {
  std::vector<SceneCrack> out;
  if (solid.has_prescribed_crack()) {
    out.push_back({true, solid.prescribed_crack().initial_length_m()});
  } else if (solid.has_mpm()) {
    for (const auto& crack : solid.mpm().cracks()) {
      SceneCrack sc{!crack.start_is_tip() || crack.has_inlet_vertex(), 0};
      double before = 0;  // the length up to the inlet vertex
      for (int i = 1; i < std::min(crack.x_m_size(), crack.y_m_size()); ++i) {
        sc.length += std::hypot(crack.x_m(i) - crack.x_m(i - 1), crack.y_m(i) - crack.y_m(i - 1));
        if (crack.has_inlet_vertex() && static_cast<int>(crack.inlet_vertex()) == i) before = sc.length;
      }
      if (crack.has_inlet_vertex()) sc.length = std::min(before, sc.length - before);
      out.push_back(sc);
    }
  }
  return out;
}

// The pressure the MPM fluid admits before it fails a step, as a multiple of
// its bulk modulus (FluidSolver::kCompressionLimit, fluid/include/hfmpm/fluid/mpm/solver.hpp).
constexpr double kAdmittedPressureOverK = 100;

// Each constant finite on its own can still give a quantity the fluid
// computes with that is not: K = 1e308 passed every rule and ran, its
// pressure limit 100 K overflowing to inf and the inlet pressure with it.
// What the fluid derives from K, rho and c before it steps must be finite:
// its sound speed sqrt(K / rho) (the explicit step cfl h / c_s), the largest
// pressure it admits, 100 K, and that pressure over tait_c (the implicit
// interface's compressibility term K + p / c).
void check_derived_constants(Checker& c, const scene::MpmFluid& f, const std::string& key) {
  const double K = f.bulk_modulus_pa(), rho = f.density_kg_m3(), tait = f.tait_c();
  auto valid = [](double v) { return std::isfinite(v) && v > 0; };
  if (!valid(K) || !valid(rho) || !valid(tait)) return;  // reported by their own rules
  const double speed = std::sqrt(K / rho);
  const double admitted = kAdmittedPressureOverK * K;
  const std::string values =
      "bulk_modulus_pa = " + text(K) + ", density_kg_m3 = " + text(rho) + ", tait_c = " + text(tait);
  if (!(std::isfinite(speed) && speed > 0)) {
    c.bad(key + "bulk_modulus_pa", text(K),
          "a bulk modulus and density whose sound speed sqrt(bulk_modulus_pa / density_kg_m3) is a finite number > 0 "
          "(m/s; the fluid's explicit step is cfl h / that): here " +
              text(speed) + " m/s from " + values);
  } else if (!std::isfinite(admitted) || !std::isfinite(admitted / tait)) {
    c.bad(key + "bulk_modulus_pa", text(K),
          "a bulk modulus with the pressure the fluid admits, " + text(kAdmittedPressureOverK) +
              " x bulk_modulus_pa, and that pressure / tait_c finite (the implicit interface's term K + p / tait_c): "
              "at most " +
              text(std::numeric_limits<double>::max() / kAdmittedPressureOverK * std::min(1.0, tait), 3) +
              " Pa with tait_c = " + text(tait) + " (liquids: 1e9 to 1e10 Pa)");
  }
}

}  // namespace

void check_mpm_fluid(Checker& c, const scene::Scene& s) {
  const auto& f = s.fluid().mpm();
  const std::string key = "fluid.mpm.";
  c.positive(key + "density_kg_m3", f.density_kg_m3(), "kg/m^3");
  c.positive(key + "bulk_modulus_pa", f.bulk_modulus_pa(), "Pa");
  c.positive(key + "tait_c", f.tait_c(), "dimensionless; 0.0894 for water");
  check_derived_constants(c, f, key);
  c.non_negative(key + "viscosity_pa_s", f.viscosity_pa_s(), "Pa s");
  c.range(key + "cfl", f.cfl(), 0, 1, true, "dimensionless");
  c.non_negative(key + "particle_length_m", f.particle_length_m(), "m; 0 = half the mouth element");
  if (!(f.merge_fraction() >= 0 && f.merge_fraction() < 2))
    c.bad(key + "merge_fraction", text(f.merge_fraction()), "a finite value >= 0 and < 2 (of particle_length)");
  c.range(key + "flip_fraction", f.flip_fraction(), 0, 1, false, "0 = PIC, 1 = FLIP");
  c.positive(key + "min_width_m", f.min_width_m(), "m");
  c.non_negative(key + "virtual_opening_m", f.virtual_opening_m(), "m");
  if (f.lag() == scene::MpmFluid::LAG_UNSPECIFIED)
    c.bad(key + "lag", "LAG_UNSPECIFIED",
          "ZERO_PRESSURE, FRONT_PRESSURE, FIXED_PRESSURE, TIP_ASYMPTOTE or TIP_ASYMPTOTE_MATCHED");
  c.non_negative(key + "lag_pressure_pa", f.lag_pressure_pa(), "Pa");
  // The matched tip closure holds the fluid to the tip solution over the
  // crack's opening; an MPM crack grown under load reads 0.65-0.82 of its
  // opening unless its surfaces come from the material (docs/fluid.md).
  if (f.lag() == scene::MpmFluid::TIP_ASYMPTOTE_MATCHED && s.solid().has_mpm() &&
      s.solid().mpm().fracture().propagate() && !s.solid().mpm().fracture().surfaces_from_material()) {
    c.bad(key + "lag", "TIP_ASYMPTOTE_MATCHED",
          "with a growing MPM crack, TIP_ASYMPTOTE_MATCHED needs solid.mpm.fracture.surfaces_from_material: true (a "
          "crack grown under load otherwise reads 0.65-0.82 of its opening, and the closure, matched to that "
          "opening, runs the crack short and wide); or another lag: ZERO_PRESSURE, FRONT_PRESSURE, FIXED_PRESSURE or "
          "TIP_ASYMPTOTE");
  }
  if (f.max_substeps() < 1 || f.max_substeps() > 100000) {
    c.bad(key + "max_substeps", std::to_string(f.max_substeps()), "1 to 100000 fluid steps per coupled step");
  }

  if (!f.has_inlet()) {
    c.missing(key + "inlet", "an inlet: inlet { flow_rate_m2_s { .. } } or inlet { pressure_pa { .. } }");
  } else {
    const auto& in = f.inlet();
    if (in.has_flow_rate_m2_s())
      check_time_function(c, key + "inlet.flow_rate_m2_s", in.flow_rate_m2_s(), 0.0, "m^2/s");
    else if (in.has_pressure_pa())
      check_time_function(c, key + "inlet.pressure_pa", in.pressure_pa(), 0.0, "Pa");
    else
      c.missing(key + "inlet", "one of flow_rate_m2_s { .. } or pressure_pa { .. }");
    c.non_negative(key + "inlet.pre_opening_m", in.pre_opening_m(), "m");
    c.non_negative(key + "inlet.pre_opening_length_m", in.pre_opening_length_m(), "m");
  }
  if (f.has_outlet()) {
    if (!f.outlet().has_pressure_pa())
      c.missing(key + "outlet.pressure_pa", "the outlet pressure p(t) (Pa), a TimeFunction");
    else
      check_time_function(c, key + "outlet.pressure_pa", f.outlet().pressure_pa(), 0.0, "Pa");
  }

  // A fluid entering inside the body (a crack's inlet_vertex) keeps one
  // pressure where its two wings meet over every coupled step; that holds
  // with the implicit interface step (the fluid's pressure waves implicit).
  // The explicit fluid's waves cross many fluid substeps within a coupled
  // step, and one transfer between the wings per coupled step does not hold
  // them to one pressure (tried: the mismatch grew from step to step).
  if (s.solid().has_mpm() && s.coupling().scheme() != scene::Coupling::IMPLICIT) {
    for (int i = 0; i < s.solid().mpm().cracks_size(); ++i) {
      if (!s.solid().mpm().cracks(i).has_inlet_vertex()) continue;
      c.bad("solid.mpm.cracks[" + std::to_string(i) + "].inlet_vertex",
            std::to_string(s.solid().mpm().cracks(i).inlet_vertex()),
            "coupling.scheme: IMPLICIT with an inlet vertex (the fluid's two wings keep one pressure where they "
            "meet only under the implicit interface step); or, under another scheme, a crack with a mouth "
            "(start_is_tip: false, no inlet_vertex) on a symmetry plane");
    }
  }

  // Which cracks hold fluid.
  const auto cracks = scene_cracks(s.solid());
  std::vector<std::size_t> filled;
  if (f.crack_ids_size() == 0) {
    for (std::size_t i = 0; i < cracks.size(); ++i) {
      if (cracks[i].mouth) filled.push_back(i);
    }
    if (filled.empty() && s.solid().model_case() != scene::Solid::MODEL_NOT_SET) {
      c.bad(key + "crack_ids", "(empty)",
            "the ids of the cracks that hold fluid; by default every crack whose first point is a mouth "
            "(start_is_tip: false) or that has an inlet_vertex, and this scene has none");
    }
  }
  std::set<std::uint32_t> seen;
  for (int i = 0; i < f.crack_ids_size(); ++i) {
    const auto id = f.crack_ids(i);
    const std::string k = key + "crack_ids[" + std::to_string(i) + "]";
    if (id >= cracks.size()) {
      c.bad(k, std::to_string(id),
            "a crack id below " + std::to_string(cracks.size()) + " (the solid's cracks, in order)");
    } else if (!seen.insert(id).second) {
      c.bad(k, std::to_string(id), "an id not listed before");
    } else {
      filled.push_back(id);
    }
  }

  if (f.has_initial_fill()) {
    const auto& fill = f.initial_fill();
    if (!fill.has_front_m()) {
      c.missing(key + "initial_fill.front_m",
                "the arc length (m) the fluid fills from the mouth (each way from an inlet vertex), > 0");
    } else {
      double shortest = kInf;
      for (auto id : filled) shortest = std::min(shortest, cracks[id].length);
      if (std::isfinite(shortest)) {
        c.range(key + "initial_fill.front_m", fill.front_m(), 0, shortest * (1 + 1e-12), true,
                "m, at most the initial length of every fluid crack (of its shorter wing from an inlet vertex)");
      } else {
        c.positive(key + "initial_fill.front_m", fill.front_m(), "m");
      }
    }
    const double K = f.bulk_modulus_pa() > 0 ? f.bulk_modulus_pa() : kInf;
    c.range(key + "initial_fill.pressure_pa", fill.pressure_pa(), 0, K, false,
            "Pa, at most fluid.mpm.bulk_modulus_pa (no liquid's equation of state holds beyond)");
  }
}

}  // namespace hfmpm::fluid
