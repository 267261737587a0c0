// Stand-in fluid: the pressure on every crack it is given is a formula of time
// and arc length. No flow is computed; the fluid volume is the integral of the
// received width over the wetted length, so the widths it reports on are the
// widths the solid sent. Lets the solid, coupler and protocol be tested alone.
#pragma once

#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::fluid {

struct PrescribedPressureConfig {
  enum class Profile { Uniform, Linear };
  TimeFunction inlet_pressure;  // Pa, p_inlet(t)
  Profile profile = Profile::Uniform;
  double front_fraction = 1;  // front at this fraction of the crack length, (0, 1]
  double stable_dt = 1e-3;    // s, the step this stand-in reports
};

class PrescribedPressure {
 public:
  explicit PrescribedPressure(const PrescribedPressureConfig& config) : config_(config) {}

  // The cracks from the solid. A crack seen before must keep its ids as a
  // prefix (growth appends ids); throws std::invalid_argument otherwise.
  void set_geometry(const std::vector<CrackGeometry>& cracks);

  void advance(double dt);

  double time() const { return t_; }
  double stable_dt() const { return config_.stable_dt; }
  // Pressure at every crack particle of every crack, at the current time.
  std::vector<CrackPressure> pressures() const;
  SideDiagnostics diagnostics() const;

 private:
  struct CrackFlow {
    CrackGeometry geometry;
    std::vector<double> arc;  // m
    double volume = 0;        // m^2, wetted volume now
    double previous_volume = 0;
    double flux = 0;  // m^2/s
  };
  double pressure_at(double s, double front) const;
  double wetted_volume(const CrackFlow& crack) const;

  PrescribedPressureConfig config_;
  double t_ = 0;
  std::vector<CrackFlow> cracks_;
};

}  // namespace hfmpm::fluid
