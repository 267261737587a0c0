// Verification of the fluid in rigid channels (the crack width held fixed).
//
// 1. Poiseuille: steady laminar flow through a channel of constant width w and
//    length L between a pressure inlet p_in at the mouth and an outlet at
//    p = 0 obeys the cubic law q = w^3 / (12 mu) (p_in - p_out) / L (plane
//    Poiseuille flow, e.g. Batchelor, "An introduction to fluid dynamics",
//    4.2; Witherspoon et al. 1980 for fractures), with a linear pressure
//    profile. Started from rest; steady after a few diffusion times
//    L^2 / D, D = K w^2 / (12 mu). Asserted within 1% (flux) and, at 40
//    cells, 1% of p_in (nodal pressure profile); compressibility changes the volume flux by ~ p_in / K = 5e-5.
//    Non-uniform grid (spacings varying ~2.3x), particles straddling nodes.
//    The same with a flow-rate inlet Q (ramped over ~tau): the mouth pressure
//    is 12 mu Q L / w^3 within 1%, nodal pressures within 2% of it at all
//    times once steady (the inlet particle's split cycle makes a small
//    sawtooth near the mouth), the outflow equals Q within 1%.
//    Filling: a channel holding a column of length x_0 at rest is filled
//    from a pressure inlet, with p = 0 ahead of the front (no lag in a rigid
//    channel): the cubic law with a moving front, x_f dx_f/dt =
//    w^2 p_in / (12 mu), gives x_f^2 = x_0^2 + w^2 p_in t / (6 mu) (valid for
//    t >> tau = rho w^2 / (12 mu) and p_in << K). Asserted within 1% until the
//    front has travelled 0.4 m, no worse under refinement. (Started from an
//    empty crack, the seed particle's start-up adds ~0.3% that depends on the
//    seed length, not on the grid.)
// 2. Equilibrium: a fluid at rest under a uniform pressure in a crack whose
//    width tapers linearly to zero at the tip (the fluid front) stays at
//    rest: the force p dw/ds of the inclined faces balances -d(p w)/ds. Checked
//    to round-off.
// 3. A widening channel: the faces of a channel of length L closed at its far
//    end part at a uniform rate dw/dt, and a pressure inlet fills it. The
//    fluid must bring the new volume in, so its velocity is linear along the
//    channel, v = alpha (L - s), alpha = (dw/dt) / w, and the momentum balance
//    rho (dv/dt + v dv/ds) = -dp/ds - 12 mu v / w^2 (alpha' = -alpha^2) gives
//    p(s) = p_in - rho (alpha L)^2 / 2 + C (L s - s^2 / 2), C = 2 rho alpha^2 -
//    12 mu alpha / w^2 (the mouth below the well's p_in by the inflow's
//    rho v^2 / 2, tests/fluid/pressure_inlet_test.cpp).
//    A linear velocity is what plain PIC averages away at every step: a loss
//    per step, which acts as a drag of order 1 / dt and, at the steps here,
//    puts the nodal pressures 12% and 25% of the drop off with rho = 100 (41%
//    and 81% with water's density; more the smaller the step). With the affine
//    transfer (APIC), for rho = 100, the profile is asserted within 1% of the
//    drop at two steps and falling with the grid, and PIC is checked to miss
//    it by ten times that; with water's density APIC misses by 3.5%, an
//    excess not explained (below), held below 5%.
// 4. No tension: crack faces pulled apart quickly (width doubling in a few
//    steps) leave every particle and nodal pressure >= 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "channel.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {
namespace {

struct PoiseuilleResult {
  double flux_error;     // relative, inlet volume flux vs the cubic law
  double outflux_error;  // relative, outlet volume flux vs the cubic law
  double profile_error;  // max |p_i - p_linear(s_i)| / p_in over the nodes
};

// Nodes with spacings varying by a factor ~2.3 (1 +- 0.4 sin), as a
// published crack would have them.
std::vector<double> uneven_nodes(double length, int cells) {
  std::vector<double> s{0.0};
  for (int i = 0; i < cells; ++i) s.push_back(s.back() + 1 + 0.4 * std::sin(2.3 * i));
  for (double& x : s) x *= length / s.back();
  return s;
}

PoiseuilleResult poiseuille(int cells, bool smooth_jacobian = true) {
  const double L = 1.0, w = 1e-3, mu = 1.0, p_in = 1e5;
  FluidConfig c;
  c.density = 1000;
  c.bulk_modulus = 2.2e9;
  c.viscosity = mu;
  c.smooth_jacobian = smooth_jacobian;
  c.particle_length = 0.37 * L / cells;  // particles straddle nodes
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(p_in);
  c.outlet.enabled = true;
  c.outlet.pressure = TimeFunction::constant(0);
  FluidSolver fluid(c);
  const auto nodes = uneven_nodes(L, cells);
  fluid.set_crack(test::straight_crack(nodes, std::vector<double>(nodes.size(), w)));
  fluid.fill(L, 0.0);
  const double D = c.bulk_modulus * w * w / (12 * mu);
  const double t_steady = 2.0 * L * L / D;  // slowest mode decays as exp(-pi^2 D t / L^2): e^-20
  while (fluid.time() < t_steady) fluid.advance(fluid.stable_dt());
  // Fluxes averaged over a further 1% of the run.
  const double m_in = fluid.injected_mass(), m_out = fluid.outflow_mass(), t0 = fluid.time();
  while (fluid.time() < 1.01 * t_steady) fluid.advance(fluid.stable_dt());
  const double dt = fluid.time() - t0;
  const double q_in = (fluid.injected_mass() - m_in) / (c.density * dt);
  const double q_out = (fluid.outflow_mass() - m_out) / (c.density * dt);
  const double q_exact = w * w * w / (12 * mu) * p_in / L;
  double profile = 0;
  const auto& p = fluid.nodal_pressure();
  for (std::size_t i = 0; i < p.size(); ++i) {
    profile = std::max(profile, std::abs(p[i] - p_in * (1 - fluid.grid().arc()[i] / L)) / p_in);
  }
  return {q_in / q_exact - 1, q_out / q_exact - 1, profile};
}

TEST(Poiseuille, SteadyFluxFollowsTheCubicLaw) {
  double previous_profile = 1;
  for (int cells : {10, 20, 40}) {
    const auto r = poiseuille(cells);
    std::printf(
        "Poiseuille: %d cells, inlet flux error %+.3e, outlet flux error %+.3e, max profile error %.3e of p_in\n",
        cells, r.flux_error, r.outflux_error, r.profile_error);
    EXPECT_LT(std::abs(r.flux_error), 0.01);
    EXPECT_LT(std::abs(r.outflux_error), 0.01);
    // Nodal pressures: the lumped (mass-weighted) projection of the element
    // pressures is first order on an uneven grid, off by ~ (h_i - h_{i-1}) / 4.
    EXPECT_LT(r.profile_error, previous_profile * 0.7);
    previous_profile = r.profile_error;
    if (cells >= 40) {
      EXPECT_LT(r.profile_error, 0.01);
    }
  }
}

TEST(Poiseuille, PerParticlePressureOptionToo) {
  const auto r = poiseuille(20, false);
  std::printf("Poiseuille, per-particle J: 20 cells, inlet flux error %+.3e, max profile error %.3e of p_in\n",
              r.flux_error, r.profile_error);
  EXPECT_LT(std::abs(r.flux_error), 0.01);
  EXPECT_LT(r.profile_error, 0.03);
}

struct FlowRateResult {
  double inlet_error;    // relative, time-mean mouth pressure vs 12 mu Q L / w^3
  double outflux_error;  // relative, outlet flux vs Q
  double worst_profile;  // max over nodes and the last 20% of the run of |p_i - p_exact(s_i)| / p_in
};

FlowRateResult flow_rate_channel(int cells) {
  const double L = 0.2, w = 1e-3, mu = 0.1, Q = 1e-2;
  const double v = Q / w, flush = L / v;  // 10 m/s, 20 ms to cross the channel
  FluidConfig c;
  c.viscosity = mu;
  c.inlet.kind = InletConfig::Kind::FlowRate;
  c.inlet.flow_rate = TimeFunction::table({0, 0.05 * flush}, {0, Q});  // ramp over ~ tau = rho w^2 / (12 mu)
  c.outlet.enabled = true;
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(L, cells, w));
  fluid.fill(L, 0.0);
  const double dpds = 12 * mu * Q / (w * w * w), p_in = dpds * L;
  double worst = 0, p_sum = 0, t_sum = 0, m_out = 0, t_out = 0;
  while (fluid.time() < 1.5 * flush) {
    const double dt = fluid.stable_dt();
    fluid.advance(dt);
    if (fluid.time() < 1.2 * flush) continue;
    if (t_sum == 0) {
      m_out = fluid.outflow_mass();
      t_out = fluid.time();
    }
    p_sum += fluid.inlet_pressure() * dt;
    t_sum += dt;
    for (std::size_t i = 0; i < fluid.grid().size(); ++i) {
      const double exact = dpds * (L - fluid.grid().arc()[i]);
      worst = std::max(worst, std::abs(fluid.nodal_pressure()[i] - exact) / p_in);
    }
  }
  const double q_out = (fluid.outflow_mass() - m_out) / (c.density * (fluid.time() - t_out));
  return {p_sum / t_sum / p_in - 1, q_out / Q - 1, worst};
}

