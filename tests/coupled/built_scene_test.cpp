// Scenes from physics alone (hfmpm scene, app/scene_builder.hpp) through the
// real programs: a CI-size subset of the robustness matrix
// (tools/robustness_matrix.py, docs/verification.md "Scenes from physics
// alone"). Four KGD problems: three viscosity-dominated (the lab analog, and
// two field rocks of the matrix: E = 30 GPa, and nu = 0.15, Km = 0.1) and the
// lab toughness-dominated one (Km = 7.6); each is built with no setting made
// for it, at 10 (lab) or 12 (field) cells per expected final half-length (the
// matrix uses 20) with a notch of two cells, run with water, and compared
// with the vertex its Km selects from three notch lengths on. The full matrix
// (23 of 24 within issue 19's bounds on 5 December; field Km = 100, at ten
// times its confinement, stalls) is a benchmark, not a test: 1150 s.
//
// Bounds, from the runs measured when this test was written (worst over the
// compared rows; at 10 cells a cell is 10% of the final half-length and the
// growth step 2.5 to 5% of it):
// - M-vertex cases: mouth opening and net inlet pressure within 10% and 20%
//   (the CI bounds of the hand-built KGD scenes), the fluid front within 20%
//   (it leads the vertex by about a cell, docs/verification.md "What limits
//   the KGD length").
// - The K-vertex case: the same bounds since the faces are read from the
//   material, relaxed over a transit, with damping critical for the crack's
//   mode (5 December, docs/verification.md "A growth step without a jolt";
//   30% on opening and pressure before, when the velocity faces read the
//   grown part narrow: 21.9% and 25.8%).
// Measured (5 December; front, opening, pressure, volume balance): lab
// viscosity 3.6%, 5.1%, 8.1%, 1e-4; field E = 30 GPa 3.9%, 4.8%, 7.7%, 5e-4;
// field nu = 0.15 4.0%, 5.0%, 7.3%, 5e-4; lab toughness 4.5%, 8.4%, 16.2%,
// 1e-4. 36 s for the four, two at a time. With the method derived at run
// time and the settling cap at the tip's final speed (7 December): 4.3%,
// 4.2%, 7.0%; 4.3%, 4.1%, 6.5%; 4.3%, 4.3%, 5.9%; lab toughness 4.5%, 8.5%,
// 17.9%; 30-45 s.
// - Every case: the water's volume (sum of l w) is the injected volume plus
//   the notch's virtual film within 2% once the crack is three notch lengths
//   long, and the run completes.
#include <cmath>
#include <cstdio>
#include <future>
#include <string>
#include <vector>

#include "coupled_support.hpp"
#include "scene_builder.hpp"

