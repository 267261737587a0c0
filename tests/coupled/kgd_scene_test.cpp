// The real solid and the real fluid coupled.
//
// scenarios/kgd-toughness.scene, shortened to 0.6 s, through `hfmpm run`:
// the start of the run, before the crack is three notch lengths long (the
// K-vertex comparison of the full run is in docs/verification.md, "Coupled
// KGD"). It holds what the coupled run must get right from the start:
// - the fluid's mass: the injected volume equals the integral of the inlet
//   ramp Q(t) (4.15e-4 (t - 0.025) once the 0.05 s ramp is over; exact to the
//   trapezoid error of the substep holding the ramp's kink);
// - the fluid's volume (sum of l w) within 10% of its zero-pressure volume
//   (injected plus initial): the compression at the pressures reached is
//   under 6%, and partly filled particles (J > 1, at zero pressure) count
//   empty space;
// - the run is stable and quasi-static: no NaN, the kinetic energy stays
//   below 1e-2 of the work the inlet pressure has done (measured: ~1e-4);
// - the fracture is driven: the inlet pressure rises above the confining
//   stress once the ramp is over, the mouth opens, and the crack grows.
#include <algorithm>
#include <cmath>
#include <future>
#include <string>
#include <vector>

#include "coupled_support.hpp"
#include "h5_reader.hpp"

