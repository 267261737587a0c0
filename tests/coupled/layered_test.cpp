// Layered medium, CI size (issue 6; docs/verification.md, "Layered medium"):
// scenarios/layered-ci.scene, a fluid-driven crack 4 m (4 cells) from the bond
// between a stiff layer (E = 10 GPa) and a soft one (2.5 GPa), confining stress
// 2 MPa, inlet pressure ramped from it at 0.125 MPa/s, growth by J >= J_Ic in the
// maximum hoop stress direction.
//
// What bimaterial fracture mechanics says, and what is asserted:
// - a crack parallel to the interface in the stiffer layer sees a K_II that
//   turns it toward the softer layer (the soft side is the more compliant one):
//   the path bends toward the interface;
// - in the softer layer the K_II has the other sign: the crack turns away from
//   the stiff layer (it stays in the soft one);
// - started in the stiff layer, the crack turns to reach the bond (the
//   paper's second observation): at 1e-3 and at 1e-2 Pa s the tip ends at
//   +3.74 and +3.88 m, within a cell of the bond at y = 4 m. (Until the
//   pressure inlet became a well, fluid.md "Pressure inlet", the 1e-2 Pa s
//   crack turned only to +2.5 m by the end: the inflow's free kinetic energy
//   drove the crack's dynamic run from 3 s on, and the path with it.);
// - a more viscous fluid turns it more near the notch (the method paper's
//   finding): two cells past the notch (x = 6 m, which every growing crack
//   reaches) the path of mu = 1e-2 Pa s lies further toward the soft layer
//   than that of 1e-3 Pa s (+0.367 against +0.290 m);
// - a fluid of 1 Pa s does not enter the crack fast enough to grow it by the
//   end time under the same ramp.
// Bounds, in cells (h = 1 m): a crack "grew" when it went more than 2 cells past
// the notch (the zero-lag closure alone lets a tip run about a cell ahead of
// the fluid, and J_Ic = 5 J/m^2 lets the start's transient do that); a turn
// counts when the path is more than a quarter cell off its line (crack
// particles are half a cell apart and each growth step may kink); the
// viscosity effect at x = 6 m is asserted as more than a twentieth of a cell
// (0.077 m); "reaching the bond"
// as coming within a cell of it. The scene runs the implicit interface scheme
// at 0.9 of the solid's step; at half of it every path of the sweep lies
// within 0.19 cell of the scene's (docs/verification.md, "Layered medium").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "coupled_support.hpp"
#include "h5_reader.hpp"

namespace hfmpm::test {
namespace {

constexpr double kNotchTip = 4;   // m, the initial crack runs from x = 0 to 4 at y = 0
constexpr double kInterface = 4;  // m, y of the bond between the layers
constexpr double kCell = 1, kQuarterCell = 0.25, kTwentiethCell = 0.05;

struct Path {
  std::vector<double> x, y;
  double reach() const { return x.back(); }
  // y where the path first reaches x (linear between crack particles).
  double y_at(double at) const {
    for (std::size_t i = 1; i < x.size(); ++i) {
      if (x[i - 1] <= at && at <= x[i] && x[i] > x[i - 1])
        return y[i - 1] + (at - x[i - 1]) / (x[i] - x[i - 1]) * (y[i] - y[i - 1]);
    }
    return std::nan("");
  }
  // Mean y over a <= x <= b (64 intervals along x).
  double mean_y(double a, double b) const {
    double sum = 0;
    for (int k = 0; k <= 64; ++k) sum += y_at(a + (b - a) * k / 64);
    return sum / 65;
  }
};

// One layered-ci run: the scene with the given viscosity; `soft_start` swaps
// the layers so the crack starts in the soft one. Each run's solid takes one
// thread (2,100 particles: a second thread saves little at this size) and the
// tests start their two runs at once, one per core (docs/verification.md,
// "Layered medium": the CI cost).
class LayeredRun {
 public:
  LayeredRun(std::string name, double viscosity, bool soft_start)
      : name_(std::move(name)), viscosity_(viscosity), out_(scratch_dir("layered_" + name_)) {
    std::vector<std::string> argv = {bin("hfmpm"), "run", source("scenarios/layered-ci.scene"), "--out", out_,
                                     "--quiet", "--set", "solid.mpm.threads=1", "--set",
                                     "fluid.mpm.viscosity_pa_s=" + std::to_string(viscosity),
                                     // The thin fluid's retried implicit steps (up to 256 substeps each) can
                                     // make a 20-step command outlast the 10 s liveness timeout on a slow
                                     // machine: measured 14-17 s failures of the same build that passed
                                     // before. The path, not the wall time, is what this test checks.
                                     "--set", "coupling.step_timeout_s=120"};
    if (soft_start) {
      argv.push_back("--set");
      argv.push_back(
          "solid.mpm.regions=[{material: \"soft\" rectangle {x_min_m: 0 y_min_m: -11 x_max_m: 24 y_max_m: 4} "
          "initial_stress {xx_pa: -2e6 yy_pa: -2e6}}, {material: \"stiff\" rectangle {x_min_m: 0 y_min_m: 4 x_max_m: "
          "24 y_max_m: 11} initial_stress {xx_pa: -2e6 yy_pa: -2e6}}]");
    }
    process_ = std::make_unique<Process>(argv);
  }

