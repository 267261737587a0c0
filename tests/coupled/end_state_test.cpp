// A run must not end "completed" in a state the physics forbids
// (docs/stability.md, "When a run must not pass silently"): each scene here is
// forced into one such state, and the run warns (run.json "warnings", stderr)
// or stops as stated. Small dry or stand-in scenes, a few seconds each.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "coupled_support.hpp"

namespace hfmpm::test {
namespace {

// A pressurised crack from the left edge of a 1 m plate (E = 1 GPa, h =
// 0.05 m), K_Ic = 0.1 MPa m^0.5 against K_I of about 1 MPa m^0.5: it grows
// straight at every check. `fracture` is appended to its fracture block.
std::string dry_growth_scene(double end_s, const std::string& fracture) {
  return R"(name: "dry-growth"
time { end_s: )" +
         std::to_string(end_s) +
         R"( }
output { interval_s: )" +
         std::to_string(end_s / 10) + R"( }
solid {
  mpm {
    grid { x_min_m: 0 y_min_m: -0.525 x_max_m: 1.05 y_max_m: 0.525 }
    cell_size_m: 0.05
    materials { name: "rock" youngs_modulus_pa: 1e9 poisson_ratio: 0.25 density_kg_m3: 2500 toughness_pa_sqrt_m: 1e5 }
    regions { material: "rock" rectangle { x_min_m: 0 y_min_m: -0.5 x_max_m: 1 y_max_m: 0.5 } }
    damping { grid_alpha_per_s: 1500 }
    fracture { propagate: true direction: STRAIGHT growth_cells: 0.5 check_interval: 2 )" +
         fracture + R"( }
    cracks { x_m: [0, 0.3] y_m: [0, 0] start_is_tip: false end_is_tip: true pressure_pa { constant: 1e6 } }
  }
}
)";
}

TEST(EndStates, CrackReachingTheEdgeStopsTheRun) {
  const std::string out = scratch_dir("end_state_edge");
  const auto result = run_scene(dry_growth_scene(0.02, ""), out, {});
  EXPECT_EQ(result.exit_code, 3) << result.err;
  EXPECT_NE(result.err.find("the crack reached the boundary"), std::string::npos) << result.err;
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_NE(manifest.find("\"status\": \"stopped\""), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\"stop_reason\": \"the crack reached the boundary"), std::string::npos) << manifest;
  // Output kept: history up to the stop, the last row at the stop.
  const Csv h = read_csv(out + "/history.csv");
  const auto times = h.values("time_s");
  ASSERT_GE(times.size(), 2u);
  EXPECT_LT(times.back(), 0.02);
  EXPECT_GT(h.values("crack_length_m").back(), 0.85);  // ran to within a cell or two of x = 1
}

TEST(EndStates, StalledTipIsReported) {
  // The tip grows once, then waits 1000 shear transits of the crack (0.75 s)
  // before its next check (settle_transits), with K ten times K_Ic: stalled.
  const std::string out = scratch_dir("end_state_stall");
  const auto result = run_scene(dry_growth_scene(0.01, "settle_transits: 1000"), out, {});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("stalled-tip"), std::string::npos) << result.err;
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_NE(manifest.find("\"status\": \"completed\""), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\"warnings\""), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("stalled-tip (solid"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("without growing"), std::string::npos) << manifest;
  // Without the wait the same tip grows and nothing is reported (it reaches
  // the edge instead: the stop of the test above).
  const std::string free_out = scratch_dir("end_state_no_stall");
  const auto free_run = run_scene(dry_growth_scene(0.01, ""), free_out, {});
  EXPECT_EQ(free_run.err.find("stalled-tip"), std::string::npos) << free_run.err;
}

// The MPM solid with the prescribed-pressure stand-in fluid (10 kPa on the
// faces): a region whose in-situ stress says 0.1 MPa of compression, edges
// that pull at 0.1 MPa instead of holding it. The crack opens wide while every
// pressure on it is a tenth of the in-situ normal stress: reported.
TEST(EndStates, OpenBelowStressIsReported) {
  const std::string scene = R"(name: "open-below-stress"
time { end_s: 0.02 }
output { interval_s: 0.002 }
solid {
  mpm {
    grid { x_min_m: 0 y_min_m: -0.525 x_max_m: 1.05 y_max_m: 0.525 }
    cell_size_m: 0.05
    materials { name: "rock" youngs_modulus_pa: 1e9 poisson_ratio: 0.25 density_kg_m3: 2500 }
    regions { material: "rock" rectangle { x_min_m: 0 y_min_m: -0.5 x_max_m: 1 y_max_m: 0.5 }
              initial_stress { xx_pa: -1e5 yy_pa: -1e5 } }
    in_situ_reference: true
    tractions { edge: TOP normal_pa { constant: 1e5 } }
    tractions { edge: BOTTOM normal_pa { constant: 1e5 } }
    tractions { edge: RIGHT normal_pa { constant: -1e5 } }
    damping { grid_alpha_per_s: 1500 }
    cracks { x_m: [0, 0.3] y_m: [0, 0] start_is_tip: false end_is_tip: true }
  }
}
fluid {
  prescribed_pressure { inlet_pressure_pa { constant: 1e4 } profile: UNIFORM stable_dt_s: 1 }
}
)";
  const std::string out = scratch_dir("end_state_open_below");
  // The edges pull: their tractions do work, which the energy check (inlet work only) does not count.
  const auto result = run_scene(scene, out, {"--set", "coupling.energy_bound=0"});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("open-below-stress"), std::string::npos) << result.err;
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_NE(manifest.find("open-below-stress (solid"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("below the smallest in-situ normal stress"), std::string::npos) << manifest;
}

}  // namespace
}  // namespace hfmpm::test
