#include "hfmpm/coupling/method.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "hfmpm/coupling/number_text.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::method {
namespace {

namespace pb = google::protobuf;
using text::approx;
using text::num;
using text::significant;

// The field at a dotted path of singular fields, its message created on the
// way; null when a component is not a field.
pb::Message* parent_of(pb::Message& root, const std::string& key, const pb::FieldDescriptor** field) {
  pb::Message* message = &root;
  std::stringstream parts(key);
  std::string part;
  std::vector<std::string> components;
  while (std::getline(parts, part, '.')) components.push_back(part);
  for (std::size_t i = 0; i < components.size(); ++i) {
    const auto* f = message->GetDescriptor()->FindFieldByName(components[i]);
    if (!f || f->is_repeated()) return nullptr;
    if (i + 1 == components.size()) {
      *field = f;
      return message;
    }
    message = message->GetReflection()->MutableMessage(message, f);
  }
  return nullptr;
}

bool is_set(const scene::Scene& scene, const std::string& key) {
  scene::Scene probe = scene;  // reading must not create blocks in the scene itself
  const pb::FieldDescriptor* field = nullptr;
  pb::Message* parent = parent_of(probe, key, &field);
  return parent && parent->GetReflection()->HasField(*parent, field);
}

// Sets `key` to `value` (text format) where the scene leaves it unset, and
// records it. A value that does not parse is a bug here, not the user's.
void derive_key(scene::Scene& scene, std::vector<Setting>& applied, const std::string& key, const std::string& value,
                const std::string& rule) {
  if (is_set(scene, key)) return;
  const pb::FieldDescriptor* field = nullptr;
  pb::Message* parent = parent_of(scene, key, &field);
  if (!parent) throw std::logic_error("derived method: no scene key " + key);
  const std::string separator = field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE ? " " : ": ";
  if (!pb::TextFormat::MergeFromString(field->name() + separator + value, parent)) {
    throw std::logic_error("derived method: " + key + " = " + value + " does not parse");
  }
  applied.push_back({key, value, rule});
}

// A rate function the scene's rules would accept, so that it can be
// evaluated here (the method is derived before those rules run).
bool well_formed(const scene::TimeFunction& f) {
  auto finite = [](double v) { return std::isfinite(v); };
  switch (f.kind_case()) {
    case scene::TimeFunction::kConstant:
      return finite(f.constant());
    case scene::TimeFunction::kRamp:
      return f.ramp().has_t1() && f.ramp().has_v1() && finite(f.ramp().t0()) && finite(f.ramp().v0()) &&
             finite(f.ramp().t1()) && finite(f.ramp().v1()) && f.ramp().t1() > f.ramp().t0();
    case scene::TimeFunction::kTable: {
      const auto& t = f.table().t();
      const auto& v = f.table().v();
      if (t.empty() || t.size() != v.size()) return false;
      for (int i = 0; i < t.size(); ++i) {
        if (!finite(t[i]) || !finite(v[i]) || (i > 0 && !(t[i] > t[i - 1]))) return false;
      }
      return true;
    }
    case scene::TimeFunction::kPower:
      return finite(f.power().scale()) && finite(f.power().exponent()) && f.power().exponent() >= 0 &&
             finite(f.power().t_ref()) && f.power().t_ref() > 0;
    default:
      return false;
  }
}

// The injected volume over [0, end] divided by the rate at `end`: the time
// the end rate takes to inject it (a constant rate: `end`; a ramp over t_r
// from zero: end - t_r / 2). Ramps and tables are integrated exactly between
// their points, a power law in closed form.
double effective_time(const scene::TimeFunction& f, double end) {
  const TimeFunction rate = proto::to_time_function(f);
  const double at_end = rate(end);
  if (!(at_end > 0)) return 0;
  if (f.has_power()) return end / (f.power().exponent() + 1);
  std::vector<double> at{0.0};
  if (f.has_ramp()) at.insert(at.end(), {f.ramp().t0(), f.ramp().t1()});
  if (f.has_table()) at.insert(at.end(), f.table().t().begin(), f.table().t().end());
  at.push_back(end);
  std::sort(at.begin(), at.end());
  double volume = 0;
  for (std::size_t i = 1; i < at.size(); ++i) {
    const double a = std::clamp(at[i - 1], 0.0, end), b = std::clamp(at[i], 0.0, end);
    volume += 0.5 * (rate(a) + rate(b)) * (b - a);
  }
  return volume / at_end;
}

bool contains(const scene::RegionSpec& r, double x, double y) {
  if (r.has_rectangle()) {
    const auto& b = r.rectangle();
    return x >= b.x_min_m() && x <= b.x_max_m() && y >= b.y_min_m() && y <= b.y_max_m();
  }
  if (r.has_layer()) return y >= r.layer().y_min_m() && y <= r.layer().y_max_m();
  if (r.has_polygon()) {
    const auto& p = r.polygon();
    bool inside = false;
    const int n = std::min(p.x_m_size(), p.y_m_size());
    for (int i = 0, j = n - 1; i < n; j = i++) {
      if ((p.y_m(i) > y) != (p.y_m(j) > y) &&
          x < (p.x_m(j) - p.x_m(i)) * (y - p.y_m(i)) / (p.y_m(j) - p.y_m(i)) + p.x_m(i)) {
        inside = !inside;
      }
    }
    return inside;
  }
  return false;
}

// The in-situ stress is in equilibrium on its own (the solid's rule for
// in_situ_reference: rectangles or layers, equal tractions across them).
bool in_situ_in_equilibrium(const scene::MpmSolid& m) {
  bool stressed = false;
  for (int i = 0; i < m.regions_size(); ++i) {
    const auto& r = m.regions(i);
    if (r.has_polygon()) return false;
    const auto& b = r.initial_stress();
    stressed = stressed || b.xx_pa() != 0 || b.yy_pa() != 0 || b.xy_pa() != 0;
    for (int j = 0; j < i; ++j) {
      const auto& a = m.regions(j).initial_stress();
      const bool layers = r.has_layer() && m.regions(j).has_layer();
      if (!(a.yy_pa() == b.yy_pa() && a.xy_pa() == b.xy_pa() && (layers || a.xx_pa() == b.xx_pa()))) return false;
    }
  }
  return stressed;
}

}  // namespace

