// Plain C++ types that cross between a physics library and its protocol
// adapter. No Protobuf or ZeroMQ here: the physics libraries see only these.
// Units are SI; 2D quantities are per unit thickness.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace hfmpm {

using Vec2 = Eigen::Vector2d;

// What the solid publishes about one crack after a step (docs/protocol.md).
// Arrays are ordered from the mouth (or one end) to the tip, all of size().
struct CrackGeometry {
  std::uint32_t crack_id = 0;
  std::vector<std::uint64_t> ids;  // stable crack-particle ids
  std::vector<Vec2> position;      // m, crack-plane position
  std::vector<Vec2> normal;        // unit normal towards the "above" side
  std::vector<double> width;       // m, opening, >= 0
  std::vector<char> tip;           // 1 at a tip
  bool grew = false;               // ids appended since the previous publication
  // Optional (empty, or one per id; coupling.scheme IMPLICIT): the faces'
  // response over the coming step of dt under face pressures p_j:
  //   w_k(t + dt) = width_k + dt (opening_rate_k + dt (opening_acceleration_k + sum_j C_kj p_j)),
  // C banded, |k - j| <= compliance_band, row-major:
  // C_kj = opening_compliance[k (2 band + 1) + j - k + band].
  std::vector<double> opening_rate;          // m/s
  std::vector<double> opening_acceleration;  // m/s^2, all loads but the face pressure
  std::vector<double> opening_compliance;    // m/s^2 per Pa, size() (2 band + 1)
  std::uint32_t compliance_band = 0;
  // Optional with the response: the crack plane's motion, x(t + dt) = x + dt (plane_rate + dt plane_acceleration).
  std::vector<Vec2> plane_rate;          // m/s
  std::vector<Vec2> plane_acceleration;  // m/s^2
  // Optional (0: not sent): what a fluid needs for a tip closure in the unresolved
  // last cell (fluid lag TIP_ASYMPTOTE): the plane-strain modulus E' of the
  // material at the crack's last point (the tip the fluid runs towards), and
  // the length over which the solid resolves the faces' opening (its cell).
  double tip_modulus = 0;  // Pa
  double resolution = 0;   // m
  // Optional: a fluid entering at an interior crack particle (a wellbore
  // inside the body) enters at the one with id inlet_id and flows both ways;
  // start_tip_modulus is E' at the crack's first point, the start tip (0: not
  // sent). Without has_inlet the fluid enters at the first particle, a mouth.
  bool has_inlet = false;
  std::uint64_t inlet_id = 0;
  double start_tip_modulus = 0;  // Pa

  std::size_t size() const { return ids.size(); }
};

// What the fluid publishes about one crack after a step.
struct CrackPressure {
  std::uint32_t crack_id = 0;
  std::vector<std::uint64_t> ids;  // crack-particle ids, same order as the geometry
  std::vector<double> pressure;    // Pa, >= 0, 0 beyond the front
  // Optional (empty, or one per id): -dp/dw (Pa/m, >= 0) at each crack
  // particle and the crack widths (m) the pressures were computed from. The
  // solid then applies p - stiffness (w - width) for its current width w and
  // treats the change over its step implicitly.
  std::vector<double> stiffness;
  std::vector<double> width;
  // m, arc lengths from the first of `ids`: the fluid occupies
  // [front_start_position, front_position] (front_start_position 0 at a mouth;
  // > 0 for an interior inlet whose start-side wing has not reached the start).
  double front_position = 0;
  double front_start_position = 0;
  double inlet_flux = 0;    // m^2/s
  double fluid_volume = 0;  // m^2

  std::size_t size() const { return ids.size(); }
};