  // Waits for the run and reads the crack's final path (empty if it failed).
  Path finish() {
    Path p;
    const bool ended = process_->wait(900);
    EXPECT_TRUE(ended) << name_ << " did not end within 900 s";
    if (!ended) return p;
    // A crack that runs to the box's edge stops the run there (exit 3,
    // "the crack reached the boundary"), its path kept.
    const bool at_edge =
        process_->exit_code() == 3 && process_->err().find("the crack reached the boundary") != std::string::npos;
    EXPECT_TRUE(process_->exit_code() == 0 || at_edge) << name_ << ": " << process_->err();
    if (process_->exit_code() != 0 && !at_edge) return p;
    const H5Reader h5(out_ + "/solid.h5");
    const auto frames = h5.children("frames");
    const auto xy = h5.f64("frames/" + frames.back() + "/crack0/positions");
    for (std::size_t i = 0; i + 1 < xy.size(); i += 2) {
      p.x.push_back(xy[i]);
      p.y.push_back(xy[i + 1]);
    }
    std::printf("%s (mu = %g Pa s): reached x = %.2f m, tip y = %+.2f m, max |y| = %.2f m\n", name_.c_str(), viscosity_,
                p.reach(), p.y.back(), std::abs(*std::max_element(p.y.begin(), p.y.end(), [](double a, double b) {
                  return std::abs(a) < std::abs(b);
                })));
    return p;
  }

 private:
  std::string name_;
  double viscosity_;
  std::string out_;
  std::unique_ptr<Process> process_;
};

TEST(Layered, StartedInTheStiffLayerItTurnsTowardTheSoftOneAndMoreSoWithAMoreViscousFluid) {
  LayeredRun thin_run("stiff_mu1e-3", 1e-3, false), thick_run("stiff_mu1e-2", 1e-2, false);
  const Path thin = thin_run.finish();
  const Path thick = thick_run.finish();
  ASSERT_FALSE(thin.x.empty());
  ASSERT_FALSE(thick.x.empty());
  // Each path's tip ends more than a quarter cell toward the soft layer and
  // never turns a quarter cell away from it; the two are compared two cells
  // past the notch. Measured: docs/verification.md; the test prints the figures.
  const double at = kNotchTip + 2 * kCell;
  for (const Path* p : {&thin, &thick}) {
    EXPECT_GT(p->reach(), kNotchTip + 2 * kCell) << "the crack must grow more than the zero-lag closure allows";
    EXPECT_GT(p->y.back(), kQuarterCell) << "the tip ends toward the soft layer (y > 0)";
    EXPECT_GT(*std::min_element(p->y.begin(), p->y.end()), -kQuarterCell) << "it never turns away from it";
  }
  for (const Path* p : {&thin, &thick}) {
    EXPECT_GT(*std::max_element(p->y.begin(), p->y.end()), kInterface - kCell) << "it reaches the bond";
  }
  const double d_thin = thin.y_at(at), d_thick = thick.y_at(at);
  std::printf("deviation at x = %.2f m: mu 1e-3 %+.3f m, mu 1e-2 %+.3f m; mean offset from x = 4 m: %+.3f m, %+.3f m\n",
              at, d_thin, d_thick, thin.mean_y(kNotchTip, at), thick.mean_y(kNotchTip, at));
  EXPECT_GT(d_thick, d_thin + kTwentiethCell) << "at x = " << at << " m";
}

// Two runs that share nothing but their cost: started in the soft layer the
// crack stays there (1e-2 Pa s), and a fluid of 1 Pa s started in the stiff
// layer does not grow it by the end time.
TEST(Layered, StartedInTheSoftLayerItStaysThereAndAFluidOfOnePascalSecondDoesNotGrowIt) {
  LayeredRun soft_run("soft_mu1e-2", 1e-2, true), thick_run("stiff_mu1", 1, false);
  const Path soft = soft_run.finish();
  const Path thick = thick_run.finish();
  ASSERT_FALSE(soft.x.empty());
  EXPECT_GT(soft.reach(), kNotchTip + 2 * kCell);
  // The stiff layer is above (y > 4): the crack must not turn toward it.
  EXPECT_LT(*std::max_element(soft.y.begin(), soft.y.end()), kQuarterCell);
  EXPECT_LT(soft.y.back(), 0.0);
  ASSERT_FALSE(thick.x.empty());
  EXPECT_LE(thick.reach(), kNotchTip + 2 * kCell) << "1 Pa s";
}

// A thin fluid (1e-4 Pa s) started in the stiff layer runs on toward the bond
// and does not curl back on itself. Until the growth check required the tip's
// K's to carry J (growth.cpp, growth_direction_known), a growth step at 0.98 s
// read J = 14 J/m^2 with K's a hundredth of sqrt(J E') and kinked by 71 deg;
// two more kinks curled the path back to x = 6.2 m, the tip stalled against
// the crack behind it, and the fluid's solve struggled there to the end (213
// Newton iterations per step, 148 s). Now: to the box's edge (22.85 m), no
// kink above 34 deg, 15 Newton iterations per step, 23 s. Asserted: the path
// advances in x at every crack particle (no curl), no kink above 45 deg, and
// it grows more than ten cells past the notch.
TEST(Layered, AThinFluidsCrackDoesNotCurlBackOnItself) {
  LayeredRun thin_run("stiff_mu1e-4", 1e-4, false);
  const Path thin = thin_run.finish();
  ASSERT_GT(thin.x.size(), 2u);
  double largest = 0;
  for (std::size_t i = 1; i < thin.x.size(); ++i) {
    EXPECT_GT(thin.x[i], thin.x[i - 1]) << "the path turns back at crack particle " << i;
    if (i + 1 < thin.x.size()) {
      const double a1 = std::atan2(thin.y[i] - thin.y[i - 1], thin.x[i] - thin.x[i - 1]);
      const double a2 = std::atan2(thin.y[i + 1] - thin.y[i], thin.x[i + 1] - thin.x[i]);
      largest = std::max(largest, std::abs(std::remainder(a2 - a1, 2 * M_PI)) * 180 / M_PI);
    }
  }
  std::printf("largest kink %.1f deg\n", largest);
  EXPECT_LT(largest, 45.0);
  EXPECT_GT(thin.reach(), kNotchTip + 10 * kCell);
}

}  // namespace
}  // namespace hfmpm::test