TEST(Poiseuille, FlowRateInletPressureFollowsTheCubicLaw) {
  double previous = 1;
  for (int cells : {20, 40}) {
    const auto r = flow_rate_channel(cells);
    std::printf(
        "Poiseuille, flow-rate inlet: %d cells, mouth pressure error %+.3e, outlet flux error %+.3e, "
        "max nodal deviation %.3e of p_in\n",
        cells, r.inlet_error, r.outflux_error, r.worst_profile);
    EXPECT_LT(std::abs(r.inlet_error), 0.01);
    EXPECT_LT(std::abs(r.outflux_error), 0.01);
    EXPECT_LT(r.worst_profile, 0.02);
    EXPECT_LT(r.worst_profile, previous);
    previous = r.worst_profile;
  }
}

// Returns the relative error of the front position at the end.
double filling_front_error(int cells, double* front_out) {
  const double L = 0.4, w = 1e-3, mu = 0.1, p_in = 1e5;
  FluidConfig c;
  c.viscosity = mu;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(p_in);
  FluidSolver fluid(c);
  fluid.set_crack(test::channel(L, cells, w));
  const double x0 = 0.1 * L;  // a short column at rest: the start-up transient (~tau) stays small
  fluid.fill(x0, 0.0);
  const double t_end = 6 * mu * 0.25 * L * L / (w * w * p_in);  // the front reaches about L/2
  while (fluid.time() < t_end) fluid.advance(fluid.stable_dt());
  const double exact = std::sqrt(x0 * x0 + w * w * p_in * fluid.time() / (6 * mu));
  *front_out = fluid.front_position();
  return fluid.front_position() / exact - 1;
}

