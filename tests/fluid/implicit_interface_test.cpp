// The implicit interface step (FluidSolver::step_implicit, implicit.cpp): the
// fluid solves its pressure over a step together with the walls' response
// over that step, so the walls carry the pressure the fluid has at the end.
// The walls here stand in for the solid: each node's opening is a point
// mass per unit crack length under the face pressure against a closing
// stress sigma (an inertial wall, the solid's explicit update without its
// elasticity):
//   r' = r + dt c (p - sigma),   w' = w + dt r',
// reported to the fluid as rate r, acceleration -c sigma, compliance c
// (band 0), exactly what the MPM solid reports (solid face_response_test).
// - Consistency: after each step the walls open under the pressures the
//   fluid reported, and the fluid's own pressure at the new walls is the
//   same (interface_mismatch) up to the shift of the nodal projection as the
//   particles move over the step, ~ v dt |dp/ds| (0.1 m/s x 1e-3 s x 1.2
//   kPa/m = 0.12 Pa here; measured 0.075 and 0.079 Pa against a net
//   pressure of 118 and 121 Pa; asserted below 2e-3 of the net pressure),
//   for a soft (2 MPa) and a stiff (water, 2 GPa) fluid, while mass is
//   conserved to round-off (measured 3e-16).
// - Incompressible limit: the walls open by the injected volume. With water
//   the crack's volume gain equals the injected volume within the fluid's
//   compression (p / K ~ 5e-5; measured 1 - 5.0e-5); with 2 MPa it is short
//   by that compression (measured 1 - 0.040, p / K = 0.05).
// - The step is not limited by the fluid's sound speed: water runs at 71
//   times its acoustic step (0.02 m elements, 1 ms).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::fluid::mpm {
namespace {

constexpr double kSigma = 1e5;  // Pa, closing stress on the walls
constexpr double kC = 2e-3;     // m/s^2 per Pa, the walls' compliance
constexpr double kW0 = 1e-3;    // m, initial opening
constexpr double kQ = 1e-4;     // m^2/s, injection

struct Walls {
  std::vector<double> s, w, r;
};

CrackGeometry report(const Walls& walls) {
  auto g = test::straight_crack(walls.s, walls.w);
  const std::size_t n = walls.s.size();
  g.opening_rate = walls.r;
  g.opening_acceleration.assign(n, -kC * kSigma);
  g.opening_compliance.assign(n, kC);
  g.compliance_band = 0;
  g.opening_rate.back() = g.opening_acceleration.back() = g.opening_compliance.back() = 0;  // a closed tip
  return g;
}

struct Result {
  double worst_mismatch = 0, net = 0, volume_gain = 0, injected = 0, mass_error = 0, acoustic_dt = 0;
};

// Water-like fluid injected at kQ after a ramp over 20 steps of dt, with
// implicit interface steps; walls at rest, kW0 open, closed at the tip.
FluidConfig channel_config(double bulk_modulus, double dt) {
  FluidConfig c;
  c.density = 1000;
  c.bulk_modulus = bulk_modulus;
  c.viscosity = 1e-3;
  c.implicit_interface = true;
  c.inlet.kind = InletConfig::Kind::FlowRate;
  c.inlet.flow_rate = TimeFunction::table({0, 20 * dt}, {0, kQ});
  return c;
}
Walls initial_walls() {
  Walls walls;
  walls.s = test::uniform_nodes(0.2, 10);
  walls.w.assign(walls.s.size(), kW0);
  walls.w.back() = 0;
  walls.r.assign(walls.s.size(), 0.0);
  return walls;
}

// One coupled step: the fluid's implicit step against the walls' response,
// then the walls move under the pressures it reported. Returns them.
std::vector<double> step_with_walls(FluidSolver& f, Walls& walls, double dt) {
  f.set_crack(report(walls));
  f.step_implicit(dt);
  auto p = f.nodal_pressure();  // what the walls carry over this step
  for (std::size_t i = 0; i + 1 < walls.s.size(); ++i) {
    walls.r[i] += dt * kC * (p[i] - kSigma);
    walls.w[i] = std::max(0.0, walls.w[i] + dt * walls.r[i]);
  }
  f.set_crack(report(walls));
  return p;
}

Result run(double bulk_modulus, double dt, int steps) {
  const FluidConfig c = channel_config(bulk_modulus, dt);
  Walls walls = initial_walls();
  FluidSolver f(c);
  f.set_crack(report(walls));
  f.fill(0.2, kSigma);
  Result out;
  out.acoustic_dt = 0.2 / 10 / std::sqrt(bulk_modulus / 1000);
  const double mass0 = f.fluid_mass();
  double volume0 = 0;
  for (std::size_t i = 0; i + 1 < walls.s.size(); ++i) volume0 += 0.5 * (walls.w[i] + walls.w[i + 1]) * 0.02;
  for (int k = 0; k < steps; ++k) {
    const auto p = step_with_walls(f, walls, dt);
    if (k > 0) out.worst_mismatch = std::max(out.worst_mismatch, f.interface_mismatch());
    out.net = std::max(out.net, p[0] - kSigma);
  }
  double volume = 0;
  for (std::size_t i = 0; i + 1 < walls.s.size(); ++i) volume += 0.5 * (walls.w[i] + walls.w[i + 1]) * 0.02;
  out.volume_gain = volume - volume0;
  out.injected = f.injected_volume();
  out.mass_error = std::abs(f.fluid_mass() - mass0 - f.injected_mass()) / f.fluid_mass();
  return out;
}

TEST(ImplicitInterface, WallsCarryThePressureTheFluidHasAtTheEndOfTheStep) {
  for (double K : {2e6, 2e9}) {
    const Result r = run(K, 1e-3, 200);
    std::printf(
        "K = %g Pa: worst mismatch %.3e Pa (net pressure %.3e Pa), volume gain %.6e m^2 against %.6e "
        "injected, mass error %.1e, step / acoustic step %.0f\n",
        K, r.worst_mismatch, r.net, r.volume_gain, r.injected, r.mass_error, 1e-3 / r.acoustic_dt);
    EXPECT_LT(r.worst_mismatch, 2e-3 * r.net) << K;
    EXPECT_LT(r.mass_error, 1e-12) << K;
    // The walls open by the injected volume less what the fluid compressed (p / K).
    const double compression = (kSigma + r.net) / K;
    EXPECT_NEAR(r.volume_gain / r.injected, 1.0, 2 * compression + 1e-6) << K;
  }
}

// The step limit of the implicit interface step is advection's, particle by
// particle: no particle moves more than cfl of its own length (nor of the
// shortest element) in a step. The fluid side passes it to the coupler as it
// is (it was multiplied by max_substeps, but the implicit step does not
// subcycle, so the limit never acted: a built K-vertex field case then
// turned a particle inside out at 5 x its limit). Checked here on the
// injecting channel after 100 steps, against the formula computed from the
// particles, and against the bound it replaced (the shortest particle over
// the fastest), which is smaller whenever the shortest particle is not the
// fastest.
TEST(ImplicitInterface, StableStepIsEachParticlesAdvectionLimit) {
  const double dt = 1e-3;
  const FluidConfig c = channel_config(2e9, dt);
  Walls walls = initial_walls();
  FluidSolver f(c);
  f.set_crack(report(walls));
  EXPECT_TRUE(std::isinf(f.stable_dt()));  // no fluid moves yet
  f.fill(0.2, kSigma);
  EXPECT_TRUE(std::isinf(f.stable_dt()));  // at rest
  for (int k = 0; k < 100; ++k) step_with_walls(f, walls, dt);
  const auto& part = f.particles();
  double expected = std::numeric_limits<double>::infinity(), shortest = 0.02, fastest = 0;
  for (std::size_t q = 0; q < part.size(); ++q) {
    const double v = std::abs(part.velocity[q]);
    if (v > 0) expected = std::min(expected, c.cfl * std::min(part.length[q], 0.02) / v);
    shortest = std::min(shortest, part.length[q]);
    fastest = std::max(fastest, v);
  }
  ASSERT_TRUE(std::isfinite(expected));
  std::printf("%zu particles: stable step %.4e s (each particle's limit), %.4e s (shortest over fastest)\n",
              part.size(), f.stable_dt(), c.cfl * shortest / fastest);
  EXPECT_DOUBLE_EQ(f.stable_dt(), expected);
  EXPECT_GE(f.stable_dt(), c.cfl * shortest / fastest);
  for (std::size_t q = 0; q < part.size(); ++q) {
    EXPECT_LE(std::abs(part.velocity[q]) * f.stable_dt(), c.cfl * part.length[q] * (1 + 1e-12)) << q;
  }
}

// The K-regime stall (issue 19; docs/fluid.md, "The implicit interface
// step"): a water-filled crack closed at its tip between stiff faces, fed at
// the mouth, with a thin fluid (field-km100's water, 1e-4 Pa s) and a long
// step. Over a step a pressure difference of 1 Pa between neighbours moves
// the fluid far more than a uniform 1 Pa compresses it or opens the faces
// (here ~1e-4 against ~6e-10 per Pa: the flow Laplacian's row sums are ~1e5
// times smaller than its diagonal), and the forward-difference Jacobian,
// off by a fraction of a percent wherever a particle end crosses a node,
// got the uniform mode wrong: the solve stalled with the crack over-filled,
// and the step was committed anyway. Checked: every step's largest
// element misfit is a volume strain of at most 1e-8 (K x 1e-8 = 20 Pa of
// water; stricter than the solver's commit bound, 1e-8 of the crack's fluid
// per element, so none is retried or committed above it; before the fix the largest final residual was 5.4e8 Pa, 193 of
// the 300 solves stopped above the tolerance and the crack gained 3.7% more than the injected volume; after it 0.02 Pa,
// none, and 0.99753 of it against the fluid compressed to 0.99753 at 5 MPa), mass is kept to round-off (1e-12: sums of
// ~100 particle masses), and the crack's volume gain is the injected volume less the fluid's compression.
TEST(ImplicitInterface, StiffClosedCrackWithThinWaterIsSolvedEveryStep) {
  constexpr double kStiff = 4e-9;  // m/s^2 per Pa: dt^2 c / w = 4e-9 per Pa, field-km100's 3.7e-9
  constexpr double kWidth = 1e-4, kClosing = 5e6, kK = 2e9, kDt = 1e-2;
  const auto s = test::uniform_nodes(0.2, 8);
  const std::size_t n = s.size();
  std::vector<double> w(n, kWidth), r(n, 0.0);
  w.back() = 0;
  auto crack = [&] {
    auto g = test::straight_crack(s, w);
    g.opening_rate = r;
    g.opening_acceleration.assign(n, -kStiff * kClosing);
    g.opening_compliance.assign(n, kStiff);
    g.compliance_band = 0;
    g.opening_rate.back() = g.opening_acceleration.back() = g.opening_compliance.back() = 0;  // a closed tip
    return g;
  };
  FluidConfig c;
  c.density = 1000;
  c.bulk_modulus = kK;
  c.viscosity = 1e-4;
  c.implicit_interface = true;
  c.inlet.kind = InletConfig::Kind::FlowRate;
  c.inlet.flow_rate = TimeFunction::table({0, 20 * kDt}, {0, 2e-7});
  FluidSolver f(c);
  f.set_crack(crack());
  f.fill(0.2, kClosing);
  const double mass0 = f.fluid_mass();
  double volume0 = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) volume0 += 0.5 * (w[i] + w[i + 1]) * (s[i + 1] - s[i]);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    f.set_crack(crack());
    f.step_implicit(kDt);
    worst = std::max(worst, f.interface_residual());
    const auto p = f.nodal_pressure();
    for (std::size_t i = 0; i + 1 < n; ++i) {
      r[i] += kDt * kStiff * (p[i] - kClosing);
      w[i] = std::max(0.0, w[i] + kDt * r[i]);
    }
  }
  f.set_crack(crack());
  double volume = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) volume += 0.5 * (w[i] + w[i + 1]) * (s[i + 1] - s[i]);
  const double mass_error = std::abs(f.fluid_mass() - mass0 - f.injected_mass()) / f.fluid_mass();
  std::printf(
      "largest final residual %.3e Pa; %llu solves above tolerance; mass error %.1e; volume gain %.6e m^2 "
      "against %.6e injected; inlet pressure %.6e Pa\n",
      worst, static_cast<unsigned long long>(f.interface_unconverged_steps()), mass_error, volume - volume0,
      f.injected_volume(), f.nodal_pressure()[0]);
  EXPECT_LE(worst, 1e-8 * kK);
  EXPECT_LT(mass_error, 1e-12);
  // Each step may commit a misfit up to 1e-8 of the crack's volume (2e-5
  // m^2): over 300 steps 6e-11 m^2, 1e-4 of the injected volume.
  EXPECT_NEAR((volume - volume0) / f.injected_volume(), f.eos().volume_ratio(f.nodal_pressure()[0]), 1e-4);
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
