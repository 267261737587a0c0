// The problem's own checks, its parsing and the in-situ stress on its notch
// (app/scene_builder.hpp): what `hfmpm scene` refuses before it derives anything.
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include <cmath>
#include <numbers>
#include <regex>

#include "hfmpm/coupling/number_text.hpp"
#include "scene_builder.hpp"

namespace hfmpm::app {
namespace {

using text::join;
using text::num;

struct ErrorCollector : google::protobuf::io::ErrorCollector {
  std::vector<std::string> errors;
  std::string name;
  void AddError(int line, int column, const std::string& message) override {
    errors.push_back(name + ":" + std::to_string(line + 1) + ":" + std::to_string(column + 1) + ": " + message);
  }
};

// The checks of a problem: each failing one adds "key = value is not allowed; allowed: range".
class Checks {
 public:
  void require(bool present, const std::string& key) {
    if (!present) problems_.push_back(key + " is required");
  }
  void range(const std::string& key, double v, bool ok, const std::string& allowed) {
    if (!ok || !std::isfinite(v)) problems_.push_back(key + " = " + num(v) + " is not allowed; allowed: " + allowed);
  }
  void fail(const std::string& line) { problems_.push_back(line); }
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

}  // namespace

// The in-situ stress in the grid's axes (compression positive) and on the
// notch's plane.
NotchStresses notch_stresses(const problem::Problem& p) {
  constexpr double kDeg = std::numbers::pi / 180;
  const auto& s = p.in_situ();
  NotchStresses out;
  if (s.has_normal_to_crack_pa()) {
    out.xx = s.has_along_crack_pa() ? s.along_crack_pa() : s.normal_to_crack_pa();
    out.yy = s.normal_to_crack_pa();
  } else {
    const double lo = s.sigma_hmin_pa(), hi = s.has_sigma_hmax_pa() ? s.sigma_hmax_pa() : lo;
    const double a = s.sigma_hmax_azimuth_deg() * kDeg, c = std::cos(a), sn = std::sin(a);
    out.xx = hi * c * c + lo * sn * sn;
    out.yy = hi * sn * sn + lo * c * c;
    out.xy = (hi - lo) * sn * c;
    out.minimum = lo;
  }
  if (s.has_normal_to_crack_pa()) out.minimum = std::min(out.xx, out.yy);
  const double b = p.notch_azimuth_deg() * kDeg;
  const double tx = std::cos(b), ty = std::sin(b), nx = -ty, ny = tx;
  out.normal = out.xx * nx * nx + out.yy * ny * ny + 2 * out.xy * nx * ny;
  out.along = out.xx * tx * tx + out.yy * ty * ty + 2 * out.xy * tx * ty;
  out.shear = out.xx * tx * nx + out.yy * ty * ny + out.xy * (tx * ny + ty * nx);
  return out;
}

namespace {

void check(const problem::Problem& p, Checks& c) {
  c.require(p.has_name(), "name");
  if (p.has_name() && !std::regex_match(p.name(), std::regex("[A-Za-z0-9_.-]{1,64}"))) {
    c.fail("name = '" + p.name() + "' is not allowed; allowed: 1 to 64 of [A-Za-z0-9_.-]");
  }
  c.require(p.has_rock(), "rock");
  c.require(p.has_in_situ(), "in_situ");
  c.require(p.has_fluid(), "fluid");
  c.require(p.has_injection(), "injection");
  c.require(p.has_duration_s(), "duration_s");
  c.require(p.has_notch_m(), "notch_m");
  if (p.has_duration_s()) c.range("duration_s", p.duration_s(), p.duration_s() > 0, "> 0 s");
  if (p.has_notch_m()) c.range("notch_m", p.notch_m(), p.notch_m() > 0, "> 0 m");
  if (p.has_rock()) {
    const auto& r = p.rock();
    c.require(r.has_youngs_modulus_pa(), "rock.youngs_modulus_pa");
    c.require(r.has_poisson_ratio(), "rock.poisson_ratio");
    c.require(r.has_toughness_pa_sqrt_m(), "rock.toughness_pa_sqrt_m");
    c.range("rock.youngs_modulus_pa", r.youngs_modulus_pa(), !r.has_youngs_modulus_pa() || r.youngs_modulus_pa() > 0,
            "> 0 Pa");
    c.range("rock.poisson_ratio", r.poisson_ratio(), r.poisson_ratio() >= 0 && r.poisson_ratio() < 0.5, "[0, 0.5)");
    c.range("rock.density_kg_m3", r.density_kg_m3(), r.density_kg_m3() > 0, "> 0 kg/m^3");
    c.range("rock.toughness_pa_sqrt_m", r.toughness_pa_sqrt_m(), r.toughness_pa_sqrt_m() >= 0, ">= 0 Pa m^0.5");
  }
  if (p.has_in_situ()) {
    const auto& s = p.in_situ();
    const bool principal = s.has_sigma_hmin_pa() || s.has_sigma_hmax_pa() || s.has_sigma_hmax_azimuth_deg();
    if (principal && (s.has_normal_to_crack_pa() || s.has_along_crack_pa())) {
      c.fail(
          "in_situ gives both forms; allowed: normal_to_crack_pa (and along_crack_pa) for a notch along x, or "
          "sigma_hmin_pa, sigma_hmax_pa and sigma_hmax_azimuth_deg");
    } else if (principal) {
      c.require(s.has_sigma_hmin_pa(), "in_situ.sigma_hmin_pa");
      c.range("in_situ.sigma_hmin_pa", s.sigma_hmin_pa(), s.sigma_hmin_pa() >= 0, ">= 0 Pa (a compressive magnitude)");
      if (s.has_sigma_hmax_pa()) {
        c.range("in_situ.sigma_hmax_pa", s.sigma_hmax_pa(), s.sigma_hmax_pa() >= s.sigma_hmin_pa(),
                ">= in_situ.sigma_hmin_pa (" + num(s.sigma_hmin_pa()) + " Pa): sigma_H is the larger");
      }
      c.range("in_situ.sigma_hmax_azimuth_deg", s.sigma_hmax_azimuth_deg(),
              s.sigma_hmax_azimuth_deg() > -90 && s.sigma_hmax_azimuth_deg() <= 90, "(-90, 90] degrees from x");
    } else {
      c.require(s.has_normal_to_crack_pa(), "in_situ.normal_to_crack_pa");
      c.range("in_situ.normal_to_crack_pa", s.normal_to_crack_pa(), s.normal_to_crack_pa() >= 0,
              ">= 0 Pa (a compressive magnitude)");
      if (s.has_along_crack_pa()) {
        c.range("in_situ.along_crack_pa", s.along_crack_pa(), s.along_crack_pa() >= 0,
                ">= 0 Pa (a compressive magnitude)");
      }
    }
  }
  c.range("notch_azimuth_deg", p.notch_azimuth_deg(), p.notch_azimuth_deg() > -90 && p.notch_azimuth_deg() <= 90,
          "(-90, 90] degrees from x");
  if (p.notch_azimuth_deg() != 0 && !p.injection().both_wings()) {
    c.fail("notch_azimuth_deg = " + num(p.notch_azimuth_deg()) +
           " needs injection { both_wings: true }: a notch at an angle has no symmetry plane through the well");
  }
  if (p.notch_azimuth_deg() != 0 && p.has_in_situ() && p.in_situ().has_normal_to_crack_pa()) {
    c.fail("notch_azimuth_deg = " + num(p.notch_azimuth_deg()) +
           " needs the in-situ stress as in_situ { sigma_hmin_pa sigma_hmax_pa sigma_hmax_azimuth_deg } "
           "(normal_to_crack_pa "
           "is for a notch along x)");
  }
  c.range("notch_friction_coefficient", p.notch_friction_coefficient(),
          p.notch_friction_coefficient() >= 0 && std::isfinite(p.notch_friction_coefficient()),
          ">= 0 (0: frictionless)");
  if (p.has_fluid()) {
    const auto& f = p.fluid();
    c.require(f.has_viscosity_pa_s(), "fluid.viscosity_pa_s");
    c.range("fluid.density_kg_m3", f.density_kg_m3(), f.density_kg_m3() > 0, "> 0 kg/m^3");
    // The notch is filled at the confining stress, and no liquid's equation of
    // state holds at pressures above its bulk modulus (the scene's own rule).
    const double sigma_n = p.has_in_situ() ? notch_stresses(p).normal : 0;
    c.range("fluid.bulk_modulus_pa", f.bulk_modulus_pa(), f.bulk_modulus_pa() > 0 && f.bulk_modulus_pa() >= sigma_n,
            "> 0 Pa and at least in_situ.normal_to_crack_pa (" + num(sigma_n) +
                " Pa): the fluid fills the notch at that pressure, and Tait's equation of state does not hold "
                "above the bulk modulus");
    c.range("fluid.viscosity_pa_s", f.viscosity_pa_s(), !f.has_viscosity_pa_s() || f.viscosity_pa_s() > 0,
            "> 0 Pa s (the builder sizes the run by the viscous and toughness vertices)");
  }
  if (p.has_injection()) {
    const auto& i = p.injection();
    c.require(i.has_total_rate_m2_s(), "injection.total_rate_m2_s");
    c.range("injection.total_rate_m2_s", i.total_rate_m2_s(), !i.has_total_rate_m2_s() || i.total_rate_m2_s() > 0,
            "> 0 m^2/s");
    if (i.has_ramp_s()) {
      const bool ok = i.ramp_s() >= 0 && (!p.has_duration_s() || i.ramp_s() <= 0.5 * p.duration_s());
      c.range("injection.ramp_s", i.ramp_s(), ok, "[0, duration_s / 2] s");
    }
  }
  const auto& a = p.accuracy();
  c.range("accuracy.cells_per_half_length", a.cells_per_half_length(),
          a.cells_per_half_length() >= 8 && a.cells_per_half_length() <= 200, "[8, 200]");
  c.range("accuracy.box_half_lengths", a.box_half_lengths(), a.box_half_lengths() >= 2 && a.box_half_lengths() <= 20,
          "[2, 20]");
}

}  // namespace

ProblemError::ProblemError(const std::vector<std::string>& lines) : std::runtime_error(join(lines)), problems(lines) {}

problem::Problem parse_problem(const std::string& text, const std::string& name) {
  problem::Problem p;
  google::protobuf::TextFormat::Parser parser;
  ErrorCollector errors;
  errors.name = name;
  parser.RecordErrorsTo(&errors);
  if (!parser.ParseFromString(text, &p)) {
    if (errors.errors.empty()) errors.errors.push_back(name + ": not a problem file (problem.proto text format)");
    throw ProblemError(errors.errors);
  }
  return p;
}

std::vector<std::string> problem_problems(const problem::Problem& p) {
  Checks checks;
  check(p, checks);
  return checks.problems();
}

}  // namespace hfmpm::app