namespace hfmpm::test {
namespace {

// The columns of a KGD run's history.csv that the checks use.
struct KgdHistory {
  std::vector<double> t, length, mouth, p_in, injected, volume, ke;
  double dt_max = 0;  // the largest coupled step, s
};
KgdHistory read_kgd_history(const std::string& out) {
  const Csv h = read_csv(out + "/history.csv");
  KgdHistory k{h.values("time_s"),
               h.values("crack_length_m"),
               h.values("mouth_opening_m"),
               h.values("inlet_pressure_pa"),
               h.values("injected_volume_m2"),
               h.values("fluid_volume_m2"),
               h.values("kinetic_energy_j")};
  const auto dt = h.values("dt_s");
  k.dt_max = dt.empty() ? 0.0 : *std::max_element(dt.begin(), dt.end());
  return k;
}

// Volume injected by time t by a rate ramped linearly from 0 to q over
// `ramp` s, and the tolerance on it: the inlet integrates the rate by the
// trapezoid rule per fluid substep, exact but for the substep holding the
// ramp's kink, which errs by at most (q / ramp) dt^2 / 8 (dt <= the coupled
// step; measured 2.3e-13 m^2), plus round-off.
double ramp_volume(double q, double ramp, double t) {
  return t >= ramp ? q * (t - 0.5 * ramp) : 0.5 * q * t * t / ramp;
}
double ramp_tolerance(double q, double ramp, double dt_max) { return q / ramp * dt_max * dt_max / 8 + 1e-9 * q; }

TEST(KgdScene, ToughnessSceneRunsStablyConservesFluidAndGrows) {
  const auto out = scratch_dir("kgd_toughness");
  std::string text = read_file(source("scenarios/kgd-toughness.scene"));
  text = replace_once(text, "end_s: 10", "end_s: 1.2");  // the K-vertex reaches the 0.2 m notch at ~0.9 s
  text = replace_once(text, "interval_s: 0.25", "interval_s: 0.05");
  const auto result = run_scene(text, out, {"--set", "output.hdf5=false"}, 900);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto [t, length, mouth, p_in, injected, volume, ke, dt_max] = read_kgd_history(out);
  ASSERT_GE(t.size(), 10u);
  constexpr double kQ = 4.15e-4, kRamp = 0.05, kSigma0 = 1e5, kK = 2e9, kC = 0.0894;  // water
  constexpr double kInitial = 0.2 * 2e-5;  // the notch's fluid at 1e5 Pa: the virtual film x 0.2 m
  double work = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    for (double v : {length[i], mouth[i], p_in[i], injected[i], volume[i], ke[i]}) ASSERT_TRUE(std::isfinite(v));
    EXPECT_NEAR(injected[i], ramp_volume(kQ, kRamp, t[i]), ramp_tolerance(kQ, kRamp, dt_max)) << "t = " << t[i];
    if (i > 0) work += 0.5 * (p_in[i] + p_in[i - 1]) * (injected[i] - injected[i - 1]);
    if (t[i] > 0.1) {
      EXPECT_LT(ke[i], 1e-2 * work) << "t = " << t[i];
    }
    const double zero_pressure_volume = injected[i] + kInitial / (1 - kC * std::log1p(kSigma0 / (kC * kK)));
    EXPECT_NEAR(volume[i] / zero_pressure_volume, 1, 0.1) << "t = " << t[i];
  }
  std::printf(
      "kgd-toughness to %.2f s: length %.3f m, mouth opening %.3e m, inlet pressure %.0f Pa, "
      "max kinetic energy / inlet work %.2e\n",
      t.back(), length.back(), mouth.back(), p_in.back(), *std::max_element(ke.begin(), ke.end()) / work);
  EXPECT_GT(p_in.back(), kSigma0);
  EXPECT_GT(mouth.back(), 5e-4);
  // At least one growth step of a quarter cell (0.0125 m). Measured with water
  // 0.262 m (the K-vertex 0.240 m at 1.2 s less half the ramp); the former 2 MPa
  // fluid grew the notch by 0.6 s already (0.212 m), before the vertex says.
  EXPECT_GE(length.back(), 0.2 + 0.01);
  for (std::size_t i = 1; i < t.size(); ++i) EXPECT_GE(length[i], length[i - 1] - 1e-3) << "t = " << t[i];
}

// The M-vertex (zero toughness, zero lag; Spence and Sharp 1985, Adachi and
// Detournay 2002) for the total rate Q: half-length, mouth opening and net
// inlet pressure at time t.
struct Vertex {
  double length, opening, pressure;
};
Vertex m_vertex(double E, double nu, double mu, double Q, double t) {
  const double ep = E / (1 - nu * nu), mup = 12 * mu;
  return {0.6152 * std::pow(ep * Q * Q * Q * t * t * t * t / mup, 1.0 / 6),
          1.126 * std::pow(mup * Q * Q * Q * t * t / ep, 1.0 / 6), 0.545 * std::cbrt(mup * ep * ep / t)};
}

TEST(KgdScene, MVertexReference) {
  // The numbers the issue quotes for the full-size scene at 10 s.
  const Vertex v = m_vertex(1e7, 0.25, 0.01, 2.5e-4, 10);
  EXPECT_NEAR(v.length, 0.954, 1e-3);
  EXPECT_NEAR(v.opening, 1.82e-3, 1e-5);
  EXPECT_NEAR(v.pressure, 6.05e3, 10);
}

// The K-vertex (zero viscosity: uniform pressure, Sneddon's ellipse, LEFM and
// the volume balance) for the total rate Q.
Vertex k_vertex(double E, double nu, double KIc, double Q, double t) {
  const double ep = E / (1 - nu * nu), kp = std::sqrt(32 / 3.141592653589793) * KIc, pi = 3.141592653589793;
  return {2 / std::pow(pi, 2.0 / 3) * std::pow(ep * Q * t / kp, 2.0 / 3),
          std::pow(pi, -1.0 / 3) * std::cbrt(kp * kp * Q * t / (ep * ep)),
          std::cbrt(pi) / 8 * std::cbrt(kp * kp * kp * kp / (ep * Q * t))};
}

TEST(KgdScene, KVertexReference) {
  // The numbers the issue quotes for the full-size toughness scene at 10 s.
  const Vertex v = k_vertex(1e7, 0.25, 25e3, 8.3e-4, 10);
  EXPECT_NEAR(v.length, 0.999, 1e-3);
  EXPECT_NEAR(v.opening, 5.29e-3, 1e-5);
  EXPECT_NEAR(v.pressure, 14.1e3, 50);
}

// A CI-size KGD scene as it stands (5 s, h = 0.035 m, notch 0.15 m, a 0.05 s
// ramp to Q in total): once the crack is three notch lengths long,
// half-length and mouth opening within the CI-size 10% of the
// vertex solution and the net inlet pressure within 20% (time shifted by
// half the ramp). Also: the injected volume is the integral of the ramp; the
// fluid's volume is its zero-pressure volume less a compression of at most
// the Tait J at the run's highest inlet pressure; the run stays quasi-static.
struct Bounds {
  double length = 0.10, opening = 0.10, pressure = 0.20;  // the CI-size bounds
  // How far the fluid's volume may fall below its compressed zero-pressure
  // volume: the implicit step's misfit at a row the tip grew in (the fluid's
  // state is read at the crack the solid published, which growth changed
  // within the step). 0 unless a run is measured to need it.
  double volume_misfit = 0;
  // 2: both wings modelled, the fluid entering at the crack's inlet vertex at
  // x = 0 (no symmetry plane): Q all into the crack, the half-length half the
  // crack, the notch's fluid twice; and the wings' lengths from x = 0 (from
  // solid.h5): from three notch lengths on, their difference within `apart`
  // of their mean on average over the frames, and within `apart_cells` cells
  // (h = 0.035 m) at every frame.
  int wings = 1;
  double apart = 0.02, apart_cells = 0.5;
};

// (start wing, end wing) lengths from x = 0 at every frame of a run's solid.h5.
std::vector<std::pair<double, double>> wing_lengths(const std::string& out) {
  H5Reader h5(out + "/solid.h5");
  std::vector<std::pair<double, double>> wings;
  for (const auto& frame : h5.children("/frames")) {
    const auto x = h5.f64("/frames/" + frame + "/crack0/positions");  // n x 2, row-major
    wings.emplace_back(-x.front(), x[x.size() - 2]);
  }
  return wings;
}

template <class Reference>
void expect_ci_scene_follows(const std::string& scene, double Q, Reference reference, double bulk_modulus = 2e6,
                             std::vector<std::string> sets = {}, Bounds bounds = {}) {
  const auto out = scratch_dir("kgd_ci");
  std::vector<std::string> args;
  if (bounds.wings == 1) args = {"--set", "output.hdf5=false"};  // two wings: their tips from solid.h5
  args.insert(args.end(), sets.begin(), sets.end());
  const auto result = run_scene(read_file(source(scene)), out, args, 900);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto [t, length, mouth, p_in, injected, volume, ke, dt_max] = read_kgd_history(out);
  ASSERT_GE(t.size(), 20u);
  ASSERT_NEAR(t.back(), 5, 1e-3);
  constexpr double kRamp = 0.05, kSigma0 = 1e5, kNotch = 0.15;
  const double kInitial = bounds.wings * kNotch * 2e-5;  // the notch's fluid: the virtual film x 0.15 m per wing
  const double p_max = *std::max_element(p_in.begin(), p_in.end());
  const double j_min = 1 - 0.0894 * std::log1p(p_max / (0.0894 * bulk_modulus));  // Tait, c = 0.0894
  double work = 0, worst_length = 0, worst_opening = 0, worst_pressure = 0;
  int compared = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    for (double v : {length[i], mouth[i], p_in[i], injected[i], volume[i], ke[i]}) ASSERT_TRUE(std::isfinite(v));
    const double q = bounds.wings * 0.5 * Q;  // into the modelled wing, or both
    EXPECT_NEAR(injected[i], ramp_volume(q, kRamp, t[i]), ramp_tolerance(q, kRamp, dt_max)) << "t = " << t[i];
    if (i > 0) work += 0.5 * (p_in[i] + p_in[i - 1]) * (injected[i] - injected[i - 1]);
    if (t[i] > 0.1) {
      EXPECT_LT(ke[i], 1e-2 * work) << "t = " << t[i];
      const double ratio = volume[i] / (injected[i] + kInitial);
      EXPECT_GT(ratio, j_min - bounds.volume_misfit) << "t = " << t[i];
      // Above 1 only by a particle at zero pressure stretched past its rest
      // volume (J > 1: the liquid cavitates rather than carry tension), whose
      // domain then counts some empty crack: water's front particle early on
      // (measured 1.0116 at 0.25 s, 1.0033 at 0.5 s, below 1.0001 from 0.75 s).
      EXPECT_LT(ratio, t[i] < 1 ? 1.02 : 1.001) << "t = " << t[i];
    }
    const double half = length[i] / bounds.wings;
    if (half < 3 * kNotch) continue;
    const Vertex v = reference(t[i] - 0.5 * kRamp);
    const double e_length = half / v.length - 1, e_opening = mouth[i] / v.opening - 1;
    const double e_pressure = (p_in[i] - kSigma0) / v.pressure - 1;
    std::printf("t %.2f s: half-length %+.3f, mouth opening %+.3f, net inlet pressure %+.3f\n", t[i], e_length,
                e_opening, e_pressure);
    EXPECT_LT(std::abs(e_length), bounds.length) << "t = " << t[i];
    EXPECT_LT(std::abs(e_opening), bounds.opening) << "t = " << t[i];
    EXPECT_LT(std::abs(e_pressure), bounds.pressure) << "t = " << t[i];
    worst_length = std::max(worst_length, std::abs(e_length));
    worst_opening = std::max(worst_opening, std::abs(e_opening));
    worst_pressure = std::max(worst_pressure, std::abs(e_pressure));
    ++compared;
  }
  std::printf("%s: %d rows compared; worst half-length %.3f, mouth opening %.3f, net inlet pressure %.3f\n",
              scene.c_str(), compared, worst_length, worst_opening, worst_pressure);
  EXPECT_GE(compared, 5);  // the crack reached three notch lengths by ~3.3 s
  if (bounds.wings == 2) {
    const auto wings = wing_lengths(out);
    ASSERT_GE(wings.size(), 10u);
    double worst = 0, sum = 0;
    int frames = 0;
    for (const auto& [start, end] : wings) {
      if (start + end < 6 * kNotch) continue;
      worst = std::max(worst, std::abs(end - start));
      sum += std::abs(end - start) / (0.5 * (start + end));
      ++frames;
    }
    ASSERT_GE(frames, 5);
    std::printf(
        "wings at the end: %.4f m and %.4f m from the inlet; from three notch lengths on (%d frames) "
        "they differ by %.4f of their mean on average and by at most %.4f m\n",
        wings.back().first, wings.back().second, frames, sum / frames, worst);
    EXPECT_LT(sum / frames, bounds.apart);
    // Growth steps are cut in the deformed body, whose strain (the confining
    // stress over E: 1%) stretches them: 2% allowed on top.
    EXPECT_LE(worst, 1.02 * bounds.apart_cells * 0.035);
  }
}