namespace hfmpm::test {
namespace {

// The output interval changes neither the answer nor a run's verdict. Found on
// the soft start of the full layered scene with a fluid of 1e-4 Pa s, which on
// the scene's former Gauss-Seidel scheme met a transient in its first 10 ms
// that the coupler's energy check may or may not catch: until the control
// points were fixed at multiples of the control block, an output every 20 ms
// stopped the run at step 220 and an output every 1 ms did not, with the
// exchanges the same bit for bit up to step 220 (docs/protocol.md, "How the
// coupler chooses dt"; docs/verification.md, "Layered medium"). The scene now
// runs the implicit scheme, which has no such transient; the same run still
// checks that the output interval moves nothing. Asserted at three output
// intervals over 0.02 s: the same exit code, the same last history row and the
// same largest kinetic energy over the fluid's work.
TEST(Layered, VerdictAndAnswerDoNotDependOnTheOutputInterval) {
  const std::string text = read_file(source("scenarios/layered.scene"));
  const std::string soft_start =
      "solid.mpm.regions=[{material: \"soft\" rectangle {x_min_m: 0 y_min_m: -17 x_max_m: 36 y_max_m: 4} "
      "initial_stress { xx_pa: -2e6 yy_pa: -2e6 }}, {material: \"stiff\" rectangle {x_min_m: 0 y_min_m: 4 x_max_m: "
      "36 y_max_m: 17} initial_stress { xx_pa: -2e6 yy_pa: -2e6 }}]";
  struct Outcome {
    int exit_code;
    std::vector<double> last_row;
    double largest_ratio;
  };
  std::vector<Outcome> outcomes;
  const std::vector<std::string> intervals{"0.02", "0.001", "0.0037"};
  for (const auto& interval : intervals) {
    const auto out = scratch_dir("layered_output_" + interval);
    const auto result =
        run_scene(text, out,
                  {"--set", soft_start, "--set", "fluid.mpm.viscosity_pa_s=1e-4", "--set", "time.end_s=0.02", "--set",
                   "output.interval_s=" + interval, "--set", "output.hdf5=false"},
                  300);
    const Csv history = read_csv(out + "/history.csv");
    ASSERT_FALSE(history.rows.empty()) << result.err;
    auto last = history.rows.back();
    last[history.column("wall_s")] = 0;
    outcomes.push_back(
        {result.exit_code, last, json_number(read_file(out + "/run.json"), "max_kinetic_energy_over_inlet_work")});
    std::printf("output every %s s: exit %d, last row at step %.0f, largest KE / fluid work %.6g\n", interval.c_str(),
                result.exit_code, last[history.column("step")], outcomes.back().largest_ratio);
  }
  for (std::size_t i = 1; i < outcomes.size(); ++i) {
    EXPECT_EQ(outcomes[i].exit_code, outcomes[0].exit_code) << "output every " << intervals[i] << " s";
    EXPECT_EQ(outcomes[i].last_row, outcomes[0].last_row) << "output every " << intervals[i] << " s";
    EXPECT_EQ(outcomes[i].largest_ratio, outcomes[0].largest_ratio) << "output every " << intervals[i] << " s";
  }
}

}  // namespace
}  // namespace hfmpm::test
