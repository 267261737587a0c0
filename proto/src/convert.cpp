#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "hfmpm/proto/convert.hpp"

namespace hfmpm::proto {
namespace {

[[noreturn]] void fail(std::string_view message_type, std::uint32_t crack_id, const std::string& what) {
  throw ProtocolError(std::string(message_type) + " crack " + std::to_string(crack_id) + ": " + what);
}

template <class Repeated>
void check_length(std::string_view type, std::uint32_t crack_id, const char* name, const Repeated& array,
                  int expected) {
  if (array.size() != expected) {
    fail(type, crack_id,
         std::string("array '") + name + "' has " + std::to_string(array.size()) + " entries but 'ids' has " +
             std::to_string(expected) + "; every per-particle array must match 'ids'");
  }
}

template <class Repeated>
void check_finite(std::string_view type, std::uint32_t crack_id, const char* name, const Repeated& array) {
  for (int i = 0; i < array.size(); ++i) {
    if (!std::isfinite(array[i])) {
      fail(type, crack_id, std::string("'") + name + "[" + std::to_string(i) + "]' is not finite");
    }
  }
}

template <class Repeated>
void check_unique_ids(std::string_view type, std::uint32_t crack_id, const Repeated& ids) {
  // Ids are usually increasing (appended at the tip): then they are unique, in O(n).
  if (std::adjacent_find(ids.begin(), ids.end(), std::greater_equal<>()) == ids.end()) return;
  std::vector<std::uint64_t> sorted(ids.begin(), ids.end());
  std::sort(sorted.begin(), sorted.end());
  const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
  if (twice != sorted.end()) {
    const auto first = std::find(ids.begin(), ids.end(), *twice);
    const auto second = std::find(std::next(first), ids.end(), *twice);
    fail(type, crack_id,
         "id " + std::to_string(*twice) + " appears twice (at index " + std::to_string(first - ids.begin()) +
             " and index " + std::to_string(second - ids.begin()) + ")");
  }
}

}  // namespace

void to_proto(const CrackGeometry& crack, protocol::CrackState::Crack* out) {
  const int n = static_cast<int>(crack.size());
  out->Clear();
  out->set_crack_id(crack.crack_id);
  out->set_grew(crack.grew);
  out->mutable_ids()->Add(crack.ids.begin(), crack.ids.end());
  for (auto* a : {out->mutable_x(), out->mutable_y(), out->mutable_nx(), out->mutable_ny()}) a->Reserve(n);
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    out->add_x(crack.position[k].x());
    out->add_y(crack.position[k].y());
    out->add_nx(crack.normal[k].x());
    out->add_ny(crack.normal[k].y());
  }
  out->mutable_width()->Add(crack.width.begin(), crack.width.end());
  out->mutable_tip()->Reserve(n);
  for (char t : crack.tip) out->add_tip(t != 0);
  out->mutable_opening_rate()->Add(crack.opening_rate.begin(), crack.opening_rate.end());
  out->mutable_opening_acceleration()->Add(crack.opening_acceleration.begin(), crack.opening_acceleration.end());
  out->mutable_opening_compliance()->Add(crack.opening_compliance.begin(), crack.opening_compliance.end());
  out->set_opening_compliance_band(crack.compliance_band);
  for (const auto& v : crack.plane_rate) {
    out->add_plane_rate_x(v.x());
    out->add_plane_rate_y(v.y());
  }
  for (const auto& a : crack.plane_acceleration) {
    out->add_plane_acceleration_x(a.x());
    out->add_plane_acceleration_y(a.y());
  }
  out->set_tip_modulus_pa(crack.tip_modulus);
  out->set_resolution_m(crack.resolution);
  if (crack.has_inlet) out->set_inlet_id(crack.inlet_id);
  out->set_start_tip_modulus_pa(crack.start_tip_modulus);
}