// Viscosity-dominated (Km = 0.023) against the M-vertex, with water, the
// implicit scheme, the tip closure matched to the fluid (lag
// TIP_ASYMPTOTE_MATCHED) and the crack's surfaces from the material, which it
// needs (the scene's defaults since 4 December, thirteenth session, when the
// growth step began to re-derive the strain of the particles it cuts).
// Measured: 3.0%, 3.4% and 8.3% worst, the fluid front within 2.4% (before
// that fix 3.0%, 1.8%, 5.8%, front 2.7%); asserted within 6%, 4% and 10%,
// tighter than the CI bounds, so that the closure's gain in length over the
// former default (next test) stays held; a growth step is 1.4-1.9% of the
// crack at the compared rows. The pressure is 8% low at every row: the
// finite box makes the body 4-5% more compliant than the M-vertex's infinite
// one (a net pressure 3% lower at the same injection), and the virtual film
// eases the flow by (1 + f / w)^3 (docs/verification.md). The fluid's volume
// fell 4.1e-5 below its compression (water: 6e-5 here) at one row where the
// tip had just grown: allowed 1e-4.
TEST(KgdScene, ViscosityCiSceneFollowsTheMVertex) {
  expect_ci_scene_follows("scenarios/kgd-viscosity-ci.scene", 2.5e-4,
                          [](double t) { return m_vertex(1e7, 0.25, 0.01, 2.5e-4, t); }, 2e9, {},
                          {0.06, 0.04, 0.10, 1e-4});
}

