// Verification of the pressure inlet as a well: the fluid at rest at p_in
// feeds the mouth, and what enters brings p_in per unit volume, pressure
// work and kinetic energy together (InletConfig::pressure; docs/fluid.md,
// "Pressure inlet").
//
// 1. Torricelli: an inviscid fluid flowing from the well through a rigid
//    channel of length L to an outlet at p = 0 reaches the efflux speed
//    v = sqrt(2 p_in / rho) (Bernoulli along the streamline from the well at
//    rest; Torricelli's law). With the mouth held at p_in itself nothing
//    balances the pressure drop and the fluid accelerates without bound
//    (v = p_in t / (rho L)): the inflow's kinetic energy would come for
//    free. Asserted within 1% of the efflux speed at two resolutions: the
//    compressibility changes it by ~ p_in / K = 5e-5, and the one-step lag of
//    the mouth's velocity by less than dt / (2 L / v) = 1e-4 at these steps.
// 2. Entrance and wall friction: with viscosity the steady speed solves
//    rho v^2 / 2 + 12 mu L v / w^2 = p_in - p_out (the entrance's Bernoulli
//    drop and the cubic law in series). The parameters make the entrance 35%
//    of the drop, so the cubic law alone is 27% off; asserted within 1%.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {
namespace {

struct SteadyFlow {
  double speed;         // m/s, the steady mean speed through the channel (outflow volume flux / w)
  double mouth;         // Pa, the mouth's static pressure (nodal_pressure()[0])
  double inlet_report;  // Pa, inlet_pressure()
};

// Flow from a well at p_in through a rigid channel (length L, width w) to an
// outlet at 0, from rest (filled at 0) to t_end; the speed is the outflow's
// mean over the last tenth of the run.
SteadyFlow well_to_outlet(double p_in, double mu, double L, double w, int cells, double t_end) {
  FluidConfig c;
  c.density = 1000;
  c.bulk_modulus = 2e9;
  c.viscosity = mu;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(p_in);
  c.outlet.enabled = true;
  c.outlet.pressure = TimeFunction::constant(0);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(L, cells, w));
  fluid.fill(L, 0.0);
  while (fluid.time() < 0.9 * t_end) fluid.advance(fluid.stable_dt());
  const double m0 = fluid.outflow_mass(), t0 = fluid.time();
  while (fluid.time() < t_end) fluid.advance(fluid.stable_dt());
  const double q = (fluid.outflow_mass() - m0) / (c.density * (fluid.time() - t0));
  return {q / w, fluid.nodal_pressure()[0], fluid.inlet_pressure()};
}

TEST(PressureInlet, InviscidFlowReachesTorricellisSpeed) {
  const double p_in = 1e5, rho = 1000, L = 1.0, w = 1e-3;
  const double v = std::sqrt(2 * p_in / rho);  // 14.1 m/s
  // The speed approaches v as tanh(v t / (2 L)): within 1e-4 by 10 L / v.
  const double t_end = 10 * L / v;
  for (int cells : {20, 40}) {
    const SteadyFlow r = well_to_outlet(p_in, 0.0, L, w, cells, t_end);
    std::printf("Torricelli, %d cells: speed %.4f m/s against %.4f (%+.2e); mouth %.1f Pa, reported inlet %.1f Pa\n",
                cells, r.speed, v, r.speed / v - 1, r.mouth, r.inlet_report);
    EXPECT_NEAR(r.speed / v, 1.0, 0.01);
    // The mouth's static pressure is the well's less rho v^2 / 2 (= p_in here:
    // all of it), the reported inlet pressure the well's.
    EXPECT_LT(r.mouth, 0.02 * p_in);
    EXPECT_DOUBLE_EQ(r.inlet_report, p_in);
  }
}

TEST(PressureInlet, EntranceDropAndWallFrictionInSeries) {
  const double p_in = 1e5, rho = 1000, mu = 1e-3, L = 1.0, w = 1e-3;
  const double a = 0.5 * rho, b = 12 * mu * L / (w * w);
  const double v = (-b + std::sqrt(b * b + 4 * a * p_in)) / (2 * a);  // 6.55 m/s
  const double cubic = p_in / b;                                      // 8.33 m/s: the cubic law alone
  // The speed settles on the slower of the friction time rho w^2 / (12 mu)
  // (0.08 s) and the transit 2 L / v (0.3 s): run 5 transits.
  const SteadyFlow r = well_to_outlet(p_in, mu, L, w, 20, 10 * L / v);
  std::printf("entrance + friction: speed %.4f m/s against %.4f (%+.2e); the cubic law alone %.4f\n", r.speed, v,
              r.speed / v - 1, cubic);
  EXPECT_NEAR(r.speed / v, 1.0, 0.01);
  EXPECT_GT(cubic / v - 1, 0.2);  // the entrance is what the 1% tests
  EXPECT_NEAR(r.mouth, p_in - a * v * v, 0.01 * p_in);
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