namespace hfmpm::test {
namespace {

struct Case {
  std::string name;
  double e, nu, rho, k_ic, sigma, mu, q, t;
  double cells;  // accuracy.cells_per_half_length
};

struct Outcome {
  std::string name;
  bool viscous = true;
  RunResult result;
  std::vector<double> t, tip, front, mouth, p_in, injected, volume;
  double notch = 0, sigma = 0, e_prime = 0, mu = 0, q = 0, k_ic = 0, ramp = 0, film = 0;
};

Outcome run_case(const Case& c) {
  Outcome o;
  o.name = c.name;
  o.e_prime = c.e / (1 - c.nu * c.nu);
  o.mu = c.mu;
  o.q = c.q;
  o.k_ic = c.k_ic;
  o.sigma = c.sigma;
  o.ramp = 0.01 * c.t;
  const double t_eff = c.t - 0.5 * o.ramp;
  const double l = std::min(app::m_vertex(o.e_prime, c.mu, c.q, t_eff).half_length,
                            app::k_vertex(o.e_prime, c.k_ic, c.q, t_eff).half_length);
  o.notch = 2 * l / c.cells;  // two cells
  char text[1024];
  std::snprintf(text, sizeof text,
                "name: \"%s\"\n"
                "rock { youngs_modulus_pa: %g poisson_ratio: %g density_kg_m3: %g toughness_pa_sqrt_m: %g }\n"
                "in_situ { normal_to_crack_pa: %g }\n"
                "fluid { viscosity_pa_s: %g }\n"
                "injection { total_rate_m2_s: %g }\n"
                "duration_s: %g\nnotch_m: %g\n"
                "accuracy { cells_per_half_length: %g }\n",
                c.name.c_str(), c.e, c.nu, c.rho, c.k_ic, c.sigma, c.mu, c.q, c.t, o.notch, c.cells);
  const app::BuiltScene built = app::build_scene(app::parse_problem(text, c.name));
  o.viscous = built.derived.viscosity_dominated;
  o.film = o.notch * built.derived.virtual_opening;
  const auto out = scratch_dir("built_" + c.name);
  // One solid thread each: two cases run at once on the two cores.
  o.result = run_scene(built.text, out, {"--set", "output.hdf5=false", "--set", "solid.mpm.threads=1"}, 900);
  if (o.result.exit_code != 0) return o;
  const Csv h = read_csv(out + "/history.csv");
  o.t = h.values("time_s");
  o.tip = h.values("crack_length_m");
  o.front = h.values("front_position_m");
  o.mouth = h.values("mouth_opening_m");
  o.p_in = h.values("inlet_pressure_pa");
  o.injected = h.values("injected_volume_m2");
  o.volume = h.values("fluid_volume_m2");
  return o;
}

void check(const Outcome& o) {
  SCOPED_TRACE(o.name);
  ASSERT_EQ(o.result.exit_code, 0) << o.result.err;
  const double opening_bound = 0.10, pressure_bound = 0.20;
  int compared = 0;
  double worst[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < o.t.size(); ++i) {
    if (o.front[i] < 3 * o.notch) continue;
    const double te = o.t[i] - 0.5 * o.ramp;
    const app::Vertex v =
        o.viscous ? app::m_vertex(o.e_prime, o.mu, o.q, te) : app::k_vertex(o.e_prime, o.k_ic, o.q, te);
    const double e[4] = {o.front[i] / v.half_length - 1, o.mouth[i] / v.opening - 1,
                         (o.p_in[i] - o.sigma) / v.net_pressure - 1, o.volume[i] / (o.injected[i] + o.film) - 1};
    for (int k = 0; k < 4; ++k) worst[k] = std::max(worst[k], std::abs(e[k]));
    EXPECT_LT(std::abs(e[0]), 0.20) << "front, t = " << o.t[i];
    EXPECT_LT(std::abs(e[1]), opening_bound) << "mouth opening, t = " << o.t[i];
    EXPECT_LT(std::abs(e[2]), pressure_bound) << "net inlet pressure, t = " << o.t[i];
    EXPECT_LT(std::abs(e[3]), 0.02) << "volume balance, t = " << o.t[i];
    ++compared;
  }
  std::printf("%s (%s-vertex): %d rows; worst front %.3f, opening %.3f, pressure %.3f, volume balance %.4f\n",
              o.name.c_str(), o.viscous ? "M" : "K", compared, worst[0], worst[1], worst[2], worst[3]);
  EXPECT_GE(compared, 4);
}

TEST(BuiltScene, FourProblemsFromPhysicsAloneFollowTheirVertex) {
  const std::vector<Case> cases = {
      // name, E, nu, rho, K_Ic, sigma_n, mu, Q, t, cells
      {"lab-viscosity", 1e7, 0.25, 2500, 100, 1e5, 0.01, 2.5e-4, 5, 10},
      {"field-E30GPa", 3e10, 0.25, 2600, 2.95e4, 1e6, 1e-4, 2e-5, 300, 12},
      {"lab-toughness", 1e7, 0.25, 2500, 25e3, 1e5, 0.001, 8.3e-4, 5, 10},
      {"field-nu0.15", 2e10, 0.15, 2600, 2.11e4, 1e6, 1e-4, 2e-5, 300, 12},
  };
  for (std::size_t i = 0; i < cases.size(); i += 2) {
    auto a = std::async(std::launch::async, run_case, cases[i]);
    auto b = std::async(std::launch::async, run_case, cases[i + 1]);
    check(a.get());
    check(b.get());
  }
}

}  // namespace
}  // namespace hfmpm::test