// The case of the scene above with both wings modelled and the fluid entering
// at the notch's centre (scenarios/kgd-two-wing-ci.scene; docs/fluid.md,
// "Injection from inside the body"): no symmetry plane, the fluid side
// sharing Q between the wings. Measured (5 December, sixteenth session):
// half-length (half the crack) 2.0%, opening at the wellbore 3.3%, net inlet
// pressure 7.0-8.8% worst, the one-wing scene's figures within a point
// (1.4 junction iterations per step). The wings are equal to 1e-6 m at most
// frames, but a tip's energy criterion is met at one growth check and its
// mirror's at the next when round-off tips J across the toughness, so one
// wing runs a growth step (a quarter cell, 8.75 mm) or two ahead until the
// other catches up: from three notch lengths on, measured 0.55% of their
// mean on average over the frames and 17.5 mm (0.5 cell, 3.0%) at worst.
// Asserted: the one-wing scene's bounds, the pressure's at 12%; the wings
// within 2% of each other on average (the bound, met exactly by
// the full-size scene: docs/verification.md) and within two growth steps.
TEST(KgdScene, TwoWingCiSceneFollowsTheMVertexWithEqualWings) {
  Bounds bounds{0.06, 0.05, 0.12, 1e-4};
  bounds.wings = 2;
  expect_ci_scene_follows(
      "scenarios/kgd-two-wing-ci.scene", 2.5e-4, [](double t) { return m_vertex(1e7, 0.25, 0.01, 2.5e-4, t); }, 2e9, {},
      bounds);
}