TEST(Filling, FrontFollowsTheCubicLawFromAPressureInlet) {
  double previous = 1;
  for (int cells : {20, 40}) {
    double front = 0;
    const double error = filling_front_error(cells, &front);
    std::printf("filling from a pressure inlet: %d cells, front %.4f m, front error %+.3e\n", cells, front, error);
    EXPECT_LT(std::abs(error), 0.01);
    EXPECT_LT(std::abs(error), previous * 1.05);  // no worse under refinement
    previous = std::abs(error);
  }
}

TEST(Equilibrium, UniformPressureInATaperingCrackStaysAtRest) {
  const double L = 1.0, w_mouth = 1e-3, p0 = 2e6;
  const int cells = 16;
  const auto s = test::uniform_nodes(L, cells);
  std::vector<double> width(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) width[i] = w_mouth * (1 - s[i] / L);  // closes at the tip
  FluidConfig c;
  c.viscosity = 1e-3;
  c.particle_length = 0.3 * L / cells;  // particles straddle nodes too
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(p0);
  FluidSolver fluid(c);
  fluid.set_crack(test::straight_crack(s, width));
  fluid.fill(L, p0);
  const double mass = fluid.fluid_mass();
  for (int k = 0; k < 500; ++k) fluid.step(fluid.stable_dt());
  double vmax = 0, pdev = 0;
  for (std::size_t p = 0; p < fluid.particles().size(); ++p) {
    vmax = std::max(vmax, std::abs(fluid.particles().velocity[p]));
    pdev = std::max(pdev, std::abs(fluid.particles().pressure[p] - p0) / p0);
  }
  // Scale: an unbalanced force p0 w_mouth / L per unit length would accelerate
  // the fluid at p0 / (rho L) = 2e3 m/s^2, i.e. ~1 m/s within these 500 steps.
  std::printf("Tapering crack at rest: max speed %.3e m/s, max pressure change %.3e of p0 after 500 steps\n", vmax,
              pdev);
  EXPECT_LT(vmax, 1e-9);
  EXPECT_LT(pdev, 1e-9);
  EXPECT_NEAR(fluid.fluid_mass(), mass, 1e-13 * mass);
}

