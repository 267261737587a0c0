// Conformance checks of the step schedule: StepCommands of several sizes, one
// DataFrame per exchange step in the scheme's order, StepReports whose step and
// t match the command bit for bit, with exchange intervals 1 and 5 and both
// schemes, and a longer run whose every frame is checked.
#include "checks.hpp"

namespace hfmpm::conformance {
namespace {

// Runs commands of the given sizes (in exchange intervals); returns a summary.
std::string run_commands(Session& s, const std::vector<std::uint32_t>& windows) {
  std::string sizes;
  for (auto w : windows) {
    const std::uint32_t n = w * s.exchange_interval();
    s.run_command(n);
    sizes += (sizes.empty() ? "" : ", ") + std::to_string(n);
  }
  return std::to_string(windows.size()) + " commands (" + sizes + " steps), " +
         std::to_string(s.peer().frames_checked()) + " frames checked, StepReport step " + std::to_string(s.step()) +
         " at t = " + fmt(s.t()) + " s bitwise";
}

std::string check_steps(Context& context) {
  Session s(context);
  s.start();
  const std::string summary = run_commands(s, {1, 2, 3, 20});
  s.run_command(s.exchange_interval(), true);
  return summary + "; then one with write_output";
}

std::string check_exchange_interval(Context& context) {
  Session s(context, {{"coupling.exchange_interval=5"}, {}});
  s.start();
  // Exchanges at steps 10, 20, 25, 35, 45: a frame for any other step fails.
  return "exchange_interval 5: " + run_commands(s, {2, 2, 1, 2, 2});
}

std::string check_gauss_seidel(Context& context) {
  Session s(context, {{"coupling.scheme=GAUSS_SEIDEL"}, {}});
  s.start();
  return "Gauss-Seidel: " + run_commands(s, {1, 3, 20});
}

std::string check_gauss_seidel_interval(Context& context) {
  Session s(context, {{"coupling.scheme=GAUSS_SEIDEL", "coupling.exchange_interval=5"}, {}});
  s.start();
  return "Gauss-Seidel, exchange_interval 5: " + run_commands(s, {2, 1, 3});
}

// The peer's frame for step n arrives before the side has sent its own. A fake fluid then
// answers with the ids of the previous CrackState, as a real Jacobi fluid does after growth.
std::string check_peer_early(Context& context) {
  Session s(context);
  s.start();
  s.set_peer_early(true);
  const std::uint32_t n = 50 * s.exchange_interval();
  while (s.step() < 600) s.run_command(n);
  return "our frame first at every exchange over " + std::to_string(s.step()) + " steps, " +
         std::to_string(s.peer().growth_events()) + " with crack growth";
}

std::string check_diagnostics(Context& context) {
  Session s(context);
  s.start();
  s.peer().check_diagnostics(s.ready().diagnostics(), "Ready");
  for (int i = 0; i < 10; ++i) {
    const auto report = s.run_command(10 * s.exchange_interval());
    s.peer().check_diagnostics(report.diagnostics(), "StepReport of step " + std::to_string(report.step()));
  }
  return "Ready and 10 StepReports: " + std::string(s.role() == protocol::SOLID
                                                        ? "crack_particles, crack_length, mouth_opening and "
                                                          "crack_face_load match the frames"
                                                        : "finite, >= 0, front within the crack");
}

std::string check_frames(Context& context) {
  Session s(context);
  s.start();
  const std::uint32_t n = 20 * s.exchange_interval();
  for (int i = 0; i < 15; ++i) s.run_command(n);
  return std::to_string(s.peer().frames_checked()) + " frames over " + std::to_string(s.step()) +
         " steps: arrays match ids, values finite, " +
         (s.role() == protocol::SOLID ? "normals unit, widths >= 0, tip last and closed, ids appended only"
                                      : "ids = those of the last CrackState, pressures >= 0");
}

}  // namespace

std::vector<Check> schedule_checks() {
  return {
      {"steps", "StepCommands of 1, 2, 3, 20, 1 (write_output) steps: a frame per step, StepReport step/t bitwise",
       check_steps},
      {"exchange_interval", "coupling.exchange_interval=5: frames only at multiples of 5, commands of 5 to 10 steps",
       check_exchange_interval},
      {"gauss_seidel", "coupling.scheme=GAUSS_SEIDEL: the fluid waits for the solid's frame of the same step",
       check_gauss_seidel},
      {"gauss_seidel_interval", "Gauss-Seidel with exchange_interval=5", check_gauss_seidel_interval},
      {"peer_early", "Jacobi with the peer's frame n arriving before the side sends its own (growth included)",
       check_peer_early},
      {"diagnostics", "Ready/StepReport diagnostics finite and consistent with the frames exchanged",
       check_diagnostics},
      {"frames", "300 steps; every CrackState/FluidState checked (convert.hpp from_proto plus own rules)",
       check_frames},
  };
}

}  // namespace hfmpm::conformance