// The same with the former defaults: the tip-asymptote closure (lag
// TIP_ASYMPTOTE) and the surfaces integrated from their fields' velocities,
// which read the grown part of the crack 13-16% narrow. Measured (4
// December, thirteenth session): 5.5%, 3.4% and 3.2% worst, the front within
// 0.5% (4.5%, 4.9%, 2.1% before the growth step re-derived the strain of the
// particles it cuts; with the vacuum front, lag FIXED_PRESSURE, and half-cell
// growth 15.9%, 0.5% and 3.9%, the front 7.7% long; docs/verification.md).
TEST(KgdScene, ViscosityCiSceneWithTheVelocitySurfacesFollowsTheMVertex) {
  expect_ci_scene_follows(
      "scenarios/kgd-viscosity-ci.scene", 2.5e-4, [](double t) { return m_vertex(1e7, 0.25, 0.01, 2.5e-4, t); }, 2e9,
      {"--set", "fluid.mpm.lag=TIP_ASYMPTOTE", "--set", "solid.mpm.fracture.surfaces_from_material=false"});
}

// Toughness-dominated (Km = 7.6) against the K-vertex, with water and the
// implicit interface scheme (the scene's defaults since issue 17). Quarter-cell
// growth used to add a crack particle every quarter cell, and the water run
// then failed at 4.9 s (from ~3.6 s every interface solve stopped above
// tolerance); with crack particles half a cell apart (docs/solid.md) it runs
// to the end. Measured: 2.9%, 1.8% and 3.4% worst against the K-vertex (5
// December, with each growth step's face load applied over the settling
// wait, fracture.release_transits; 3.0%, 2.9% and 8.5% with it applied at
// once; docs/verification.md, "The load of a growth step applied as the tip
// advances"); 9.0%, 3.3% and 18.0% before the faces were read from the
// material and the damping set for the crack's own mode.
TEST(KgdScene, ToughnessCiSceneFollowsTheKVertex) {
  expect_ci_scene_follows(
      "scenarios/kgd-toughness-ci.scene", 8.3e-4, [](double t) { return k_vertex(1e7, 0.25, 25e3, 8.3e-4, t); }, 2e9);
}

