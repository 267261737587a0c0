// Verification: a pressure pulse in a nearly inviscid rigid channel travels at
// the sound speed c = sqrt(K / rho) (the telegraph equation
// p_tt + p_t / tau = c^2 p_ss with tau = rho w^2 / (12 mu) >> the travel time;
// e.g. Lighthill, "Waves in fluids", 1.1). The inlet pressure is a triangular
// pulse of amplitude 1e4 Pa (1e4 / K = 5e-6: linear acoustics) and duration
// 0.1 L / c; the arrival time at two stations is the time centroid of the
// nodal pressure there, integral p t dt / integral p dt, which numerical
// dispersion spreads but does not shift. Asserted within 2% (PIC: every
// resolution; FLIP: from 200 cells, see below).
#include <gtest/gtest.h>

#include <cmath>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {
namespace {

double measured_speed(int cells, double flip) {
  const double L = 1.0, w = 1e-3, rho = 1000, K = 2.2e9, amplitude = 1e4;
  const double c0 = std::sqrt(K / rho), duration = 0.1 * L / c0;
  FluidConfig c;
  c.density = rho;
  c.bulk_modulus = K;
  c.viscosity = 1e-6;  // tau = rho w^2 / (12 mu) = 83 s, the run lasts < 1 ms
  c.flip = flip;
  c.particle_length = 0.5 * L / cells;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::table({0, 0.5 * duration, duration}, {0, amplitude, 0});
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(L, cells, w));
  fluid.fill(L, 0.0);
  const std::size_t i1 = static_cast<std::size_t>(0.3 * cells), i2 = static_cast<std::size_t>(0.6 * cells);
  const double s1 = fluid.grid().arc()[i1], s2 = fluid.grid().arc()[i2];
  // Until the pulse has passed s2 (and before its reflection from the front returns).
  const double t_end = (s2 + 0.25 * L) / c0 + duration;
  double m1 = 0, mt1 = 0, m2 = 0, mt2 = 0;
  while (fluid.time() < t_end) {
    const double dt = fluid.stable_dt();
    fluid.step(dt);
    const double t = fluid.time();
    m1 += fluid.nodal_pressure()[i1] * dt;
    mt1 += fluid.nodal_pressure()[i1] * t * dt;
    m2 += fluid.nodal_pressure()[i2] * dt;
    mt2 += fluid.nodal_pressure()[i2] * t * dt;
  }
  return (s2 - s1) / (mt2 / m2 - mt1 / m1);
}

TEST(Wave, PulseTravelsAtTheSoundSpeed) {
  const double c0 = std::sqrt(2.2e9 / 1000);
  for (double flip : {0.0, 1.0}) {
    for (int cells : {100, 200, 400}) {
      const double error = measured_speed(cells, flip) / c0 - 1;
      std::printf("wave speed: %s, %d cells, error %+.3e\n", flip > 0 ? "FLIP" : "PIC", cells, error);
      // PIC (the default) at every resolution. Pure FLIP rings behind the
      // pulse; at p = 0 the no-tension limit clips the negative half of the
      // ringing, which biases the arrival time at coarse resolution (-1.8% at
      // 100 cells), so it is held to 2% from 200 cells.
      if (flip == 0 || cells >= 200) {
        EXPECT_LT(std::abs(error), 0.02);
      }
    }
  }
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
