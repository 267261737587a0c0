#include "hfmpm/fluid/prescribed_pressure.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace hfmpm::fluid {

void PrescribedPressure::set_geometry(const std::vector<CrackGeometry>& cracks) {
  for (const auto& geometry : cracks) {
    auto it = std::find_if(cracks_.begin(), cracks_.end(),
                           [&](const CrackFlow& c) { return c.geometry.crack_id == geometry.crack_id; });
    if (it == cracks_.end()) {
      cracks_.push_back(CrackFlow{});
      it = std::prev(cracks_.end());
    } else {
      check_crack_update(geometry.crack_id, it->geometry.ids, geometry.ids, &geometry.grew);
    }
    it->geometry = geometry;
    it->arc = arc_length(geometry.position);
    it->volume = wetted_volume(*it);
  }
}

double PrescribedPressure::pressure_at(double s, double front) const {
  if (s > front) return 0.0;  // lag zone beyond the front
  const double p = std::max(0.0, config_.inlet_pressure(t_));
  if (config_.profile == PrescribedPressureConfig::Profile::Linear) return front > 0 ? p * (1 - s / front) : 0.0;
  return p;
}

double PrescribedPressure::wetted_volume(const CrackFlow& crack) const {
  // Trapezoidal integral of the width from the mouth to the front, with the
  // width interpolated linearly at the front.
  const double front = config_.front_fraction * crack.arc.back();
  double volume = 0;
  for (std::size_t i = 1; i < crack.arc.size(); ++i) {
    const double s0 = crack.arc[i - 1], s1 = crack.arc[i];
    if (s0 >= front) break;
    const double w0 = crack.geometry.width[i - 1], w1 = crack.geometry.width[i];
    const double end = std::min(s1, front);
    const double w_end = w0 + (w1 - w0) * (end - s0) / (s1 - s0);
    volume += 0.5 * (w0 + w_end) * (end - s0);
  }
  return volume;
}

void PrescribedPressure::advance(double dt) {
  t_ += dt;
  for (auto& crack : cracks_) {
    crack.flux = (crack.volume - crack.previous_volume) / dt;
    crack.previous_volume = crack.volume;
  }
}

std::vector<CrackPressure> PrescribedPressure::pressures() const {
  std::vector<CrackPressure> out;
  out.reserve(cracks_.size());
  for (const auto& crack : cracks_) {
    CrackPressure p;
    p.crack_id = crack.geometry.crack_id;
    p.ids = crack.geometry.ids;
    p.front_position = config_.front_fraction * crack.arc.back();
    p.pressure.reserve(crack.arc.size());
    for (const double s : crack.arc) p.pressure.push_back(pressure_at(s, p.front_position));
    p.inlet_flux = crack.flux;
    p.fluid_volume = crack.volume;
    out.push_back(std::move(p));
  }
  return out;
}

SideDiagnostics PrescribedPressure::diagnostics() const {
  SideDiagnostics d;
  d.inlet_pressure = std::max(0.0, config_.inlet_pressure(t_));
  for (const auto& crack : cracks_) {
    d.fluid_volume += crack.volume;
    d.front_position = std::max(d.front_position, config_.front_fraction * crack.arc.back());
  }
  d.injected_volume = d.fluid_volume;  // incompressible stand-in without leak-off
  return d;
}

}  // namespace hfmpm::fluid