// The sawtooth of discrete growth (issue 17): kgd-toughness-ci written with
// rows every 0.01 s; from 2 to 4.75 s the net inlet pressure's RMS deviation
// from its centred 0.5 s moving mean (tools/sawtooth.py) is below 2.8% and
// its largest below 8.5%. Measured 2.51% and 7.20% with each growth step's
// face load applied over the settling wait (fracture.release_transits, the
// scene's), 3.05% and 9.81% with it applied at once, when the new quarter
// cell opened faster than the water could fill it and every step's dip ran
// to the mouth (docs/verification.md, "The load of a growth step applied as
// the tip advances"). The bounds lie between the two.
TEST(KgdScene, ToughnessCiScenesPressureSwingsLessWithEachStepsLoadApplied) {
  const auto out = scratch_dir("kgd_sawtooth");
  const auto result = run_scene(read_file(source("scenarios/kgd-toughness-ci.scene")), out,
                                {"--set", "output.hdf5=false", "--set", "output.interval_s=0.01"}, 900);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto h = read_kgd_history(out);
  constexpr double kSigma0 = 1e5, kHalfWindow = 0.25, kFrom = 2, kTo = 4.75;
  std::vector<double> net;
  for (double p : h.p_in) net.push_back(p - kSigma0);
  double sum = 0, largest = 0;
  int rows = 0;
  for (std::size_t i = 0; i < h.t.size(); ++i) {
    if (h.t[i] < kFrom || h.t[i] > kTo) continue;
    double mean = 0;
    int count = 0;
    for (std::size_t j = 0; j < h.t.size(); ++j) {
      if (std::abs(h.t[j] - h.t[i]) > kHalfWindow) continue;
      mean += net[j];
      ++count;
    }
    mean /= count;
    const double d = net[i] / mean - 1;
    sum += d * d;
    largest = std::max(largest, std::abs(d));
    ++rows;
  }
  ASSERT_GE(rows, 250);
  const double rms = std::sqrt(sum / rows);
  std::printf("kgd-toughness-ci: net inlet pressure about its 0.5 s mean, %d rows: RMS %.4f, largest %.4f\n", rows, rms,
              largest);
  EXPECT_LT(rms, 0.028);
  EXPECT_LT(largest, 0.085);
}

// The same scene with a fluid a thousand times softer than water (2 MPa, the
// former default), under the default implicit interface scheme. Measured
// 1.9%, 3.4% and 5.9% worst (5 December, with the growth step's load applied
// over the settling wait; 4 December, with the cut particles' strain
// reprojected at growth: 2.5%, 6.0% and 5.9%). Under the former Gauss-Seidel scheme this run is
// stopped by the energy check at step 220: at the first growth check the
// fluid's pressure at the dry tip particles rises to 1.4 and then 5.7 MPa in
// two steps and the solid's kinetic energy to 44 J/m, 4.7 times the inlet's
// work. That happens with and without the reprojection (without it the
// kinetic energy is 14 J/m 0.6 ms later and had decayed by the next control
// point, where the check looks); docs/verification.md ("The strain of the
// particles a growth step cuts").
TEST(KgdScene, ToughnessCiSceneWithASoftFluidFollowsTheKVertex) {
  expect_ci_scene_follows("scenarios/kgd-toughness-ci.scene", 8.3e-4,
                          [](double t) { return k_vertex(1e7, 0.25, 25e3, 8.3e-4, t); }, 2e6,
                          {"--set", "fluid.mpm.bulk_modulus_pa=2e6"});
}