Vertex m_vertex(double e_prime, double viscosity, double total_rate, double t) {
  const double mu = 12 * viscosity, q = total_rate;
  Vertex v;
  v.half_length = 0.6152 * std::pow(e_prime * q * q * q * t * t * t * t / mu, 1.0 / 6);
  v.opening = 1.126 * std::pow(mu * q * q * q * t * t / e_prime, 1.0 / 6);
  v.net_pressure = 0.545 * std::cbrt(mu * e_prime * e_prime / t);
  return v;
}

Vertex k_vertex(double e_prime, double toughness, double total_rate, double t) {
  const double k = std::sqrt(32 / std::numbers::pi) * toughness, q = total_rate;
  Vertex v;
  v.half_length = 2 / std::cbrt(std::numbers::pi * std::numbers::pi) * std::pow(e_prime * q * t / k, 2.0 / 3);
  v.opening = std::cbrt(k * k * q * t / (std::numbers::pi * e_prime * e_prime));
  v.net_pressure = std::cbrt(std::numbers::pi) / 8 * std::cbrt(k * k * k * k / (e_prime * q * t));
  return v;
}

double toughness_number(double e_prime, double viscosity, double total_rate, double toughness) {
  const double k = std::sqrt(32 / std::numbers::pi) * toughness;
  return k / std::pow(e_prime * e_prime * e_prime * 12 * viscosity * total_rate, 0.25);
}

