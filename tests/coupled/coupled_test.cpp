// Coupled runs with real processes over real sockets (ipc, tcp) and the
// in-process mode, with the stand-in sides. They check the values that crossed
// the data plane and reached history.csv against the stand-ins' formulas:
//   opening   w(s, t) = w0 (t / 1 s)^(1/3) sqrt(1 - (s / L)^2),  w0 = 1 mm
//   length    L(t)    = 0.2 m + 0.8 m/s * t, in whole crack-particle spacings h = 1 cm
//   pressure  p(s, t) = p_in(t) (1 - s / s_front),  p_in ramps 0 -> 100 kPa over 0.5 s,
//             s_front = 0.9 L as the fluid last saw it
//   volume    V(t)    = integral_0^{0.9 L} w ds = w0(t) L / 2 (x sqrt(1 - x^2) + asin x), x = 0.9
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <thread>

#include "coupled_support.hpp"

namespace hfmpm::test {
namespace {

double w_mouth(double t) { return t > 0 ? 1e-3 * std::cbrt(t) : 0.0; }
double p_inlet(double t) { return 1e5 * std::min(1.0, t / 0.5); }
constexpr double kSpacing = 0.01;

TEST(Coupled, IpcRunMatchesTheStandInFormulas) {
  const auto out = scratch_dir("ipc");
  const auto result = run_scene(prescribed_scene(), out, {"--set", "output.exchange_log=true"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv history = read_csv(out + "/history.csv");
  for (const char* column : {"time_s", "step", "crack_length_m", "mouth_opening_m", "inlet_pressure_pa",
                             "injected_volume_m2", "fluid_volume_m2", "kinetic_energy_j", "wall_s"}) {
    EXPECT_NO_THROW(history.column(column)) << column;
  }
  ASSERT_EQ(history.rows.size(), 21u);  // t = 0, 0.01, ..., 0.2 s
  const auto t = history.values("time_s");
  const auto length = history.values("crack_length_m");
  const auto opening = history.values("mouth_opening_m");
  const auto pressure = history.values("inlet_pressure_pa");
  const auto volume = history.values("fluid_volume_m2");
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(t[i], 0.01 * static_cast<double>(i), 1e-12);
    EXPECT_NEAR(opening[i], w_mouth(t[i]), 1e-9 * w_mouth(t[i])) << "t = " << t[i];  // history.csv has 10 digits
    EXPECT_NEAR(pressure[i], p_inlet(t[i]), 1e-6) << "t = " << t[i];
    // Growth appends a particle each time L(t) passes the next spacing.
    const double target = 0.2 + 0.8 * t[i];
    EXPECT_LE(length[i], target + 1e-9);
    EXPECT_GT(length[i], target - kSpacing - 1e-9);
    // Volume from the widths the fluid received; trapezoid error of the
    // smooth part of the ellipse is < 3e-3 relative for h / L <= 0.05.
    const double x = 0.9;
    const double exact = w_mouth(t[i]) * length[i] / 2 * (x * std::sqrt(1 - x * x) + std::asin(x));
    if (t[i] > 0) {
      EXPECT_NEAR(volume[i], exact, 3e-3 * exact) << "t = " << t[i];
    }
  }

  // Every width that reached the fluid is the formula at the frame's time.
  const Csv widths = read_csv(out + "/fluid_received.csv");
  ASSERT_GT(widths.rows.size(), 4000u);
  std::map<double, double> length_at_step;
  for (const auto& row : widths.rows) {
    auto& l = length_at_step[row[widths.column("step")]];
    l = std::max(l, row[widths.column("x_m")]);
  }
  for (const auto& row : widths.rows) {
    const double s = row[widths.column("x_m")];
    const double l = length_at_step[row[widths.column("step")]];
    const double w = w_mouth(row[widths.column("t_s")]) * std::sqrt(std::max(0.0, 1 - (s / l) * (s / l)));
    ASSERT_NEAR(row[widths.column("width_m")], w, 1e-15) << "step " << row[0] << " s = " << s;
    ASSERT_NEAR(row[widths.column("id")] * kSpacing, s, 1e-12);  // ids count from the mouth
  }
  // Every pressure that reached the solid is the formula at the frame's time.
  const Csv pressures = read_csv(out + "/solid_received.csv");
  ASSERT_GT(pressures.rows.size(), 4000u);
  for (const auto& row : pressures.rows) {
    const double s = row[pressures.column("id")] * kSpacing;
    const double front = row[pressures.column("front_position_m")];
    const double p = s <= front ? p_inlet(row[pressures.column("t_s")]) * (1 - s / front) : 0.0;
    ASSERT_NEAR(row[pressures.column("pressure_pa")], p, 1e-8) << "step " << row[0] << " s = " << s;
  }
}

// In the Jacobi scheme the fluid's step-n state is computed on the crack of
// step n-1; in Gauss-Seidel on the crack of step n. The front (0.9 L) shows it.
void expect_front_lag(const std::string& scheme, int lag) {
  const auto out = scratch_dir("scheme");
  const auto result =
      run_scene(prescribed_scene(), out, {"--set", "output.exchange_log=true", "--set", "coupling.scheme=" + scheme});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv widths = read_csv(out + "/fluid_received.csv");
  const Csv pressures = read_csv(out + "/solid_received.csv");
  std::map<long, double> length;  // step -> crack length the solid sent
  for (const auto& row : widths.rows) {
    auto& l = length[static_cast<long>(row[widths.column("step")])];
    l = std::max(l, row[widths.column("x_m")]);
  }
  int checked = 0, grew = 0;
  for (const auto& row : pressures.rows) {
    const long step = static_cast<long>(row[pressures.column("step")]);
    if (step < lag || row[pressures.column("id")] != 0) continue;
    ASSERT_NEAR(row[pressures.column("front_position_m")], 0.9 * length.at(step - lag), 1e-12) << "step " << step;
    grew += length.at(step) != length.at(step - 1 < 0 ? 0 : step - 1) ? 1 : 0;
    ++checked;
  }
  EXPECT_GE(checked, 4000);
  EXPECT_GT(grew, 10);  // the crack grew during the run, so the lag was visible
}

TEST(Coupled, JacobiFluidSeesThePreviousCrack) { expect_front_lag("JACOBI", 1); }
TEST(Coupled, GaussSeidelFluidSeesTheNewCrack) { expect_front_lag("GAUSS_SEIDEL", 0); }

TEST(Coupled, ExchangeIntervalExchangesEveryKSteps) {
  const auto out = scratch_dir("interval");
  const auto result = run_scene(prescribed_scene(), out,
                                {"--set", "output.exchange_log=true", "--set", "coupling.exchange_interval=10"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv widths = read_csv(out + "/fluid_received.csv");
  std::set<long> steps;
  for (const auto& row : widths.rows) steps.insert(static_cast<long>(row[widths.column("step")]));
  EXPECT_EQ(steps.size(), 401u);  // step 0 and every 10th of 4000 steps
  for (long s : steps) EXPECT_EQ(s % 10, 0) << s;
  const Csv history = read_csv(out + "/history.csv");
  EXPECT_NEAR(history.values("mouth_opening_m").back(), w_mouth(0.2), 1e-9 * w_mouth(0.2));
}

TEST(Coupled, InprocAndIpcGiveIdenticalHistories) {
  const auto ipc = scratch_dir("same-ipc");
  const auto inproc = scratch_dir("same-inproc");
  ASSERT_EQ(run_scene(prescribed_scene(), ipc, {}).exit_code, 0);
  const auto result = run_scene(prescribed_scene(), inproc, {"--transport", "inproc"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  expect_same_history(read_csv(ipc + "/history.csv"), read_csv(inproc + "/history.csv"));
  EXPECT_EQ(json_string(read_file(inproc + "/run.json"), "solid_program"), "in-process thread");
}

// The three processes started by hand over tcp, as on three hosts.
TEST(Coupled, TcpCouplerAndSidesStartedByHand) {
  const auto reference = scratch_dir("tcp-ref");
  ASSERT_EQ(run_scene(prescribed_scene(), reference, {}).exit_code, 0);

  const auto out = scratch_dir("tcp");
  const auto scene = out + "/scene.scene";
  write_file(scene, prescribed_scene());
  const auto keys = make_keys(out);
  Process coupler(
      {bin("hfmpm"), "coupler", scene, "--bind", "tcp://127.0.0.1:*", "--keys", keys.coupler, "--out", out, "--quiet"});
  const std::string endpoint = wait_for_endpoint(out + "/run.json", 10);
  ASSERT_EQ(endpoint.rfind("tcp://127.0.0.1:", 0), 0u) << endpoint;
  Process solid({bin("hfmpm-prescribed-solid"), "--connect", endpoint, "--keys", keys.side, "--out", out + "/solid",
                 "--advertise-host", "127.0.0.1"});
  Process fluid({bin("hfmpm-prescribed-fluid"), "--connect", endpoint, "--keys", keys.side, "--out", out + "/fluid"});
  ASSERT_TRUE(coupler.wait(60)) << coupler.err();
  EXPECT_EQ(coupler.exit_code(), 0) << coupler.err();
  ASSERT_TRUE(solid.wait(10));
  ASSERT_TRUE(fluid.wait(10));
  EXPECT_EQ(solid.exit_code(), 0) << solid.err();
  EXPECT_EQ(fluid.exit_code(), 0) << fluid.err();
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_EQ(json_string(manifest, "data_endpoint").rfind("tcp://127.0.0.1:", 0), 0u) << manifest;
  EXPECT_EQ(json_string(manifest, "tcp_security"), "CURVE");
  EXPECT_EQ(manifest.find(read_file(keys.side).substr(read_file(keys.side).find("client_secret = ") + 16, 40)),
            std::string::npos);  // no secret in run.json
  expect_same_history(read_csv(reference + "/history.csv"), read_csv(out + "/history.csv"));
}

TEST(Coupled, DrySolidRunsAloneWithoutAFluidProcess) {
  std::string scene = prescribed_scene();
  scene = scene.substr(0, scene.find("fluid {"));
  const auto out = scratch_dir("dry");
  const auto result = run_scene(scene, out, {});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv history = read_csv(out + "/history.csv");
  EXPECT_NEAR(history.values("mouth_opening_m").back(), w_mouth(0.2), 1e-9 * w_mouth(0.2));
  EXPECT_EQ(history.values("fluid_volume_m2").back(), 0.0);
  const std::string manifest = read_file(out + "/run.json");
  EXPECT_EQ(json_string(manifest, "fluid_program"), "");
  EXPECT_EQ(json_string(manifest, "status"), "completed");
}

TEST(Coupled, DtIsTheSafetyFactorTimesTheSmallestStableStep) {
  const auto out = scratch_dir("dt");
  // solid 2e-4 s, fluid 1e-4 s -> dt = 0.5 * 1e-4 s; with the fluid at 4e-4 s, dt = 0.5 * 2e-4 s.
  ASSERT_EQ(run_scene(prescribed_scene(), out, {}).exit_code, 0);
  EXPECT_DOUBLE_EQ(read_csv(out + "/history.csv").values("dt_s").back(), 5e-5);
  const auto out2 = scratch_dir("dt2");
  ASSERT_EQ(run_scene(prescribed_scene(), out2, {"--set", "fluid.prescribed_pressure.stable_dt_s=4e-4"}).exit_code, 0);
  const Csv history = read_csv(out2 + "/history.csv");
  EXPECT_DOUBLE_EQ(history.values("dt_s").back(), 1e-4);
  EXPECT_EQ(history.values("step").back(), 2000.0);
}

TEST(Coupled, BadSceneFailsBeforeAnyProcessStarts) {
  const auto out = scratch_dir("bad");
  const auto result = run_scene(prescribed_scene(), out, {"--set", "coupling.exchange_interval=0"});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("--set coupling.exchange_interval: coupling.exchange_interval = 0 is not allowed"),
            std::string::npos)
      << result.err;
  EXPECT_FALSE(std::filesystem::exists(out + "/run.json"));
}

}  // namespace
}  // namespace hfmpm::test