// The paper's set-up in its own units with water (issue 19):
// scenarios/kgd-paper-field-ci.scene (E = 20 GPa, 1 MPa, water K = 2 GPa,
// mu = 1e-4 Pa s, 1e-5 m^2/s into the wing ramped over 5 s, h = 2 m, 300 s,
// the implicit scheme at the solid's step). From three notch lengths on (the
// 4 m notch), the mouth opening within the CI 10% of the M-vertex and the net
// inlet pressure within 20% (measured 3.7% and 10.2% with the matched closure,
// the faces read from the material and growth by 1/16 cell, since 5 December;
// 5.4% and 12.4% at a quarter cell; 3.5% and 9.3% with the tip-asymptote
// closure and velocity-read faces; 3.2% and 7.2% with the vacuum front and
// half-cell growth); the fluid front within 20% at every row and within 10% at
// the end (measured 5.6% worst; before 4.4%, 4.3%, and 15.5%), where the tip
// may lead it by the zero-lag closure's wait and a growth step (the tip is
// printed, not asserted: 4.6% worst; before 11%, 17%, 29%).
// The water's volume (sum of l w) is
// the injected volume plus the notch's virtual film within 1%: its
// compression p / K ~ 5e-4, and a partly filled front particle counts the
// empty part of its domain (measured 0.99947 to 1.0082, the
// largest at 30 s while the volume is small).
TEST(KgdScene, FieldScaleWaterCiSceneFollowsTheMVertex) {
  const auto out = scratch_dir("kgd_field_ci");
  const auto result =
      run_scene(read_file(source("scenarios/kgd-paper-field-ci.scene")), out, {"--set", "output.hdf5=false"}, 900);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv h = read_csv(out + "/history.csv");
  const auto t = h.values("time_s"), tip = h.values("crack_length_m"), mouth = h.values("mouth_opening_m");
  const auto p_in = h.values("inlet_pressure_pa"), front = h.values("front_position_m");
  const auto injected = h.values("injected_volume_m2"), volume = h.values("fluid_volume_m2");
  ASSERT_NEAR(t.back(), 300, 0.05);  // the run ends on a whole step (dt = 0.024 s)
  constexpr double kSigma0 = 1e6, kNotch = 4, kRamp = 5, kQ = 2e-5, kFilm = kNotch * 2e-6;
  int compared = 0;
  double e_front_last = 1;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] > 10) {
      // From 20 s within 1%; at 10 s the front particle, at zero pressure,
      // is stretched past its rest volume (water cavitates rather than carry
      // tension) and its domain counts some empty crack: measured 1.0630
      // with the matched closure (4.7e-6 m^2, a twentieth of the front
      // cell's volume), 1.0462 with the tip-asymptote closure, 0.9995 from
      // 20 s on.
      const double ratio = volume[i] / (injected[i] + kFilm);
      EXPECT_NEAR(ratio, 1.0, t[i] < 20 ? 7e-2 : 1e-2) << "t = " << t[i];
    }
    if (front[i] < 3 * kNotch) continue;
    const Vertex v = m_vertex(2e10, 0.25, 1e-4, kQ, t[i] - 0.5 * kRamp);
    const double e_front = front[i] / v.length - 1, e_tip = tip[i] / v.length - 1;
    const double e_opening = mouth[i] / v.opening - 1, e_pressure = (p_in[i] - kSigma0) / v.pressure - 1;
    std::printf("t %.0f s: front %+.3f (tip %+.3f), mouth opening %+.3f, net inlet pressure %+.3f\n", t[i], e_front,
                e_tip, e_opening, e_pressure);
    EXPECT_LT(std::abs(e_opening), 0.10) << "t = " << t[i];
    EXPECT_LT(std::abs(e_pressure), 0.20) << "t = " << t[i];
    EXPECT_LT(std::abs(e_front), 0.20) << "t = " << t[i];
    e_front_last = e_front;
    ++compared;
  }
  EXPECT_LT(std::abs(e_front_last), 0.10);
  EXPECT_GE(compared, 10);
}