Expected expect(const Physics& p) {
  Expected x;
  x.e_prime = p.youngs_modulus / (1 - p.poisson_ratio * p.poisson_ratio);
  x.km = toughness_number(x.e_prime, p.viscosity, p.total_rate, p.toughness);
  x.viscosity_dominated = x.km < 1;
  // The closure of the nearer vertex, the transition (Km ~ 1 to 4) split at
  // its middle: at Km = 1 the toughness closure ran the crack 10% long (the
  // front's pressure taken to the tip ignores the viscous drop there) and the
  // matched viscous closure was within 5.3 / 4.3 / 4.8%; at Km = 10 the
  // matched closure ran the front 8% long and the pressure 13% high, the
  // toughness closure within 1.3 / 3.0 / 4.7% (docs/verification.md, "A
  // growth step without a jolt").
  x.matched_closure = x.km < 2;
  const Vertex m = m_vertex(x.e_prime, p.viscosity, p.total_rate, p.effective_s);
  const Vertex k = k_vertex(x.e_prime, p.toughness, p.total_rate, p.effective_s);
  x.end = x.viscosity_dominated ? m : k;
  // Viscosity and toughness both shorten the crack: it is no longer than either vertex.
  x.end.half_length = std::min(m.half_length, p.toughness > 0 ? k.half_length : m.half_length);
  return x;
}

Method derive(const Physics& p, double h, double reach, double chosen_scaling, double chosen_growth) {
  Method d;
  d.expected = expect(p);
  const double l_end = d.expected.end.half_length, t_end = p.end_s, nu = p.poisson_ratio, e = p.youngs_modulus;
  const double p_modulus = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double c_p = std::sqrt(p_modulus / p.density), c_s = std::sqrt(e / (2 * (1 + nu)) / p.density);
  // Quasi-static density scaling: the scaled P-wave crosses the final
  // half-length in 0.5% of the injection time. With toughness, the settling
  // wait after each growth step (2 shear transits of the crack) must not cap
  // the tip below its final speed, 2/3 l / t (at the end, where the cap g h
  // c_s / (2 l) is lowest against the speed). On kgd-toughness-ci's physics
  // the cap at twice that speed (scaling 2.7) left the inlet pressure's
  // sawtooth at 13.8% worst against the K-vertex at 3.0 times the cost; at
  // 5, 7.6 (this rule) and 10: 6.2%, 5.5% and 5.9% (docs/scenes.md, "The
  // derived method").
  d.tip_speed = 2.0 / 3.0 * l_end / t_end;
  double scaling = std::pow(c_p * 0.005 * t_end / l_end, 2);
  d.settle = !d.expected.viscosity_dominated;
  // Growth step and wait, g cells. Viscosity-dominated, the tip waits for
  // the fluid front and leads it by up to a wait and a step, 2 g h: keep that
  // within 2.5% of the first length compared, three notch lengths. g is the
  // largest of 1/4, 1/8, 1/16 that does (kgd-paper-field, 1 m cells, a 2 m
  // notch: tip 9.5, 5.7, 4.0% worst from three notch lengths on at 1/4, 1/8,
  // 1/16; the front, opening and pressure the same within 0.1 point from 1/8
  // on; docs/verification.md, "The growth step on a coarse notch"). With
  // toughness the settling wait scales as 1/g and a quarter stays.
  double growth = 0.25;
  if (!d.settle) {
    while (growth > 1.0 / 16 && 2 * growth * h > 0.025 * 3 * p.notch) growth /= 2;
  }
  d.growth_cells = chosen_growth > 0 ? chosen_growth : growth;
  if (d.settle) {
    const double c_s_needed = 2 * l_end * d.tip_speed / (d.growth_cells * h);
    scaling = std::min(scaling, std::pow(c_s / c_s_needed, 2));
  }
  d.density_scaling = chosen_scaling > 0 ? chosen_scaling : significant(std::max(1.0, scaling), 2, true);
  d.virtual_opening = significant(0.01 * d.expected.end.opening, 2, false);
  // Damping (mass-proportional, alpha): critical for the body's lowest mode,
  // omega_1 = pi c / (2 B) (a quarter wave across the body's reach B), but no
  // more than delays the body behind a slowly rising load, by alpha /
  // omega_1^2, 2% of the time t_3 at which the crack reaches three notch
  // lengths (both vertices grow as t^(2/3)). Over-damped (5 /s at field
  // scale), the body lagged the load and the net pressure ran 8% above the vertex.
  d.scaled_c = c_p / std::sqrt(d.density_scaling);
  d.body_omega = std::numbers::pi * d.scaled_c / (2 * reach);
  d.t_3 = p.effective_s * std::pow(std::min(1.0, 3 * p.notch / l_end), 1.5);
  double damping = std::min(2 * d.body_omega, 0.02 * d.body_omega * d.body_omega * d.t_3);
  if (d.settle) {
    // With toughness each growth step rings the crack: the release of the
    // cut runs to the mouth and back and dips the inlet pressure by up to 20%
    // a shear transit later. Damp the crack's quarter-wave mode along its
    // length at three notch lengths, omega_c = pi c_s / (2 L_3), critically,
    // within the same 2% lag (docs/verification.md, "A growth step without a jolt").
    const double l_3 = std::min(3 * p.notch, l_end);
    const double omega_c = std::numbers::pi * c_s / std::sqrt(d.density_scaling) / (2 * l_3);
    damping = std::max(damping, std::min(2 * omega_c, 0.02 * omega_c * omega_c * d.t_3));
  }
  d.damping = significant(damping, 2, true);
  // The dry tip zone carries the stress normal to the crack there: the
  // notch's, or for a crack that turns towards sigma_H the minimum stress it
  // turns to.
  d.lag_pressure = p.symmetric ? p.normal_stress : p.minimum_stress;
  return d;
}

