// A fluid-driven crack's physics read from a scene (method::physics_of):
// the rock, stress and rate at its inlet, its notch and the body's reach.
#include <algorithm>
#include <cmath>

#include "hfmpm/coupling/method.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::method {
namespace {

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

// The body's box (regions; a layer spans the grid) and its reach from
// (x, y): the shorter of the distances to its far edges across and along.
double reach(const scene::MpmSolid& m, double x, double y) {
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
  return std::min(std::max(x - x0, x1 - x), std::max(y - y0, y1 - y));
}

// The region a point lies in: the last listed that contains it (a later
// region wins), or null outside the body.
const scene::RegionSpec* region_at(const scene::MpmSolid& m, double x, double y) {
  const scene::RegionSpec* found = nullptr;
  for (const auto& r : m.regions())
    if (contains(r, x, y)) found = &r;
  return found;
}

// The body is its own mirror image about the line of a straight crack along
// x (y = c) or y (x = c): at every cell centre and its mirror point the same
// material and in-situ stress (its shear reversed), the mirrored edges loaded
// and held alike, no shear traction, and no other crack. Then K_II = 0 at
// both tips by symmetry and the crack grows straight on, whatever lies ahead
// of it (a layer across its path).
bool mirror_symmetric(const scene::MpmSolid& m, bool along_x, double c) {
  if (m.cracks_size() != 1 || !(m.cell_size_m() > 0)) return false;
  const auto& g = m.grid();
  const double h = m.cell_size_m();
  const double lo = along_x ? g.y_min_m() : g.x_min_m(), hi = along_x ? g.y_max_m() : g.x_max_m();
  if (std::abs(lo + hi - 2 * c) > 1e-6 * h) return false;
  // Edges: the two across the line swap; shear tractions and fixed boxes are
  // not compared (the scene is then not taken as symmetric).
  const scene::Edge a = along_x ? scene::BOTTOM : scene::LEFT, b = along_x ? scene::TOP : scene::RIGHT;
  auto traction_text = [&](scene::Edge e) {
    std::string text;
    for (const auto& t : m.tractions())
      if (t.edge() == e) text += t.normal_pa().SerializeAsString() + "|";
    return text;
  };
  for (const auto& t : m.tractions())
    if (t.has_shear_pa()) return false;
  if (traction_text(a) != traction_text(b)) return false;
  auto silent = [&](scene::Edge e) { return std::count(m.silent_edges().begin(), m.silent_edges().end(), e); };
  if (silent(a) != silent(b)) return false;
  for (const auto& k : m.constraints()) {
    if (k.has_fixed_box()) return false;
    const bool across = along_x ? k.has_symmetry_y_m() : k.has_symmetry_x_m();
    if (!across) continue;
    const double at = along_x ? k.symmetry_y_m() : k.symmetry_x_m();
    bool mirrored = false;
    for (const auto& o : m.constraints()) {
      const bool same_kind = along_x ? o.has_symmetry_y_m() : o.has_symmetry_x_m();
      if (same_kind && std::abs((along_x ? o.symmetry_y_m() : o.symmetry_x_m()) - (2 * c - at)) <= 1e-6 * h)
        mirrored = true;
    }
    if (!mirrored) return false;
  }
  // Regions: cell centres, at most about 400 samples along each axis.
  const int nx = static_cast<int>(std::ceil((g.x_max_m() - g.x_min_m()) / h - 1e-9));
  const int ny = static_cast<int>(std::ceil((g.y_max_m() - g.y_min_m()) / h - 1e-9));
  if (nx <= 0 || ny <= 0) return false;
  const int sx = std::max(1, nx / 400), sy = std::max(1, ny / 400);
  for (int i = 0; i < nx; i += sx) {
    for (int j = 0; j < ny; j += sy) {
      const double x = g.x_min_m() + (i + 0.5) * h, y = g.y_min_m() + (j + 0.5) * h;
      const double mx = along_x ? x : 2 * c - x, my = along_x ? 2 * c - y : y;
      const scene::RegionSpec* r = region_at(m, x, y);
      const scene::RegionSpec* q = region_at(m, mx, my);
      if (!r || !q) {
        if (r != q) return false;
        continue;
      }
      const auto &s1 = r->initial_stress(), &s2 = q->initial_stress();
      if (r->material() != q->material() || s1.xx_pa() != s2.xx_pa() || s1.yy_pa() != s2.yy_pa() ||
          s1.xy_pa() != -s2.xy_pa())
        return false;
    }
  }
  return true;
}

}  // namespace

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
  double length = 0, before = 0;  // m, the whole crack and its part up to the inlet vertex
  bool straight = true;
  const double dx0 = crack->x_m(n - 1) - crack->x_m(0), dy0 = crack->y_m(n - 1) - crack->y_m(0);
  for (int i = 1; i < n; ++i) {
    const double dx = crack->x_m(i) - crack->x_m(i - 1), dy = crack->y_m(i) - crack->y_m(i - 1);
    length += std::hypot(dx, dy);
    if (i == inlet) before = length;
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
  // A well inside the body: the shorter wing, which the fluid's fill may not pass.
  p.notch = both ? std::min(before, length - before) : length;
  p.two_wings = both;
  // The in-situ stress at the well, compressive, on the crack's plane.
  const auto& st = region->initial_stress();
  const double sxx = -st.xx_pa(), syy = -st.yy_pa(), sxy = -st.xy_pa();
  const double nx = -ty, ny = tx;
  p.normal_stress = sxx * nx * nx + syy * ny * ny + 2 * sxy * nx * ny;
  p.shear_stress = sxx * tx * nx + syy * ty * ny + sxy * (tx * ny + ty * nx);
  p.minimum_stress = 0.5 * (sxx + syy) - std::hypot(0.5 * (sxx - syy), sxy);
  // Straight on by symmetry in a homogeneous body (one material and one
  // in-situ stress in every region), or in one that is its own mirror image
  // about the crack's line (a layer across the path); a layer of another
  // rock beside the crack turns it.
  bool homogeneous = true;
  for (const auto& r : m.regions()) {
    const auto& o = r.initial_stress();
    homogeneous = homogeneous && r.material() == region->material() && o.xx_pa() == st.xx_pa() &&
                  o.yy_pa() == st.yy_pa() && o.xy_pa() == st.xy_pa();
  }
  const bool along_x = std::abs(dy0) <= 1e-12 * std::abs(dx0), along_y = std::abs(dx0) <= 1e-12 * std::abs(dy0);
  const bool mirrored = straight && (along_x || along_y) && mirror_symmetric(m, along_x, along_x ? y : x);
  for (const auto& mat : m.materials()) {
    const double speed = std::sqrt(mat.youngs_modulus_pa() / (2 * (1 + mat.poisson_ratio())) / mat.density_kg_m3());
    if (std::isfinite(speed) && speed > 0 && (p.slowest_shear_speed == 0 || speed < p.slowest_shear_speed))
      p.slowest_shear_speed = speed;
  }
  p.symmetric = straight && (homogeneous || mirrored) &&
                std::abs(p.shear_stress) <= 1e-9 * std::max(std::abs(sxx), std::abs(syy));

  out.cell = m.cell_size_m();
  out.reach = reach(m, x, y);
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

}  // namespace hfmpm::method