CrackGeometry from_proto(const protocol::CrackState::Crack& crack) {
  constexpr std::string_view type = "CrackState";
  const std::uint32_t id = crack.crack_id();
  const int n = crack.ids_size();
  if (n < 2) fail(type, id, "a crack needs at least 2 crack particles, got " + std::to_string(n));
  // One value per id, each finite.
  auto per_id = [&](const char* name, const auto& array) {
    check_length(type, id, name, array, n);
    check_finite(type, id, name, array);
  };
  per_id("x", crack.x());
  per_id("y", crack.y());
  per_id("nx", crack.nx());
  per_id("ny", crack.ny());
  per_id("width", crack.width());
  check_length(type, id, "tip", crack.tip(), n);
  check_unique_ids(type, id, crack.ids());
  const bool response =
      crack.opening_rate_size() > 0 || crack.opening_acceleration_size() > 0 || crack.opening_compliance_size() > 0;
  const bool plane = crack.plane_rate_x_size() > 0 || crack.plane_rate_y_size() > 0 ||
                     crack.plane_acceleration_x_size() > 0 || crack.plane_acceleration_y_size() > 0;
  if (plane && !response)
    fail(type, id, "plane_rate / plane_acceleration come only with the opening_* response arrays");
  if (response) {
    per_id("opening_rate", crack.opening_rate());
    per_id("opening_acceleration", crack.opening_acceleration());
    const std::uint32_t band = crack.opening_compliance_band();
    if (band >= static_cast<std::uint32_t>(n)) {
      fail(type, id,
           "opening_compliance_band = " + std::to_string(band) + "; it must be less than the " + std::to_string(n) +
               " ids");
    }
    const auto expected = static_cast<std::int64_t>(n) * (2 * static_cast<std::int64_t>(band) + 1);
    if (crack.opening_compliance_size() != expected) {
      fail(type, id,
           "array 'opening_compliance' has " + std::to_string(crack.opening_compliance_size()) + " entries; with " +
               std::to_string(n) + " ids and opening_compliance_band " + std::to_string(band) + " it needs " +
               std::to_string(expected) + " (ids x (2 band + 1))");
    }
    check_finite(type, id, "opening_compliance", crack.opening_compliance());
    if (plane) {
      per_id("plane_rate_x", crack.plane_rate_x());
      per_id("plane_rate_y", crack.plane_rate_y());
      per_id("plane_acceleration_x", crack.plane_acceleration_x());
      per_id("plane_acceleration_y", crack.plane_acceleration_y());
    }
  }
  for (const auto& [name, value] : {std::pair<const char*, double>{"tip_modulus_pa", crack.tip_modulus_pa()},
                                    {"resolution_m", crack.resolution_m()},
                                    {"start_tip_modulus_pa", crack.start_tip_modulus_pa()}}) {
    if (!(value >= 0) || !std::isfinite(value))
      fail(type, id, std::string(name) + " = " + std::to_string(value) + "; it must be finite and >= 0 (0: not sent)");
  }

  if (crack.has_inlet_id()) {
    // The fluid enters at an inner particle: one of the ids, neither end.
    const auto& ids = crack.ids();
    const auto at = std::find(ids.begin(), ids.end(), crack.inlet_id());
    if (at == ids.end() || at == ids.begin() || at + 1 == ids.end()) {
      fail(type, id,
           "inlet_id = " + std::to_string(crack.inlet_id()) +
               "; it must be the id of one of the crack's inner particles (neither its first nor its last)");
    }
  }

  CrackGeometry out;
  out.crack_id = id;
  out.grew = crack.grew();
  out.has_inlet = crack.has_inlet_id();
  out.inlet_id = crack.inlet_id();
  out.start_tip_modulus = crack.start_tip_modulus_pa();
  out.tip_modulus = crack.tip_modulus_pa();
  out.resolution = crack.resolution_m();
  out.ids.assign(crack.ids().begin(), crack.ids().end());
  out.width.assign(crack.width().begin(), crack.width().end());
  out.opening_rate.assign(crack.opening_rate().begin(), crack.opening_rate().end());
  out.opening_acceleration.assign(crack.opening_acceleration().begin(), crack.opening_acceleration().end());
  out.opening_compliance.assign(crack.opening_compliance().begin(), crack.opening_compliance().end());
  out.compliance_band = response ? crack.opening_compliance_band() : 0;
  for (int i = 0; response && i < crack.plane_rate_x_size(); ++i) {
    out.plane_rate.emplace_back(crack.plane_rate_x(i), crack.plane_rate_y(i));
    out.plane_acceleration.emplace_back(crack.plane_acceleration_x(i), crack.plane_acceleration_y(i));
  }
  out.position.resize(static_cast<std::size_t>(n));
  out.normal.resize(static_cast<std::size_t>(n));
  out.tip.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    out.position[k] = Vec2(crack.x(i), crack.y(i));
    out.normal[k] = Vec2(crack.nx(i), crack.ny(i));
    out.tip[k] = crack.tip(i) ? 1 : 0;
    if (std::abs(out.normal[k].norm() - 1.0) > 1e-6) {
      fail(type, id,
           "normal " + std::to_string(i) + " has length " + std::to_string(out.normal[k].norm()) +
               "; normals must be unit vectors");
    }
    if (out.width[k] < 0) {
      fail(type, id, "width[" + std::to_string(i) + "] = " + std::to_string(out.width[k]) + " m; widths are >= 0");
    }
  }
  return out;
}

