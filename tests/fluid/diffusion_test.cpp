// Verification: pressure diffusion into a rigid channel filled with fluid.
//
// With inertia, wall friction and compressibility, the pressure in a rigid
// channel obeys the telegraph equation p_tt + p_t / tau = c^2 p_ss,
// tau = rho w^2 / (12 mu), c = sqrt(K / rho); for t >> tau it is the diffusion
// equation with D = c^2 tau = K w^2 / (12 mu). A step p0 in the inlet pressure
// at t = 0 into fluid at rest at p = 0 in a semi-infinite channel gives
//   p(s, t) = p0 erfc(s / (2 sqrt(D t)))
// (Carslaw and Jaeger, "Conduction of heat in solids", 2.4), and the
// (zero-pressure) volume that entered is
//   V(t) = integral of q0 dt = (w^3 / (12 mu)) p0 2 sqrt(t / (pi D)).
// Compared at t = 1000 tau (telegraph corrections ~ tau / t = 1e-3), in a
// channel 4 diffusion lengths long (erfc(4) = 2e-8: the far end does not
// matter). Asserted: max nodal error < 2% of p0 at every resolution, falling
// under refinement, and below 5e-4 and 2e-4 of p0 at the coarsest and finer
// resolutions (below); injected volume within 2%, its error falling.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {
namespace {

struct DiffusionResult {
  double max_error;     // max |p_i - p_exact(s_i)| / p0 over the nodes
  double volume_error;  // relative error of the injected volume
  int steps;
};

DiffusionResult diffusion(int cells) {
  const double w = 1e-3, mu = 1.0, rho = 1000, K = 2.2e9, p0 = 1e5;
  const double tau = rho * w * w / (12 * mu), D = K * w * w / (12 * mu);
  const double t_end = 1000 * tau;
  const double L = 4 * 2 * std::sqrt(D * t_end);
  FluidConfig c;
  c.density = rho;
  c.bulk_modulus = K;
  c.viscosity = mu;
  c.particle_length = 0.5 * L / cells;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(p0);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(L, cells, w));
  fluid.fill(L, 0.0);
  int steps = 0;
  while (fluid.time() < t_end * (1 - 1e-12)) steps += fluid.advance(std::min(fluid.stable_dt(), t_end - fluid.time()));
  const double t = fluid.time();
  double max_error = 0;
  for (std::size_t i = 0; i < fluid.grid().size(); ++i) {
    const double exact = p0 * std::erfc(fluid.grid().arc()[i] / (2 * std::sqrt(D * t)));
    max_error = std::max(max_error, std::abs(fluid.nodal_pressure()[i] - exact) / p0);
  }
  const double volume = w * w * w / (12 * mu) * p0 * 2 * std::sqrt(t / (std::numbers::pi * D));
  return {max_error, fluid.injected_volume() / volume - 1, steps};
}

TEST(PressureDiffusion, MatchesErfcAndConverges) {
  double previous = 1, previous_volume = 1;
  for (int cells : {50, 100, 200}) {
    const auto r = diffusion(cells);
    std::printf("pressure diffusion: %d cells (%d steps), max nodal error %.3e of p0, injected volume error %+.3e\n",
                cells, r.steps, r.max_error, r.volume_error);
    EXPECT_LT(r.max_error, 0.02);
    EXPECT_LT(std::abs(r.volume_error), 0.02);
    EXPECT_LT(r.max_error, previous);
    // With the affine transfer (APIC) the error is 2.1e-4, 1.5e-4 and
    // 1.4e-4 of p0 at 50, 100 and 200 cells: at the coarsest already near
    // the size of the telegraph correction the erfc leaves out (tau / t =
    // 1e-3 of the solution's scale), towards which it falls. Under plain PIC
    // it was 9.0e-4, 3.8e-4 and 1.6e-4 (order 1.25, 1.23): PIC's per-step
    // smoothing of the velocity, first order in h with dt proportional to h.
    EXPECT_LT(r.max_error, cells == 50 ? 5e-4 : 2e-4);
    if (cells > 50) {
      EXPECT_LT(std::abs(r.volume_error), std::abs(previous_volume));
    }
    previous_volume = r.volume_error;
    previous = r.max_error;
  }
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