// The implicit interface scheme (coupling.scheme IMPLICIT, issue 17) on the
// CI viscosity scene at its own step: the answer no longer depends on how
// stiff the fluid is. At K = 2e7 Pa and water (2e9 Pa), from three notch
// lengths on, the mouth opening and the net inlet pressure agree within 2%
// at every row where the two tips have grown equally, and within 3% where
// one tip is ahead (each growth step dips the pressure for a while); the
// fluid fronts within 2%; the tips differ by at most two growth increments
// (a quarter cell each, 0.00875 m) plus 2%. Against the M-vertex, water's
// opening is within 10% and its net pressure within 20% (the CI bounds).
// Measured with the scene's matched closure and surfaces from the material
// (4 December, thirteenth session): 0.30% (opening), 1.79% (pressure, at 4 s)
// and 0.43% (front) worst over 8 rows, the tips at most 0.0088 m apart; with
// the former tip-asymptote closure and velocity surfaces: 0.6%, 0.8% and
// 0.8% over 9 rows, the tips at most 0.0175 m apart (with the front particle's own velocity as the
// closure's V instead of the last cell's mean: 3.1%, 3.5%, 3.6%). K = 2e6 Pa is left out
// on purpose: at 1.1e5 Pa it is compressed by 5%, a physical difference (its
// opening was 2.9% from water's).
TEST(KgdScene, ImplicitSchemeAnswerDoesNotDependOnTheFluidStiffness) {
  struct Run {
    std::vector<double> t, length, front, mouth, p_in;
  };
  // The two runs at once, one solid thread each (the answer does not depend
  // on the thread count; together they take about the wall time of one run
  // with two threads after the other, less on a loaded machine).
  auto run_at = [](const std::string& bulk_modulus) {
    const auto out = scratch_dir("kgd_implicit_" + bulk_modulus);
    const auto scene = read_file(source("scenarios/kgd-viscosity-ci.scene"));
    return std::async(std::launch::async, [out, scene, bulk_modulus] {
      const auto result = run_scene(scene, out,
                                    {"--set", "output.hdf5=false", "--set", "coupling.scheme=IMPLICIT", "--set",
                                     "solid.mpm.threads=1", "--set", "fluid.mpm.bulk_modulus_pa=" + bulk_modulus},
                                    900);
      EXPECT_EQ(result.exit_code, 0) << result.err;
      const Csv h = read_csv(out + "/history.csv");
      return Run{h.values("time_s"), h.values("crack_length_m"), h.values("front_position_m"),
                 h.values("mouth_opening_m"), h.values("inlet_pressure_pa")};
    });
  };
  auto soft_run = run_at("2e7"), water_run = run_at("2e9");
  const Run soft = soft_run.get(), water = water_run.get();
  ASSERT_EQ(soft.t.size(), water.t.size());
  ASSERT_GE(water.t.size(), 20u);
  constexpr double kSigma0 = 1e5, kNotch = 0.15, kGrowth = 0.00875;
  double worst_opening = 0, worst_pressure = 0, worst_front = 0;
  int compared = 0;
  for (std::size_t i = 0; i < water.t.size(); ++i) {
    ASSERT_NEAR(soft.t[i], water.t[i], 1e-9);
    if (std::min(soft.length[i], water.length[i]) < 3 * kNotch) continue;
    const double opening = std::abs(soft.mouth[i] / water.mouth[i] - 1);
    const double pressure = std::abs((soft.p_in[i] - kSigma0) / (water.p_in[i] - kSigma0) - 1);
    const double front = std::abs(soft.front[i] / water.front[i] - 1);
    std::printf("t %.2f s: K = 2e7 against water: opening %.4f, net pressure %.4f, front %.4f, tip %.4f m\n",
                water.t[i], opening, pressure, front, soft.length[i] - water.length[i]);
    const double bound = std::abs(soft.length[i] - water.length[i]) < 0.5 * kGrowth ? 0.02 : 0.03;
    EXPECT_LT(opening, bound) << "t = " << water.t[i];
    EXPECT_LT(pressure, bound) << "t = " << water.t[i];
    EXPECT_LT(front, 0.02) << "t = " << water.t[i];
    EXPECT_LT(std::abs(soft.length[i] - water.length[i]), 2 * kGrowth + 0.02 * water.length[i]) << "t = " << water.t[i];
    const Vertex v = m_vertex(1e7, 0.25, 0.01, 2.5e-4, water.t[i] - 0.025);
    EXPECT_LT(std::abs(water.mouth[i] / v.opening - 1), 0.10) << "t = " << water.t[i];
    EXPECT_LT(std::abs((water.p_in[i] - kSigma0) / v.pressure - 1), 0.20) << "t = " << water.t[i];
    worst_opening = std::max(worst_opening, opening);
    worst_pressure = std::max(worst_pressure, pressure);
    worst_front = std::max(worst_front, front);
    ++compared;
  }
  std::printf("%d rows: worst difference opening %.4f, net pressure %.4f, front %.4f\n", compared, worst_opening,
              worst_pressure, worst_front);
  EXPECT_GE(compared, 5);
}

}  // namespace
}  // namespace hfmpm::test