// The worst |p_i - p(s_i)| over the nodes, as a fraction of the exact drop
// p_in - p(L), at t_end in a channel widening from w0 at dw/dt.
double widening_channel_error(bool affine, double cfl, double rho, int cells = 20) {
  const double L = 1.0, w0 = 1e-3, rate = 1e-3, mu = 0.01, p_in = 2e5, t_end = 0.1;
  FluidConfig c;
  c.density = rho;
  c.bulk_modulus = 2e8;
  c.viscosity = mu;
  c.cfl = cfl;
  c.affine = affine;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(p_in);
  FluidSolver fluid(c);
  const auto s = test::uniform_nodes(L, cells);
  fluid.set_crack(test::straight_crack(s, std::vector<double>(s.size(), w0)));
  fluid.fill(L, p_in);
  double t = 0;
  while (t < t_end - 1e-12) {
    const double dt = std::min(fluid.stable_dt(), t_end - t);
    fluid.step(dt);
    t += dt;
    fluid.set_crack(test::straight_crack(s, std::vector<double>(s.size(), w0 + rate * t)));
  }
  const double w = w0 + rate * t, alpha = rate / w;
  const double C = 2 * rho * alpha * alpha - 12 * mu * alpha / (w * w);
  const double drop = -C * L * L / 2;
  double worst = 0;
  for (std::size_t i = 1; i + 1 < s.size(); ++i) {  // the closed end's node carries the lag rule's 0
    // The mouth's static pressure is the well's less the inflow's rho v^2 / 2, v = alpha L.
    const double exact = p_in - 0.5 * rho * alpha * alpha * L * L + C * (L * s[i] - 0.5 * s[i] * s[i]);
    worst = std::max(worst, std::abs(fluid.nodal_pressure()[i] - exact) / drop);
  }
  return worst;
}

TEST(WideningChannel, LinearInflowKeepsItsMomentumUnderTheAffineTransfer) {
  // A light fluid (rho = 100: the inertial terms are 0.2% of the drop): the
  // transfer alone. Measured 0.32% at 20 cells, 0.21% at 40, 0.08% at 80.
  const double apic = widening_channel_error(true, 0.5, 100), apic_half = widening_channel_error(true, 0.25, 100);
  const double pic = widening_channel_error(false, 0.5, 100), pic_half = widening_channel_error(false, 0.25, 100);
  const double finer = widening_channel_error(true, 0.5, 100, 40);
  std::printf(
      "widening channel, rho = 100, worst nodal pressure error / drop: APIC %.4f (cfl 0.5), %.4f (0.25), "
      "%.4f (40 cells); PIC %.4f, %.4f\n",
      apic, apic_half, finer, pic, pic_half);
  EXPECT_LT(apic, 0.01);
  EXPECT_LT(apic_half, 0.01);
  EXPECT_LT(finer, apic);
  EXPECT_GT(pic, 10 * apic);       // the per-step loss the affine transfer removes,
  EXPECT_GT(pic_half, 1.5 * pic);  // which grows as the step shrinks
  // Water's density (the inertial terms 1.8% of the drop): measured 3.5% at
  // 20 cells, 3.3% at 40, 3.7% at 80, the same at half the step (and 3.3%
  // with the faces parting exponentially, alpha constant, where inertia is
  // 1.0% of the drop): the closed end's pressure stands above the exact one,
  // as if the inertial terms counted three to four times. With the mouth at
  // the well's pressure less the inflow's rho v^2 / 2 (0.9% of the drop, in
  // the exact profile too) 3.2% at 20 cells. Not explained; held here so
  // that it does not grow.
  const double water = widening_channel_error(true, 0.5, 1000);
  std::printf("widening channel, rho = 1000: APIC %.4f\n", water);
  EXPECT_LT(water, 0.05);
}

TEST(NoTension, FacesPulledApartGiveNoNegativePressure) {
  const double L = 1.0, w = 1e-4, p0 = 1e6;
  const int cells = 20;
  FluidConfig c;
  c.viscosity = 1e-3;
  c.inlet.kind = InletConfig::Kind::FlowRate;
  c.inlet.flow_rate = TimeFunction::constant(0);
  FluidSolver fluid(c);
  const auto s = test::uniform_nodes(L, cells);
  fluid.set_crack(test::straight_crack(s, std::vector<double>(s.size(), w)));
  fluid.fill(0.8 * L, p0);  // compressed, with a dry zone ahead of the front
  double min_p = 0, max_J = 0;
  for (int k = 0; k < 200; ++k) {
    // The faces open by 1% per step, faster near the tip: J grows well above 1.
    std::vector<double> width(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) width[i] = w * std::pow(1 + 0.01 * (1 + s[i]), k + 1);
    fluid.set_crack(test::straight_crack(s, width));
    fluid.step(fluid.stable_dt());
    for (std::size_t p = 0; p < fluid.particles().size(); ++p) {
      min_p = std::min(min_p, fluid.particles().pressure[p]);
      max_J = std::max(max_J, fluid.particles().jacobian(p));
    }
    for (double p : fluid.nodal_pressure()) min_p = std::min(min_p, p);
  }
  std::printf("No tension: max J %.3f, min pressure %.3e Pa\n", max_J, min_p);
  EXPECT_GT(max_J, 2.0);  // the faces really did pull away
  EXPECT_GE(min_p, 0.0);
  for (double p : fluid.nodal_pressure()) EXPECT_EQ(p, 0.0);  // fully cavitated now
}

}  // namespace
}  // namespace hfmpm::fluid::mpm