std::optional<ScenePhysics> physics_of(const scene::Scene& s, std::string* why_not) {
  auto refuse = [why_not](const std::string& why) -> std::optional<ScenePhysics> {
    if (why_not) *why_not = why;
    return std::nullopt;
  };
  if (!s.solid().has_mpm() || !s.fluid().has_mpm()) return refuse("not an MPM solid with an MPM fluid");
  const auto& m = s.solid().mpm();
  const auto& f = s.fluid().mpm();
  if (!f.inlet().has_flow_rate_m2_s()) return refuse("the fluid's inlet gives a pressure, not a flow rate");
  if (!well_formed(f.inlet().flow_rate_m2_s())) return refuse("the inlet's flow rate is not a valid function yet");
  if (!(std::isfinite(s.time().end_s()) && s.time().end_s() > 0)) return refuse("no valid time.end_s yet");
  // The fluid's crack: the first listed, or the first with a mouth or a well.
  const scene::CrackSpecScene* crack = nullptr;
  if (f.crack_ids_size() > 0) {
    if (static_cast<int>(f.crack_ids(0)) < m.cracks_size()) crack = &m.cracks(static_cast<int>(f.crack_ids(0)));
  } else {
    for (const auto& c : m.cracks()) {
      if (!c.start_is_tip() || c.has_inlet_vertex()) {
        crack = &c;
        break;
      }
    }
  }
  if (!crack || crack->x_m_size() < 2 || crack->x_m_size() != crack->y_m_size()) return refuse("no fluid crack");
  const int n = crack->x_m_size();
  const int inlet = crack->has_inlet_vertex() ? static_cast<int>(crack->inlet_vertex()) : 0;
  if (inlet < 0 || inlet >= n) return refuse("no inlet vertex");
  double length = 0;
  bool straight = true;
  const double dx0 = crack->x_m(n - 1) - crack->x_m(0), dy0 = crack->y_m(n - 1) - crack->y_m(0);
  for (int i = 1; i < n; ++i) {
    const double dx = crack->x_m(i) - crack->x_m(i - 1), dy = crack->y_m(i) - crack->y_m(i - 1);
    length += std::hypot(dx, dy);
    if (std::abs(dx * dy0 - dy * dx0) > 1e-9 * std::hypot(dx, dy) * std::hypot(dx0, dy0)) straight = false;
  }
  const bool both = crack->has_inlet_vertex() && inlet > 0 && inlet < n - 1;
  const double x = crack->x_m(inlet), y = crack->y_m(inlet);
  const int next = inlet < n - 1 ? inlet + 1 : inlet - 1;
  double tx = crack->x_m(next) - x, ty = crack->y_m(next) - y;
  const double t_norm = std::hypot(tx, ty);
  if (!(t_norm > 0)) return refuse("the crack's first segment has no length");
  tx /= t_norm;
  ty /= t_norm;

  const scene::RegionSpec* region = nullptr;
  for (const auto& r : m.regions())
    if (contains(r, x, y)) region = &r;
  if (!region) return refuse("the well lies in no region");
  const scene::MaterialSpec* material = nullptr;
  for (const auto& mat : m.materials())
    if (mat.name() == region->material()) material = &mat;
  if (!material) return refuse("the well's region names no material");

  ScenePhysics out;
  Physics& p = out.physics;
  p.youngs_modulus = material->youngs_modulus_pa();
  p.poisson_ratio = material->poisson_ratio();
  p.density = material->density_kg_m3();
  const double e_prime = p.youngs_modulus / (1 - p.poisson_ratio * p.poisson_ratio);
  out.toughness_given = material->has_toughness_pa_sqrt_m() || material->has_toughness_j_m2();
  p.toughness = material->has_toughness_pa_sqrt_m() ? material->toughness_pa_sqrt_m()
                : material->has_toughness_j_m2()    ? std::sqrt(material->toughness_j_m2() * e_prime)
                                                    : 0.0;
  p.viscosity = f.viscosity_pa_s();
  p.end_s = s.time().end_s();
  const auto& rate = f.inlet().flow_rate_m2_s();
  // An edge crack is half of a symmetric pair: the inlet's rate is one wing's.
  p.total_rate = proto::to_time_function(rate)(p.end_s) * (both ? 1.0 : 2.0);
  p.effective_s = effective_time(rate, p.end_s);
  if (!(p.total_rate > 0) || !(p.effective_s > 0) || !(p.viscosity > 0)) {
    return refuse("no injection at the end, or an inviscid fluid: no vertex to size the run by");
  }
  p.notch = both ? 0.5 * length : length;
  // The in-situ stress at the well, compressive, on the crack's plane.
  const auto& st = region->initial_stress();
  const double sxx = -st.xx_pa(), syy = -st.yy_pa(), sxy = -st.xy_pa();
  const double nx = -ty, ny = tx;
  p.normal_stress = sxx * nx * nx + syy * ny * ny + 2 * sxy * nx * ny;
  p.shear_stress = sxx * tx * nx + syy * ty * ny + sxy * (tx * ny + ty * nx);
  p.minimum_stress = 0.5 * (sxx + syy) - std::hypot(0.5 * (sxx - syy), sxy);
  // Straight on by symmetry only in a homogeneous body: one material and one
  // in-situ stress in every region (a layer of another rock beside the crack
  // turns it).
  bool homogeneous = true;
  for (const auto& r : m.regions()) {
    const auto& o = r.initial_stress();
    homogeneous = homogeneous && r.material() == region->material() && o.xx_pa() == st.xx_pa() &&
                  o.yy_pa() == st.yy_pa() && o.xy_pa() == st.xy_pa();
  }
  p.symmetric = straight && homogeneous && std::abs(p.shear_stress) <= 1e-9 * std::max(std::abs(sxx), std::abs(syy));

  out.cell = m.cell_size_m();
  // The body's box (regions; a layer spans the grid) and its reach from the
  // well: the shorter of the distances to its far edges across and along.
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& r : m.regions()) {
    if (r.has_rectangle()) {
      x0 = std::min(x0, r.rectangle().x_min_m());
      x1 = std::max(x1, r.rectangle().x_max_m());
      y0 = std::min(y0, r.rectangle().y_min_m());
      y1 = std::max(y1, r.rectangle().y_max_m());
    } else if (r.has_layer()) {
      x0 = std::min(x0, m.grid().x_min_m());
      x1 = std::max(x1, m.grid().x_max_m());
      y0 = std::min(y0, r.layer().y_min_m());
      y1 = std::max(y1, r.layer().y_max_m());
    } else if (r.has_polygon()) {
      for (int i = 0; i < r.polygon().x_m_size() && i < r.polygon().y_m_size(); ++i) {
        x0 = std::min(x0, r.polygon().x_m(i));
        x1 = std::max(x1, r.polygon().x_m(i));
        y0 = std::min(y0, r.polygon().y_m(i));
        y1 = std::max(y1, r.polygon().y_m(i));
      }
    }
  }
  out.reach = std::min(std::max(x - x0, x1 - x), std::max(y - y0, y1 - y));
  // Only physics the scene's rules would accept: anything else gets no
  // derived numbers, and the rules then name what is wrong.
  const bool finite = std::isfinite(out.cell) && std::isfinite(out.reach) && std::isfinite(p.notch) &&
                      std::isfinite(p.youngs_modulus) && std::isfinite(p.density) && std::isfinite(p.end_s) &&
                      std::isfinite(p.toughness) && std::isfinite(p.total_rate) && std::isfinite(p.effective_s) &&
                      std::isfinite(p.normal_stress) && std::isfinite(p.shear_stress) &&
                      std::isfinite(p.minimum_stress) && std::isfinite(p.viscosity);
  if (!finite || !(out.cell > 0) || !(out.reach > 0) || !(p.notch > 0) || !(p.youngs_modulus > 0) || !(p.density > 0) ||
      !(p.end_s > 0) || !(p.poisson_ratio >= 0 && p.poisson_ratio < 0.5) || !(p.toughness >= 0)) {
    return refuse("the body, the rock, the cell or the crack is not valid yet (the scene's rules say what)");
  }
  return out;
}

