// Verification of the flow-rate inlet and mass conservation.
//
// A crack that starts closed (a 1e-5 m pre-opening at the mouth) opens as
// w(s, t) = w_m(t) sqrt(1 - (s / l(t))^2) with w_m = 1 mm (t / T)^(1/3) and
// grows from l = 0.1 m to 0.5 m, crack particles appended at the tip one
// every h = 1 cm (a prescribed, KGD-like opening; no solid). Fluid enters at
// Q(t) = Q0 ramped linearly over T/10, then held. References:
// - injected volume = integral of Q dt = Q0 (T - T/20) (the trapezoid rule is
//   exact for the piecewise-linear Q when the kink falls on a step end):
//   asserted to 1e-12 relative (round-off);
// - mass: sum of the particle masses = rho0 x injected volume, to round-off
//   (1e-12 relative) at every step, through seeding, splits and appended nodes;
// - the pressure handed to the solid is >= 0 everywhere and 0 beyond the front.
#include <gtest/gtest.h>

#include <cmath>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {
namespace {

constexpr double kH = 0.01;  // m, crack particle spacing

CrackGeometry opening_crack(double t, double T) {
  const double l = 0.1 + 0.4 * t / T, w_m = 1e-3 * std::cbrt(t / T);
  const int cells = static_cast<int>(std::floor(l / kH + 1e-9));
  std::vector<double> s, w;
  for (int i = 0; i <= cells; ++i) {
    s.push_back(i * kH);
    const double x = std::min(1.0, s.back() / l);
    w.push_back(w_m * std::sqrt(1 - x * x));
  }
  return test::straight_crack(s, w);
}

TEST(FlowRateInlet, ConservesMassWhileTheCrackGrows) {
  const double T = 0.01, Q0 = 1e-2, rho = 1000;
  FluidConfig c;
  c.density = rho;
  c.viscosity = 0.1;
  c.inlet.kind = InletConfig::Kind::FlowRate;
  c.inlet.flow_rate = TimeFunction::table({0, 0.1 * T}, {0, Q0});
  c.inlet.pre_opening = 1e-5;
  c.inlet.pre_opening_length = 0;
  FluidSolver fluid(c);
  const int exchanges = 1000;
  const double dt = T / exchanges;  // the coupler's step; the fluid subcycles
  double worst_mass = 0, min_pressure = 0;
  std::size_t max_particles = 0;
  int substeps = 0;
  for (int n = 0; n < exchanges; ++n) {
    const auto crack = opening_crack(n * dt, T);
    fluid.set_crack(crack);
    substeps += fluid.advance(dt);
    worst_mass = std::max(worst_mass, std::abs(fluid.fluid_mass() - fluid.injected_mass()));
    max_particles = std::max(max_particles, fluid.particles().size());
    const auto message = fluid.pressure_message();
    ASSERT_EQ(message.ids, crack.ids);
    for (std::size_t i = 0; i < message.size(); ++i) {
      min_pressure = std::min(min_pressure, message.pressure[i]);
      if (fluid.grid().arc()[i] > message.front_position + 1e-9) {
        ASSERT_EQ(message.pressure[i], 0.0) << "node " << i << " beyond the front at step " << n;
      }
    }
  }
  EXPECT_NEAR(fluid.time(), T, 1e-12 * T);  // subcycling lands on the exchange times
  EXPECT_GT(substeps, exchanges);           // and did subcycle
  const double exact = Q0 * (T - 0.05 * T);
  const double volume_error = fluid.injected_volume() / exact - 1;
  const double mass_error = worst_mass / (rho * exact);
  std::printf("flow-rate inlet: %d substeps, %zu crack nodes (from 11), up to %zu particles, front %.3f m\n", substeps,
              fluid.grid().size(), max_particles, fluid.front_position());
  std::printf(
      "flow-rate inlet: injected volume error %+.3e, worst |sum m_p - injected mass| %.3e of the mass, "
      "fluid volume / injected %.6f, inlet pressure %.3e Pa, min nodal pressure %.1e Pa\n",
      volume_error, mass_error, fluid.fluid_volume() / fluid.injected_volume(), fluid.inlet_pressure(), min_pressure);
  EXPECT_LT(std::abs(volume_error), 1e-12);
  EXPECT_LT(mass_error, 1e-12);
  EXPECT_GT(fluid.grid().size(), 40u);                       // nodes were appended
  EXPECT_GT(max_particles, 20u);                             // the inlet particle was split many times
  EXPECT_LT(fluid.front_position(), fluid.grid().length());  // a lag zone ahead of the fluid
  EXPECT_GE(min_pressure, 0.0);
  EXPECT_NEAR(fluid.pressure_message().inlet_flux, Q0, 1e-9 * Q0);
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