// Scalars a side reports to the coupler after a StepCommand (history.csv).
struct SideDiagnostics {
  double kinetic_energy = 0;   // J/m
  double strain_energy = 0;    // J/m, elastic energy of the solid's stress (of its change with in_situ_reference)
  double crack_length = 0;     // m
  double mouth_opening = 0;    // m
  double crack_face_load = 0;  // N/m
  double inlet_pressure = 0;   // Pa
  double injected_volume = 0;  // m^2
  double fluid_volume = 0;     // m^2
  double front_position = 0;   // m
  double coupling_lag = 0;     // Pa, the fluid's pressure change at frozen crack width over its last exchange window
  double released_energy = 0;  // J/m, in-situ elastic energy released by the faces' slip (solid)
  std::uint32_t crack_particles = 0;
  std::uint32_t fluid_particles = 0;
};

// A state a side found that the physics forbids or that a run must not pass
// silently (protocol Notice): a code, sent once per run, and its message.
struct Notice {
  std::string code;
  std::string message;
};

// The protocol's crack-update rule (docs/protocol.md, CrackState), in one
// place for every side: a crack keeps its particles' ids in order and only
// adds new ones at a tip: appended at its end, or, when `prepended` is given
// (the caller's crack starts at a tip), also prepended at its start, their
// number stored there. `grew` (when given) says whether ids were added since
// the previous CrackState. Returns the number of ids appended; throws
// std::invalid_argument naming the crack and what broke.
inline std::size_t check_crack_update(std::uint32_t crack_id, const std::vector<std::uint64_t>& before,
                                      const std::vector<std::uint64_t>& now, const bool* grew = nullptr,
                                      std::size_t* prepended = nullptr) {
  const std::string crack = "crack " + std::to_string(crack_id) + ": ";
  if (now.size() < before.size()) {
    throw std::invalid_argument(crack + "has " + std::to_string(now.size()) + " crack particles, fewer than the " +
                                std::to_string(before.size()) + " it had: crack particles may not disappear");
  }
  std::size_t offset = 0;
  if (prepended && !before.empty()) {
    while (offset + before.size() < now.size() && now[offset] != before.front()) ++offset;
  }
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (now[offset + i] != before[i]) {
      throw std::invalid_argument(crack + "crack particle " + std::to_string(offset + i) + " has id " +
                                  std::to_string(now[offset + i]) + " but had id " + std::to_string(before[i]) +
                                  (prepended ? ": ids may only be added at the tips (appended at the end, prepended "
                                               "at a start tip), never reordered or removed"
                                             : ": ids may only be appended at the tip, never reordered or removed"));
    }
  }
  const std::size_t appended = now.size() - before.size() - offset;
  if (prepended) *prepended = offset;
  if (grew && *grew != (appended + offset > 0)) {
    throw std::invalid_argument(crack + "'grew' is " + (*grew ? "true" : "false") + " but " +
                                std::to_string(appended + offset) + " ids were added");
  }
  return appended;
}

// The FluidState rule: the ids a fluid answers with are the crack's ids in
// order, or a contiguous run of them while the crack grows (under Jacobi the
// fluid answers with the ids of the crack it last received, and a crack may
// grow at both ends). Returns where the run starts in `ids`, or -1 if `run`
// is not one.
inline std::ptrdiff_t ids_run_offset(const std::vector<std::uint64_t>& run, const std::vector<std::uint64_t>& ids) {
  if (run.size() > ids.size()) return -1;
  std::size_t offset = 0;
  if (!run.empty()) {
    while (offset + run.size() < ids.size() && ids[offset] != run.front()) ++offset;
  }
  for (std::size_t i = 0; i < run.size(); ++i) {
    if (run[i] != ids[offset + i]) return -1;
  }
  return static_cast<std::ptrdiff_t>(offset);
}
inline bool ids_are_prefix(const std::vector<std::uint64_t>& prefix, const std::vector<std::uint64_t>& ids) {
  return ids_run_offset(prefix, ids) == 0;
}

// Arc length of each point of a polyline from its first point.
inline std::vector<double> arc_length(const std::vector<Vec2>& points) {
  std::vector<double> s(points.size(), 0.0);
  for (std::size_t i = 1; i < points.size(); ++i) s[i] = s[i - 1] + (points[i] - points[i - 1]).norm();
  return s;
}

}  // namespace hfmpm