scene::Scene with_method(const scene::Scene& scene, std::vector<Setting>* applied_out) {
  scene::Scene s = scene;
  std::vector<Setting> applied;
  const bool mpm_solid = s.solid().has_mpm();
  const bool mpm_fluid = s.fluid().has_mpm();
  if (!mpm_solid) {
    if (applied_out) *applied_out = applied;
    return s;
  }
  const auto& m = s.solid().mpm();
  const bool cracks = m.cracks_size() > 0;
  std::string why_not;
  const auto physics = physics_of(s, &why_not);

  if (mpm_fluid) {
    // The implicit interface: the fluid's pressure solved with the crack's
    // opening, stable for water at the solid's step.
    if (s.coupling().exchange_interval() <= 1) {
      derive_key(s, applied, "coupling.scheme", "IMPLICIT",
                 "the fluid's pressure solved with the crack's opening: any fluid, water too, at the solid's step");
    }
    if (s.coupling().scheme() == scene::Coupling::IMPLICIT) {
      derive_key(s, applied, "time.safety_factor", "0.9", "the implicit interface is stable at 0.9 of the stable step");
    }
    derive_key(s, applied, "fluid.mpm.merge_fraction", "0.5",
               "particles squeezed below half their length merge (they would set the fluid's step)");
    derive_key(s, applied, "fluid.mpm.max_substeps", "1000", "the fluid subcycles within the solid's step");
  }
  if (physics) {
    const auto& p = physics->physics;
    // The damping and the zero-lag wait follow the scene's own density
    // scaling and growth step where it sets them.
    const auto& fracture = s.solid().mpm().fracture();
    const Method d = derive(p, physics->cell, physics->reach,
                            s.solid().mpm().has_density_scaling() ? s.solid().mpm().density_scaling() : 0,
                            fracture.has_growth_cells() ? fracture.growth_cells() : 0);
    const Expected& x = d.expected;
    const double l_end = x.end.half_length;
    const std::string vertex = x.viscosity_dominated ? "M" : "K";
    if (physics->toughness_given) {
      derive_key(s, applied, "solid.mpm.fracture.propagate", "true",
                 "the rock at the well has a toughness: its crack grows where J reaches it");
    }
    derive_key(
        s, applied, "solid.mpm.density_scaling", num(d.density_scaling),
        "quasi-static: the scaled P-wave (" + approx(d.scaled_c) +
            " m/s) crosses the expected final "
            "half-length " +
            approx(l_end) + " m in " + approx(100 * l_end / d.scaled_c / p.end_s) + "% of the injection (target 0.5%" +
            (d.settle ? "; with toughness, the settling wait may not cap the tip below its final speed" : "") + ")");
    derive_key(s, applied, "solid.mpm.damping.grid_alpha_per_s", num(d.damping),
               "critical for the body's lowest mode (" + approx(d.body_omega) + " rad/s over its reach " +
                   approx(physics->reach) + " m)" +
                   (d.settle ? " or, with toughness, for the crack's quarter-wave mode at three notch lengths" : "") +
                   ", at most a 2% lag behind a load rising over " + approx(d.t_3) + " s (three notch lengths)");
    derive_key(s, applied, "solid.mpm.damping.pic_fraction", "0.5", "half PIC: the particles' noise damped");
    derive_key(s, applied, "solid.mpm.fracture.j_inner_cells", "1", "J over the tip's 3-cell square");
    derive_key(s, applied, "solid.mpm.fracture.j_outer_cells", "3", "J over the tip's 3-cell square");
    derive_key(s, applied, "solid.mpm.fracture.check_interval", "2", "tips checked every other step");
    derive_key(s, applied, "solid.mpm.fracture.growth_cells", num(d.growth_cells),
               d.settle ? "a quarter cell per growth step (toughness: the settling wait scales with its inverse)"
                        : "the tip leads the fluid front by at most 2 steps, 2.5% of three notch lengths (" +
                              approx(3 * p.notch) + " m)");
    derive_key(s, applied, "solid.mpm.fracture.direction", p.symmetric ? "STRAIGHT" : "MAX_HOOP_STRESS",
               p.symmetric ? "a straight notch in a homogeneous body with no in-situ shear on it: straight on by "
                             "symmetry"
                           : "the in-situ stress puts " + approx(std::abs(p.shear_stress)) +
                                 " Pa of shear on the notch, the crack is bent or the body is not homogeneous: the "
                                 "tips turn by maximum hoop stress");
    if (s.fluid().mpm().lag() != scene::MpmFluid::ZERO_PRESSURE || !is_set(s, "fluid.mpm.lag")) {
      derive_key(s, applied, "solid.mpm.fracture.max_lag_cells", num(d.growth_cells),
                 "zero lag: the tip waits for the fluid front within a growth step");
    }
    if (d.settle) {
      derive_key(s, applied, "solid.mpm.fracture.settle_transits", "2",
                 "toughness: after a step the opening follows over 2 shear transits of the crack");
      derive_key(s, applied, "solid.mpm.fracture.release_transits",
                 num(std::min(2.0, s.solid().mpm().fracture().settle_transits())),
                 "the new part's face load rises over the settling wait");
    }
    derive_key(s, applied, "fluid.mpm.virtual_opening_m", num(d.virtual_opening),
               "1% of the expected final mouth opening, " + approx(x.end.opening) + " m (" + vertex + "-vertex)");
    if (x.matched_closure) {
      derive_key(s, applied, "fluid.mpm.lag", "TIP_ASYMPTOTE_MATCHED",
                 "Km = " + approx(x.km) + " < 2: the viscous tip solution closes the fluid's front");
    } else {
      derive_key(s, applied, "fluid.mpm.lag", "FRONT_PRESSURE",
                 "Km = " + approx(x.km) + " >= 2: the front's pressure reaches the tip (zero lag)");
    }
    const auto lag = s.fluid().mpm().lag();
    if (lag == scene::MpmFluid::TIP_ASYMPTOTE_MATCHED || lag == scene::MpmFluid::TIP_ASYMPTOTE) {
      derive_key(s, applied, "fluid.mpm.lag_pressure_pa", num(d.lag_pressure),
                 p.symmetric ? "the dry tip zone carries the in-situ stress normal to the crack"
                             : "the dry tip zone carries the minimum in-situ stress the crack turns to");
    }
    derive_key(s, applied, "fluid.mpm.initial_fill",
               "{ front_m: " + num(p.notch) + " pressure_pa: " + num(std::max(0.0, p.normal_stress)) + " }",
               "the notch filled to its tip at the in-situ stress normal to it");
  } else if (mpm_fluid && cracks && applied_out) {
    applied.push_back({"(fluid-driven crack)", "not derived", why_not});
  }
  if (cracks) {
    derive_key(s, applied, "solid.mpm.fracture.surfaces_from_material", "true",
               "the faces follow the material's opening: a grown crack opens as a cut one, no drift at the tip");
  }
  if (in_situ_in_equilibrium(s.solid().mpm())) {
    derive_key(s, applied, "solid.mpm.in_situ_reference", "true",
               "the in-situ stress as the reference state: no crack-tip error scaling with it");
  }
  if (applied_out) *applied_out = applied;
  return s;
}

std::string describe(const std::vector<Setting>& settings, const std::string& prefix) {
  std::string out;
  for (const auto& setting : settings) {
    out += prefix + setting.key + ": " + setting.value + "   # " + setting.rule + "\n";
  }
  return out;
}

}  // namespace hfmpm::method
