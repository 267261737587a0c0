// The real solid and the real fluid coupled on the toughness-dominated KGD
// scenes (the other KGD scenes: kgd_scene_test.cpp; shared checks:
// kgd_support.hpp).
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
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "coupled_support.hpp"
#include "kgd_support.hpp"

namespace hfmpm::test {
namespace {

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

// The virtual film the run derives for kgd-toughness-ci's physics: 1% of the
// K-vertex's mouth opening at the end, to 2 significant digits: 4.2e-5 m.
Bounds derived_film_bounds() {
  Bounds bounds;
  bounds.film = std::round(0.01 * k_vertex(1e7, 0.25, 25e3, 8.3e-4, 5 - 0.025).opening * 1e6) / 1e6;
  return bounds;
}

// Toughness-dominated (Km = 7.6) against the K-vertex, with water and the
// implicit interface scheme. The scene sets two method keys (density scaling
// 10, in_situ_reference false: for the sawtooth test below); the rest is
// derived from its physics (docs/scenes.md, "The derived method"), among it
// each growth step's face load applied over the settling wait
// (fracture.release_transits) and a virtual film of 4.2e-5 m. Quarter-cell
// growth used to add a crack particle every quarter cell, and the water run
// then failed at 4.9 s (from ~3.6 s every interface solve stopped above
// tolerance); with crack particles half a cell apart (docs/solid.md) it runs
// to the end. Measured: 2.9%, 2.2% and 5.3% worst against the K-vertex; with
// the film the scene wrote out before (2e-5 m) 2.9%, 1.7% and 3.4%; with
// every key derived (density scaling 7.6, the in-situ reference) 1.2%, 4.0%
// and 5.5%; with the load applied at once 3.0%, 2.9% and 8.5%
// (docs/verification.md, "The load of a growth step applied as the tip
// advances"); 9.0%, 3.3% and 18.0% before the faces were read from the
// material and the damping set for the crack's own mode.
TEST(KgdScene, ToughnessCiSceneFollowsTheKVertex) {
  expect_ci_scene_follows(
      "scenarios/kgd-toughness-ci.scene", 8.3e-4, [](double t) { return k_vertex(1e7, 0.25, 25e3, 8.3e-4, t); }, 2e9,
      {}, derived_film_bounds());
}

// The sawtooth of discrete growth (issue 17): kgd-toughness-ci written with
// rows every 0.01 s; from 2 to 4.75 s the net inlet pressure's RMS deviation
// from its centred 0.5 s moving mean (tools/sawtooth.py) is below 2.8% and
// its largest below 8.5%. Measured 2.51% and 7.39% with each growth step's
// face load applied over the settling wait (fracture.release_transits), 3.05%
// and 9.81% with it applied at once, when the new quarter cell opened faster
// than the water could fill it and every step's dip ran to the mouth
// (docs/verification.md, "The load of a growth step applied as the tip
// advances"). The bounds lie between the two. They hold with the two keys
// the scene sets for this test: with every key derived the swing is 4.21% /
// 12.05%, with in_situ_reference false alone 2.94% / 7.93%, with density
// scaling 10 alone 3.80% / 12.00%.
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
// former default), under the default implicit interface scheme (the derived
// method is the same for both fluids). Measured 2.4%, 3.7% and 3.6% worst
// (with the 2e-5 m film the scene wrote out before: 1.9%, 3.4% and 5.9%; with
// the cut particles' strain reprojected at growth but the load applied at
// once: 2.5%, 6.0% and 5.9%). Under the former Gauss-Seidel scheme this run is
// stopped by the energy check at step 220: at the first growth check the
// fluid's pressure at the dry tip particles rises to 1.4 and then 5.7 MPa in
// two steps and the solid's kinetic energy to 44 J/m, 4.7 times the inlet's
// work. That happens with and without the reprojection (without it the
// kinetic energy is 14 J/m 0.6 ms later and had decayed by the next control
// point, where the check looks); docs/verification.md ("The strain of the
// particles a growth step cuts").
TEST(KgdScene, ToughnessCiSceneWithASoftFluidFollowsTheKVertex) {
  expect_ci_scene_follows(
      "scenarios/kgd-toughness-ci.scene", 8.3e-4, [](double t) { return k_vertex(1e7, 0.25, 25e3, 8.3e-4, t); }, 2e6,
      {"--set", "fluid.mpm.bulk_modulus_pa=2e6"}, derived_film_bounds());
}

}  // namespace
}  // namespace hfmpm::test
