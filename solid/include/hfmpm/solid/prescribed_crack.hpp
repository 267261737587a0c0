// Stand-in solid: one straight crack whose opening is a formula of time and
// arc length, growing at a set speed. It has no mechanics; it exists so the
// fluid side, the coupler and the protocol can be tested without the MPM solid.
#pragma once

#include "hfmpm/exchange.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::solid {

struct PrescribedCrackConfig {
  // Channel: uniform width up to and including the last particle, which is
  // not a tip (an open far end: a rigid channel for fluid checks).
  enum class Profile { Elliptic, Uniform, Channel };
  Vec2 mouth = Vec2::Zero();   // m
  double angle_rad = 0;        // direction mouth -> tip
  double initial_length = 1;   // m, > 0
  double growth_speed = 0;     // m/s, >= 0
  double max_length = 1;       // m, >= initial_length
  double spacing = 0.1;        // m, target crack-particle spacing
  TimeFunction mouth_opening;  // m, w_mouth(t)
  Profile profile = Profile::Elliptic;
  double stable_dt = 1e-3;  // s, the step this stand-in reports
};

class PrescribedCrack {
 public:
  explicit PrescribedCrack(const PrescribedCrackConfig& config);

  // Advances the time by dt: appends crack particles while L(t) passes the
  // next particle position, then sets every width from the formula.
  void advance(double dt);

  // Pressures from the fluid for this crack. Their ids must be a prefix of the
  // crack's ids, in order (the fluid may not have seen the newest particles).
  void set_pressure(const CrackPressure& pressure);

  const CrackGeometry& geometry() const { return crack_; }
  void clear_grew() { crack_.grew = false; }
  double time() const { return t_; }
  double stable_dt() const { return config_.stable_dt; }
  double length() const { return arc_.back(); }
  // Width of the formula at arc length s on the current crack.
  double width_at(double s) const;
  SideDiagnostics diagnostics() const;

 private:
  void append_particle();
  void update_widths();

  PrescribedCrackConfig config_;
  double h_ = 0;  // m, actual spacing: initial_length / round(initial_length / spacing)
  double t_ = 0;  // s
  CrackGeometry crack_;
  std::vector<double> arc_;       // m, arc length of each particle
  std::vector<double> pressure_;  // Pa, received, per particle (0 where not received)
};

}  // namespace hfmpm::solid