void to_proto(const CrackPressure& crack, protocol::FluidState::Crack* out) {
  out->Clear();
  out->set_crack_id(crack.crack_id);
  out->mutable_ids()->Add(crack.ids.begin(), crack.ids.end());
  out->mutable_pressure()->Add(crack.pressure.begin(), crack.pressure.end());
  out->mutable_stiffness()->Add(crack.stiffness.begin(), crack.stiffness.end());
  out->mutable_width()->Add(crack.width.begin(), crack.width.end());
  out->set_front_position(crack.front_position);
  out->set_front_start_position(crack.front_start_position);
  out->set_inlet_flux(crack.inlet_flux);
  out->set_fluid_volume(crack.fluid_volume);
}

CrackPressure from_proto(const protocol::FluidState::Crack& crack) {
  constexpr std::string_view type = "FluidState";
  const std::uint32_t id = crack.crack_id();
  const int n = crack.ids_size();
  check_length(type, id, "pressure", crack.pressure(), n);
  check_finite(type, id, "pressure", crack.pressure());
  check_unique_ids(type, id, crack.ids());
  if (crack.stiffness_size() > 0 || crack.width_size() > 0) {
    check_length(type, id, "stiffness", crack.stiffness(), n);
    check_length(type, id, "width", crack.width(), n);
    check_finite(type, id, "stiffness", crack.stiffness());
    check_finite(type, id, "width", crack.width());
    for (double v : crack.stiffness()) {
      if (v < 0) fail(type, id, "stiffness (-dp/dw) must be >= 0");
    }
    for (double v : crack.width()) {
      if (v < 0) fail(type, id, "width must be >= 0");
    }
  }
  for (double v : {crack.front_position(), crack.front_start_position(), crack.inlet_flux(), crack.fluid_volume()}) {
    if (!std::isfinite(v))
      fail(type, id, "front_position, front_start_position, inlet_flux and fluid_volume must be finite");
  }
  if (crack.front_start_position() < 0)
    fail(type, id, "front_start_position = " + std::to_string(crack.front_start_position()) + "; it must be >= 0");
  CrackPressure out;
  out.crack_id = id;
  out.ids.assign(crack.ids().begin(), crack.ids().end());
  out.pressure.assign(crack.pressure().begin(), crack.pressure().end());
  out.stiffness.assign(crack.stiffness().begin(), crack.stiffness().end());
  out.width.assign(crack.width().begin(), crack.width().end());
  out.front_position = crack.front_position();
  out.front_start_position = crack.front_start_position();
  out.inlet_flux = crack.inlet_flux();
  out.fluid_volume = crack.fluid_volume();
  return out;
}

void to_proto(const SideDiagnostics& d, protocol::Diagnostics* out) {
  out->set_kinetic_energy(d.kinetic_energy);
  out->set_crack_length(d.crack_length);
  out->set_mouth_opening(d.mouth_opening);
  out->set_crack_face_load(d.crack_face_load);
  out->set_inlet_pressure(d.inlet_pressure);
  out->set_injected_volume(d.injected_volume);
  out->set_fluid_volume(d.fluid_volume);
  out->set_front_position(d.front_position);
  out->set_crack_particles(d.crack_particles);
  out->set_fluid_particles(d.fluid_particles);
  out->set_coupling_lag(d.coupling_lag);
  out->set_strain_energy(d.strain_energy);
  out->set_released_energy(d.released_energy);
}

SideDiagnostics from_proto(const protocol::Diagnostics& d) {
  SideDiagnostics out;
  out.kinetic_energy = d.kinetic_energy();
  out.crack_length = d.crack_length();
  out.mouth_opening = d.mouth_opening();
  out.crack_face_load = d.crack_face_load();
  out.inlet_pressure = d.inlet_pressure();
  out.injected_volume = d.injected_volume();
  out.fluid_volume = d.fluid_volume();
  out.front_position = d.front_position();
  out.crack_particles = d.crack_particles();
  out.fluid_particles = d.fluid_particles();
  out.coupling_lag = d.coupling_lag();
  out.strain_energy = d.strain_energy();
  out.released_energy = d.released_energy();
  return out;
}

}  // namespace hfmpm::proto
