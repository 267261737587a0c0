#include "hfmpm/solid/prescribed_crack.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hfmpm::solid {

PrescribedCrack::PrescribedCrack(const PrescribedCrackConfig& config) : config_(config) {
  const double segments = std::max(1.0, std::round(config.initial_length / config.spacing));
  h_ = config.initial_length / segments;
  for (int i = 0; i <= static_cast<int>(segments); ++i) append_particle();
  crack_.grew = false;
  update_widths();
}

void PrescribedCrack::append_particle() {
  const Vec2 direction(std::cos(config_.angle_rad), std::sin(config_.angle_rad));
  const Vec2 normal(-direction.y(), direction.x());  // "above" is to the left of mouth -> tip
  const double s = arc_.empty() ? 0.0 : arc_.back() + h_;
  const bool channel = config_.profile == PrescribedCrackConfig::Profile::Channel;
  if (!crack_.tip.empty()) crack_.tip.back() = 0;
  crack_.ids.push_back(crack_.ids.size());  // ids 0, 1, 2, ... from the mouth; never reused
  crack_.position.push_back(config_.mouth + s * direction);
  crack_.normal.push_back(normal);
  crack_.width.push_back(0.0);  // a new particle starts closed (a channel's is set by update_widths)
  crack_.tip.push_back(channel ? 0 : 1);
  crack_.grew = true;
  arc_.push_back(s);
  pressure_.push_back(0.0);
}

double PrescribedCrack::width_at(double s) const {
  const double w0 = std::max(0.0, config_.mouth_opening(t_));
  const double length = arc_.back();
  if (config_.profile == PrescribedCrackConfig::Profile::Channel) return s <= length ? w0 : 0.0;
  if (s >= length) return 0.0;
  if (config_.profile == PrescribedCrackConfig::Profile::Uniform) return w0;
  const double r = s / length;
  return w0 * std::sqrt(std::max(0.0, 1.0 - r * r));
}

void PrescribedCrack::update_widths() {
  const double w0 = std::max(0.0, config_.mouth_opening(t_));
  const double length = arc_.back();
  const bool elliptic = config_.profile == PrescribedCrackConfig::Profile::Elliptic;
  if (config_.profile == PrescribedCrackConfig::Profile::Channel) {
    std::fill(crack_.width.begin(), crack_.width.end(), w0);
    return;
  }
  for (std::size_t i = 0; i < crack_.size(); ++i) {
    const double r = arc_[i] / length;
    crack_.width[i] = arc_[i] >= length ? 0.0 : elliptic ? w0 * std::sqrt(std::max(0.0, 1.0 - r * r)) : w0;
  }
}

void PrescribedCrack::advance(double dt) {
  t_ += dt;
  const double target = std::min(config_.max_length, config_.initial_length + config_.growth_speed * t_);
  // 1e-9 h: a length that reaches the next position up to round-off counts as reached.
  while (arc_.back() + h_ <= target + 1e-9 * h_) append_particle();
  update_widths();
}

void PrescribedCrack::set_pressure(const CrackPressure& pressure) {
  if (pressure.size() > crack_.size()) {
    throw std::invalid_argument("pressure for " + std::to_string(pressure.size()) + " crack particles, but crack " +
                                std::to_string(crack_.crack_id) + " has " + std::to_string(crack_.size()));
  }
  for (std::size_t i = 0; i < pressure.size(); ++i) {
    if (pressure.ids[i] != crack_.ids[i]) {
      throw std::invalid_argument("pressure id " + std::to_string(pressure.ids[i]) + " at index " + std::to_string(i) +
                                  " where crack " + std::to_string(crack_.crack_id) + " has particle " +
                                  std::to_string(crack_.ids[i]) +
                                  "; pressure ids must follow the crack's ids in order");
    }
  }
  // All ids checked: nothing is half-applied when they do not match.
  for (std::size_t i = 0; i < crack_.size(); ++i) pressure_[i] = i < pressure.size() ? pressure.pressure[i] : 0.0;
}

SideDiagnostics PrescribedCrack::diagnostics() const {
  SideDiagnostics d;
  d.crack_length = length();
  d.mouth_opening = crack_.width.front();
  d.crack_particles = static_cast<std::uint32_t>(crack_.size());
  // Trapezoidal integral of the received pressure along the crack: the normal
  // load the faces would carry (N/m per face).
  for (std::size_t i = 1; i < arc_.size(); ++i) {
    d.crack_face_load += 0.5 * (pressure_[i - 1] + pressure_[i]) * (arc_[i] - arc_[i - 1]);
  }
  return d;
}

}  // namespace hfmpm::solid
