// Rules for solid.mpm: grid, materials, regions, constraints, tractions.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "scene_checker.hpp"

namespace hfmpm::coupling {
namespace {

// ------------------------------------------------------------- geometry

struct Pt {
  double x, y;
};

double cross(Pt o, Pt a, Pt b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

double point_segment_distance(Pt p, Pt a, Pt b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

// True if the closed segments ab and cd cross (not only touch at a point
// within `tol` of the other: that shows in the distance).
bool segments_cross(Pt a, Pt b, Pt c, Pt d) {
  const double d1 = cross(a, b, c), d2 = cross(a, b, d), d3 = cross(c, d, a), d4 = cross(c, d, b);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

double segment_distance(Pt a, Pt b, Pt c, Pt d) {
  if (segments_cross(a, b, c, d)) return 0;
  return std::min({point_segment_distance(a, c, d), point_segment_distance(b, c, d), point_segment_distance(c, a, b),
                   point_segment_distance(d, a, b)});
}

std::vector<Pt> crack_points(const scene::CrackSpecScene& cr) {
  std::vector<Pt> out;
  for (int i = 0; i < std::min(cr.x_m_size(), cr.y_m_size()); ++i) out.push_back({cr.x_m(i), cr.y_m(i)});
  return out;
}

bool all_finite(const std::vector<Pt>& pts) {
  return std::all_of(pts.begin(), pts.end(), [](Pt p) { return std::isfinite(p.x) && std::isfinite(p.y); });
}

bool box_finite(const scene::Box& b) {
  return std::isfinite(b.x_min_m()) && std::isfinite(b.y_min_m()) && std::isfinite(b.x_max_m()) &&
         std::isfinite(b.y_max_m());
}

bool in_box(Pt p, const scene::Box& b, double tol) {
  return p.x >= b.x_min_m() - tol && p.x <= b.x_max_m() + tol && p.y >= b.y_min_m() - tol && p.y <= b.y_max_m() + tol;
}

// Point in a region (closed, to `tol`). A layer spans the grid's width.
bool in_region(Pt p, const scene::RegionSpec& r, const scene::Box& grid, double tol) {
  switch (r.shape_case()) {
    case scene::RegionSpec::kRectangle:
      return in_box(p, r.rectangle(), tol);
    case scene::RegionSpec::kLayer:
      return p.y >= r.layer().y_min_m() - tol && p.y <= r.layer().y_max_m() + tol && p.x >= grid.x_min_m() - tol &&
             p.x <= grid.x_max_m() + tol;
    case scene::RegionSpec::kPolygon: {
      const auto& poly = r.polygon();
      const int n = std::min(poly.x_m_size(), poly.y_m_size());
      bool inside = false;
      for (int i = 0, j = n - 1; i < n; j = i++) {
        const Pt a{poly.x_m(i), poly.y_m(i)}, b{poly.x_m(j), poly.y_m(j)};
        if (point_segment_distance(p, a, b) <= tol) return true;
        if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) inside = !inside;
      }
      return inside;
    }
    case scene::RegionSpec::SHAPE_NOT_SET:
      return false;
  }
  return false;
}

// The body is the union of the regions.
bool in_body(Pt p, const scene::MpmSolid& m, double tol) {
  return std::any_of(m.regions().begin(), m.regions().end(),
                     [&](const scene::RegionSpec& r) { return in_region(p, r, m.grid(), tol); });
}

// On the body's edge: in the (closed) body, with body-free space within a
// millionth of a cell of it.
bool on_body_edge(Pt p, const scene::MpmSolid& m, double h) {
  if (!in_body(p, m, 1e-9 * h)) return false;
  const double d = 1e-6 * h;
  for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}, std::pair{1, 1},
                               std::pair{1, -1}, std::pair{-1, 1}, std::pair{-1, -1}}) {
    if (!in_body({p.x + dx * d, p.y + dy * d}, m, 0)) return true;
  }
  return false;
}

bool on_symmetry_line(Pt p, const scene::MpmSolid& m, double h) {
  return std::any_of(m.constraints().begin(), m.constraints().end(), [&](const scene::ConstraintSpec& con) {
    return (con.has_symmetry_x_m() && std::abs(p.x - con.symmetry_x_m()) <= 1e-9 * h) ||
           (con.has_symmetry_y_m() && std::abs(p.y - con.symmetry_y_m()) <= 1e-9 * h);
  });
}

std::string point_text(Pt p) { return "(" + text(p.x) + ", " + text(p.y) + ")"; }

// Limits on the crack polylines: the checks below are quadratic in the vertices.
constexpr int kMaxCrackVertices = 10000;
constexpr double kMaxCrackParticles = 1e6;

// Crack geometry (solid.mpm.cracks) against itself, the grid, the body and
// the other cracks. Only for cracks whose coordinates are all finite and
// whose x_m and y_m match (other rules report the rest).
void check_crack_geometry(Checker& c, const scene::MpmSolid& m) {
  const std::string key = "solid.mpm.";
  const double h = m.cell_size_m();
  if (!(std::isfinite(h) && h > 0) || !m.has_grid() || !box_finite(m.grid())) return;
  const double tol = 1e-9 * h;
  int total = 0;
  for (const auto& cr : m.cracks()) total += cr.x_m_size();
  if (total > kMaxCrackVertices) {
    c.bad(
        key + "cracks", std::to_string(total) + " vertices",
        "at most " + std::to_string(kMaxCrackVertices) + " crack vertices in all (cracks are resampled at spacing_m)");
    return;
  }
  std::vector<std::vector<Pt>> usable(static_cast<std::size_t>(m.cracks_size()));
  for (int i = 0; i < m.cracks_size(); ++i) {
    const auto& cr = m.cracks(i);
    const std::string k = key + "cracks[" + std::to_string(i) + "]";
    auto pts = crack_points(cr);
    if (cr.x_m_size() < 2 || cr.x_m_size() != cr.y_m_size() || !all_finite(pts)) continue;
    double length = 0;
    bool bad = false;
    for (std::size_t j = 1; j < pts.size(); ++j) length += std::hypot(pts[j].x - pts[j - 1].x, pts[j].y - pts[j - 1].y);
    if (!(length > tol)) {
      c.bad(k + ".x_m", "a crack of length " + text(length) + " m", "a crack of positive length (its vertices differ)");
      continue;
    }
    for (std::size_t j = 1; j < pts.size() && !bad; ++j) {
      const double seg = std::hypot(pts[j].x - pts[j - 1].x, pts[j].y - pts[j - 1].y);
      if (!(seg > tol)) {
        c.bad(k + ".x_m",
              "vertices " + std::to_string(j - 1) + " and " + std::to_string(j) + " both at " + point_text(pts[j]),
              "distinct consecutive vertices (no zero-length segment)");
        bad = true;
      }
    }
    if (bad) continue;
    // Crosses or touches itself: non-adjacent segments meet, or a segment
    // turns straight back along the one before.
    for (std::size_t a = 1; a < pts.size() && !bad; ++a) {
      for (std::size_t b = a + 1; b < pts.size() && !bad; ++b) {
        const bool adjacent = b == a + 1;
        const Pt p0 = pts[a - 1], p1 = pts[a], q0 = pts[b - 1], q1 = pts[b];
        bool meets = false;
        if (adjacent) {
          const double dot = (p1.x - p0.x) * (q1.x - q0.x) + (p1.y - p0.y) * (q1.y - q0.y);
          const double len = std::hypot(p1.x - p0.x, p1.y - p0.y) * std::hypot(q1.x - q0.x, q1.y - q0.y);
          meets = dot < 0 && std::abs(cross(p0, p1, q1)) <= 1e-12 * len;
        } else {
          meets = segment_distance(p0, p1, q0, q1) <= tol;
        }
        if (meets) {
          c.bad(k + ".x_m", "segments " + std::to_string(a - 1) + " and " + std::to_string(b - 1) + " meet",
                "a crack that does not cross or touch itself");
          bad = true;
        }
      }
    }
    if (bad) continue;
    if (length / (cr.has_spacing_m() && cr.spacing_m() > 0 ? cr.spacing_m() : h / 2) > kMaxCrackParticles) {
      c.bad(k + ".spacing_m", text(cr.has_spacing_m() ? cr.spacing_m() : h / 2),
            "at most 1e6 crack particles along the crack (length " + text(length) + " m)");
      continue;
    }
    for (std::size_t j = 0; j < pts.size() && !bad; ++j) {
      const std::string vk = k + ".x_m[" + std::to_string(j) + "]";
      if (!in_box(pts[j], m.grid(), tol)) {
        c.bad(vk, "a vertex at " + point_text(pts[j]), "a point inside solid.mpm.grid");
        bad = true;
      } else if (m.regions_size() > 0 && !in_body(pts[j], m, tol)) {
        c.bad(vk, "a vertex at " + point_text(pts[j]), "a point inside the body (the union of solid.mpm.regions)");
        bad = true;
      }
    }
    if (bad) continue;
    // A mouth (an end that is not a tip) is where the crack meets the
    // outside or a symmetry plane.
    for (const auto& [is_tip, index, name] : {std::tuple{cr.start_is_tip(), std::size_t{0}, "start_is_tip"},
                                              std::tuple{cr.end_is_tip(), pts.size() - 1, "end_is_tip"}}) {
      if (is_tip || m.regions_size() == 0) continue;
      if (!on_body_edge(pts[index], m, h) && !on_symmetry_line(pts[index], m, h)) {
        c.bad(k + "." + name,
              std::string("false with vertex ") + std::to_string(index) + " at " + point_text(pts[index]),
              "a mouth (an end that is not a tip) on the body's edge or on a symmetry line "
              "(constraints symmetry_x_m / symmetry_y_m); an interior end is a tip (" +
                  std::string(name) + ": true)");
        bad = true;
      }
    }
    if (!bad) usable[static_cast<std::size_t>(i)] = std::move(pts);
  }
  // Two cracks within a cell: a node carries at most two velocity fields
  // (its own side and across one crack), so a second crack in a node's
  // support is not represented. The solver does not model crossing or
  // branching cracks either, so touching cracks are refused too.
  for (std::size_t a = 0; a < usable.size(); ++a) {
    for (std::size_t b = a + 1; b < usable.size(); ++b) {
      if (usable[a].empty() || usable[b].empty()) continue;
      double closest = kInf;
      for (std::size_t i = 1; i < usable[a].size(); ++i) {
        for (std::size_t j = 1; j < usable[b].size(); ++j) {
          closest = std::min(closest, segment_distance(usable[a][i - 1], usable[a][i], usable[b][j - 1], usable[b][j]));
        }
      }
      if (closest < h) {
        c.bad(key + "cracks[" + std::to_string(b) + "]",
              "a crack " + text(closest) + " m from solid.mpm.cracks[" + std::to_string(a) + "]" +
                  (closest <= tol ? " (they cross or touch)" : ""),
              "cracks at least one cell (cell_size_m = " + text(h) +
                  " m) apart: a grid node carries at most two velocity fields, so it cannot tell three sides "
                  "apart; crossing or branching cracks are not modelled");
      }
    }
  }
}

// Regions within the grid: particles are made only in the grid's cells.
void check_regions_in_grid(Checker& c, const scene::MpmSolid& m) {
  const double h = m.cell_size_m();
  if (!(std::isfinite(h) && h > 0) || !m.has_grid() || !box_finite(m.grid())) return;
  const double tol = 1e-9 * h;
  const auto& g = m.grid();
  const std::string grid = "inside solid.mpm.grid (x " + text(g.x_min_m()) + " to " + text(g.x_max_m()) + ", y " +
                           text(g.y_min_m()) + " to " + text(g.y_max_m()) + " m)";
  for (int i = 0; i < m.regions_size(); ++i) {
    const auto& r = m.regions(i);
    const std::string k = "solid.mpm.regions[" + std::to_string(i) + "].";
    if (r.has_rectangle() && box_finite(r.rectangle())) {
      const auto& b = r.rectangle();
      if (!in_box({b.x_min_m(), b.y_min_m()}, g, tol) || !in_box({b.x_max_m(), b.y_max_m()}, g, tol)) {
        c.bad(k + "rectangle",
              "x " + text(b.x_min_m()) + " to " + text(b.x_max_m()) + ", y " + text(b.y_min_m()) + " to " +
                  text(b.y_max_m()) + " m",
              "a rectangle " + grid);
      }
    } else if (r.has_layer() && std::isfinite(r.layer().y_min_m()) && std::isfinite(r.layer().y_max_m())) {
      if (r.layer().y_min_m() < g.y_min_m() - tol || r.layer().y_max_m() > g.y_max_m() + tol) {
        c.bad(k + "layer", "y " + text(r.layer().y_min_m()) + " to " + text(r.layer().y_max_m()) + " m",
              "a layer " + grid);
      }
    } else if (r.has_polygon()) {
      const auto& poly = r.polygon();
      for (int j = 0; j < std::min(poly.x_m_size(), poly.y_m_size()); ++j) {
        const Pt p{poly.x_m(j), poly.y_m(j)};
        if (std::isfinite(p.x) && std::isfinite(p.y) && !in_box(p, g, tol)) {
          c.bad(k + "polygon.x_m[" + std::to_string(j) + "]", "a vertex at " + point_text(p), "a vertex " + grid);
          break;
        }
      }
    }
  }
}

// Memory check: the estimate against the machine's physical memory.
void check_memory(Checker& c, const scene::MpmSolid& m) {
  const double need = mpm_solid_memory_bytes(m);
  const double limit = memory_limit_bytes();
  if (!(limit > 0) || !(need > limit)) return;
  const auto gb = [](double bytes) { return text(std::round(bytes / 1e7) / 100) + " GB"; };
  c.bad("solid.mpm.cell_size_m", text(m.cell_size_m()),
        "a grid and particles that fit in memory: this scene needs about " + gb(need) + " (" +
            text(mpm_solid_nodes(m)) + " nodes, " + text(mpm_solid_particles(m)) +
            " particles), more than the limit of " + gb(limit) +
            " (3/4 of this machine's physical memory); use larger cells or a smaller grid");
}

// True if v is a whole number of cells from the grid origin (to 1e-9 cells).
bool on_grid_line(double v, double origin, double h) {
  const double k = (v - origin) / h;
  return std::abs(k - std::round(k)) < 1e-9 * std::max(1.0, std::abs(k));
}

void check_box(Checker& c, const std::string& key, const scene::Box& b) {
  for (const auto& [name, has, v] :
       {std::tuple{"x_min_m", b.has_x_min_m(), b.x_min_m()}, std::tuple{"y_min_m", b.has_y_min_m(), b.y_min_m()},
        std::tuple{"x_max_m", b.has_x_max_m(), b.x_max_m()}, std::tuple{"y_max_m", b.has_y_max_m(), b.y_max_m()}}) {
    if (!has)
      c.missing(key + "." + name, "a coordinate in m");
    else
      c.range(key + "." + name, v, -kInf, kInf, false, "m");
  }
  if (b.x_max_m() <= b.x_min_m()) c.bad(key + ".x_max_m", text(b.x_max_m()), "> x_min_m = " + text(b.x_min_m()));
  if (b.y_max_m() <= b.y_min_m()) c.bad(key + ".y_max_m", text(b.y_max_m()), "> y_min_m = " + text(b.y_min_m()));
}

// The in-situ stress as reference state is the same problem only if that
// stress is in equilibrium on its own: uniform in each region (it is), and
// equal tractions across the interfaces between regions. Layers meet on
// horizontal lines (equal yy and xy suffice); a rectangle may meet another
// region on any side (equal xx, yy and xy). Polygons are refused: their
// free sides are not edges of the body's box, where the in-situ traction is
// given back.
void check_in_situ_reference(Checker& c, const std::string& key, const scene::MpmSolid& m) {
  for (int i = 0; i < m.regions_size(); ++i) {
    const auto& r = m.regions(i);
    const std::string k = key + "regions[" + std::to_string(i) + "]";
    if (r.has_polygon()) {
      c.bad(k + ".polygon", "a polygon",
            "rectangle or layer regions with in_situ_reference (or in_situ_reference: false)");
    }
    for (int j = 0; j < i; ++j) {
      const auto& a = m.regions(j).initial_stress();
      const auto& b = r.initial_stress();
      const bool layers = r.has_layer() && m.regions(j).has_layer();
      const bool equal = a.yy_pa() == b.yy_pa() && a.xy_pa() == b.xy_pa() && (layers || a.xx_pa() == b.xx_pa());
      if (!equal) {
        c.bad(k + ".initial_stress",
              "xx " + text(b.xx_pa()) + ", yy " + text(b.yy_pa()) + ", xy " + text(b.xy_pa()) + " Pa against regions[" +
                  std::to_string(j) + "]'s xx " + text(a.xx_pa()) + ", yy " + text(a.yy_pa()) + ", xy " +
                  text(a.xy_pa()),
              std::string("with in_situ_reference, stresses in equilibrium across the regions: equal ") +
                  (layers ? "yy and xy between layers" : "xx, yy and xy") + " (or in_situ_reference: false)");
      }
    }
  }
}

}  // namespace

void check_mpm_solid(Checker& c, const scene::MpmSolid& m) {
  const std::string key = "solid.mpm.";
  if (!m.has_grid())
    c.missing(key + "grid", "the grid extent: grid { x_min_m: .. y_min_m: .. x_max_m: .. y_max_m: .. }");
  else
    check_box(c, key + "grid", m.grid());
  if (!m.has_cell_size_m()) {
    c.missing(key + "cell_size_m", "the cell size (m), > 0");
  } else {
    c.positive(key + "cell_size_m", m.cell_size_m(), "m");
    const double h = m.cell_size_m();
    if (h > 0 && m.has_grid()) {
      const auto& g = m.grid();
      for (const auto& [name, lo, hi] :
           {std::tuple{"x_max_m", g.x_min_m(), g.x_max_m()}, std::tuple{"y_max_m", g.y_min_m(), g.y_max_m()}}) {
        if (!on_grid_line(hi, lo, h)) {
          c.bad(key + "grid." + name, text(hi),
                "a whole number of cells (cell_size_m = " + text(h) + ") from the minimum");
        }
      }
      const double cells = (g.x_max_m() - g.x_min_m()) / h * (g.y_max_m() - g.y_min_m()) / h;
      if (cells > 1e8) c.bad(key + "cell_size_m", text(h), "at most 1e8 cells in the grid");
    }
  }
  std::set<std::string> names;
  if (m.materials_size() == 0) c.missing(key + "materials", "at least one material { name: .. youngs_modulus_pa: .. }");
  for (int i = 0; i < m.materials_size(); ++i) {
    const auto& mat = m.materials(i);
    const std::string k = key + "materials[" + std::to_string(i) + "].";
    if (!mat.has_name() || mat.name().empty())
      c.missing(k + "name", "a name the regions refer to");
    else if (!names.insert(mat.name()).second)
      c.bad(k + "name", "\"" + mat.name() + "\"", "a name not used before");
    if (!mat.has_youngs_modulus_pa())
      c.missing(k + "youngs_modulus_pa", "Young's modulus (Pa), > 0");
    else
      c.positive(k + "youngs_modulus_pa", mat.youngs_modulus_pa(), "Pa");
    if (!mat.has_poisson_ratio())
      c.missing(k + "poisson_ratio", "Poisson's ratio, in [0, 0.5)");
    else if (!(mat.poisson_ratio() >= 0 && mat.poisson_ratio() < 0.5)) {
      c.bad(k + "poisson_ratio", text(mat.poisson_ratio()), "a value in [0, 0.5)");
    }
    if (!mat.has_density_kg_m3())
      c.missing(k + "density_kg_m3", "the density (kg/m^3), > 0");
    else
      c.positive(k + "density_kg_m3", mat.density_kg_m3(), "kg/m^3");
    if (mat.has_toughness_j_m2() && mat.has_toughness_pa_sqrt_m()) {
      c.bad(k + "toughness_pa_sqrt_m", text(mat.toughness_pa_sqrt_m()),
            "unset: toughness_j_m2 is set (give one of them)");
    }
    if (mat.has_toughness_j_m2()) c.positive(k + "toughness_j_m2", mat.toughness_j_m2(), "J/m^2");
    if (mat.has_toughness_pa_sqrt_m()) c.positive(k + "toughness_pa_sqrt_m", mat.toughness_pa_sqrt_m(), "Pa m^0.5");
  }
  if (m.regions_size() == 0) c.missing(key + "regions", "at least one region { material: .. rectangle { .. } }");
  for (int i = 0; i < m.regions_size(); ++i) {
    const auto& r = m.regions(i);
    const std::string k = key + "regions[" + std::to_string(i) + "].";
    if (!names.count(r.material())) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      c.bad(k + "material", "\"" + r.material() + "\"", "the name of a material: " + (list.empty() ? "(none)" : list));
    }
    switch (r.shape_case()) {
      case scene::RegionSpec::kRectangle:
        check_box(c, k + "rectangle", r.rectangle());
        break;
      case scene::RegionSpec::kPolygon:
        if (r.polygon().x_m_size() < 3 || r.polygon().x_m_size() != r.polygon().y_m_size()) {
          c.bad(k + "polygon",
                std::to_string(r.polygon().x_m_size()) + " x, " + std::to_string(r.polygon().y_m_size()) + " y",
                "at least 3 vertices, as many x_m as y_m");
        }
        break;
      case scene::RegionSpec::kLayer:
        if (!(r.layer().y_max_m() > r.layer().y_min_m())) {
          c.bad(k + "layer.y_max_m", text(r.layer().y_max_m()), "> y_min_m = " + text(r.layer().y_min_m()));
        }
        break;
      case scene::RegionSpec::SHAPE_NOT_SET:
        c.missing(k + "shape", "one of rectangle, polygon, layer");
        break;
    }
    if (r.has_particles_per_cell() && (r.particles_per_cell() < 1 || r.particles_per_cell() > 4)) {
      c.bad(k + "particles_per_cell", std::to_string(r.particles_per_cell()), "1, 2, 3 or 4 (per direction)");
    }
    if (r.has_initial_stress()) {
      const auto& s = r.initial_stress();
      for (const auto& [name, v] : {std::pair{"xx_pa", s.xx_pa()}, std::pair{"yy_pa", s.yy_pa()},
                                    std::pair{"xy_pa", s.xy_pa()}, std::pair{"zz_pa", s.zz_pa()}}) {
        c.range(k + "initial_stress." + name, v, -kInf, kInf, false, "Pa");
      }
    }
  }
  if (m.particles_per_cell() < 1 || m.particles_per_cell() > 4) {
    c.bad(key + "particles_per_cell", std::to_string(m.particles_per_cell()), "1, 2, 3 or 4 (per direction)");
  }
  // Measured on scenarios/confined_block.scene (docs/stability.md): the
  // explicit uGIMP step blows up above 0.5-0.62 of h / c_p, depending on the
  // particles per cell (4: between 0.5 and 0.55) and Poisson's ratio.
  c.range(key + "cfl", m.cfl(), 0, 0.5, true,
          "dt = cfl h / c_p; the explicit step is unstable from about 0.55 (4 particles per cell) to 0.62 (2)");
  c.range(key + "density_scaling", m.density_scaling(), 1, 1e12, false, "a factor >= 1");
  if (m.in_situ_reference()) check_in_situ_reference(c, key, m);
  for (int i = 0; i < m.constraints_size(); ++i) {
    const auto& con = m.constraints(i);
    const std::string k = key + "constraints[" + std::to_string(i) + "].";
    const double h = m.cell_size_m();
    if (con.has_symmetry_x_m() && h > 0 && !on_grid_line(con.symmetry_x_m(), m.grid().x_min_m(), h)) {
      c.bad(k + "symmetry_x_m", text(con.symmetry_x_m()), "a grid line: x_min_m + k cell_size_m");
    } else if (con.has_symmetry_y_m() && h > 0 && !on_grid_line(con.symmetry_y_m(), m.grid().y_min_m(), h)) {
      c.bad(k + "symmetry_y_m", text(con.symmetry_y_m()), "a grid line: y_min_m + k cell_size_m");
    } else if (con.has_fixed_box()) {
      check_box(c, k + "fixed_box", con.fixed_box());
    } else if (con.kind_case() == scene::ConstraintSpec::KIND_NOT_SET) {
      c.missing(k + "kind", "one of symmetry_x_m, symmetry_y_m, fixed_box");
    }
  }
  for (int i = 0; i < m.tractions_size(); ++i) {
    const auto& t = m.tractions(i);
    const std::string k = key + "tractions[" + std::to_string(i) + "].";
    if (t.edge() == scene::EDGE_UNSPECIFIED) c.missing(k + "edge", "LEFT, RIGHT, BOTTOM or TOP");
    if (!t.has_normal_pa() && !t.has_shear_pa()) c.missing(k + "normal_pa", "a normal and/or shear traction (Pa)");
    if (t.has_normal_pa()) check_time_function(c, k + "normal_pa", t.normal_pa(), -kInf, "Pa");
    if (t.has_shear_pa()) check_time_function(c, k + "shear_pa", t.shear_pa(), -kInf, "Pa");
  }
  for (int i = 0; i < m.silent_edges_size(); ++i) {
    if (m.silent_edges(i) == scene::EDGE_UNSPECIFIED) {
      c.bad(key + "silent_edges[" + std::to_string(i) + "]", "EDGE_UNSPECIFIED", "LEFT, RIGHT, BOTTOM or TOP");
    }
  }
  for (int i = 0; i < m.cracks_size(); ++i) {
    const auto& cr = m.cracks(i);
    const std::string k = key + "cracks[" + std::to_string(i) + "].";
    if (cr.x_m_size() < 2 || cr.x_m_size() != cr.y_m_size()) {
      c.bad(k + "x_m", std::to_string(cr.x_m_size()) + " x, " + std::to_string(cr.y_m_size()) + " y",
            "at least 2 vertices, as many x_m as y_m");
    }
    if (cr.has_spacing_m()) c.range(k + "spacing_m", cr.spacing_m(), 0, m.cell_size_m(), true, "m, at most one cell");
    if (cr.has_pressure_pa()) check_time_function(c, k + "pressure_pa", cr.pressure_pa(), 0.0, "Pa");
  }
  c.non_negative(key + "damping.grid_alpha_per_s", m.damping().grid_alpha_per_s(), "1/s");
  c.range(key + "damping.pic_fraction", m.damping().pic_fraction(), 0, 1, false, "0 (FLIP) to 1 (PIC)");
  c.non_negative(key + "damping.feedback_q_m2", m.damping().feedback_q_m2(), "m^2");
  c.non_negative(key + "damping.feedback_target_kinetic_energy_j", m.damping().feedback_target_kinetic_energy_j(),
                 "J/m");
  const auto& f = m.fracture();
  c.range(key + "fracture.j_inner_cells", f.j_inner_cells(), 0, 1e3, true, "cells");
  if (std::isfinite(f.j_inner_cells()) && !(f.j_outer_cells() > f.j_inner_cells() && f.j_outer_cells() <= 1e3)) {
    c.bad(key + "fracture.j_outer_cells", text(f.j_outer_cells()),
          "more than j_inner_cells (" + text(f.j_inner_cells()) + ") cells");
  }
  c.range(key + "fracture.growth_cells", f.growth_cells(), 0, 1, true, "cells");
  if (f.has_max_lag_cells()) c.range(key + "fracture.max_lag_cells", f.max_lag_cells(), 0, 1e3, false, "cells");
  c.range(key + "fracture.settle_transits", f.settle_transits(), 0, 1e3, false, "shear-wave transits of the crack");
  if (f.check_interval() < 1)
    c.bad(key + "fracture.check_interval", std::to_string(f.check_interval()), "at least 1 step");
  if (f.direction() == scene::FractureSpec::DIRECTION_UNSPECIFIED) {
    c.bad(key + "fracture.direction", "DIRECTION_UNSPECIFIED", "MAX_HOOP_STRESS or STRAIGHT");
  }
  if (m.threads() < 1 || m.threads() > 64) c.bad(key + "threads", std::to_string(m.threads()), "1 to 64");
  check_regions_in_grid(c, m);
  check_crack_geometry(c, m);
  check_memory(c, m);
}

double mpm_solid_nodes(const scene::MpmSolid& m) {
  const auto& g = m.grid();
  const double h = m.cell_size_m();
  if (!(h > 0)) return 0;
  return (std::round((g.x_max_m() - g.x_min_m()) / h) + 1) * (std::round((g.y_max_m() - g.y_min_m()) / h) + 1);
}

double mpm_solid_particles(const scene::MpmSolid& m) {
  const auto& g = m.grid();
  const double h = m.cell_size_m();
  if (!(h > 0)) return 0;
  double count = 0, densest = m.particles_per_cell();
  for (const auto& r : m.regions()) {
    const double ppc = r.has_particles_per_cell() ? r.particles_per_cell() : m.particles_per_cell();
    densest = std::max(densest, ppc);
    double x0 = g.x_min_m(), x1 = g.x_max_m(), y0 = g.y_min_m(), y1 = g.y_max_m();
    if (r.has_rectangle()) {
      x0 = r.rectangle().x_min_m(), x1 = r.rectangle().x_max_m(), y0 = r.rectangle().y_min_m(),
      y1 = r.rectangle().y_max_m();
    } else if (r.has_layer()) {
      y0 = r.layer().y_min_m(), y1 = r.layer().y_max_m();
    } else if (r.has_polygon() && r.polygon().x_m_size() > 0 && r.polygon().y_m_size() > 0) {
      const auto& p = r.polygon();
      x0 = *std::min_element(p.x_m().begin(), p.x_m().end()), x1 = *std::max_element(p.x_m().begin(), p.x_m().end());
      y0 = *std::min_element(p.y_m().begin(), p.y_m().end()), y1 = *std::max_element(p.y_m().begin(), p.y_m().end());
    }
    // Clipped to the grid; a cell partly covered counts whole.
    const double nx = std::max(0.0, std::ceil((std::min(x1, g.x_max_m()) - std::max(x0, g.x_min_m())) / h) + 1);
    const double ny = std::max(0.0, std::ceil((std::min(y1, g.y_max_m()) - std::max(y0, g.y_min_m())) / h) + 1);
    count += nx * ny * ppc * ppc;
  }
  const double cells = std::round((g.x_max_m() - g.x_min_m()) / h) * std::round((g.y_max_m() - g.y_min_m()) / h);
  return std::min(count, cells * densest * densest);
}

// From solid/include/hfmpm/solid/mpm (grid.hpp, particles.hpp, solver.hpp):
// per node two NodalFields of 57 bytes (the second with cracks), a stamp,
// per velocity field the new velocity and acceleration (32 bytes) and one
// 64-byte accumulator per thread; per particle 96 bytes (+50 with cracks:
// displacement, grad u, side), doubled for the vectors' growth while the
// particles are made and for the output's copies.
double mpm_solid_memory_bytes(const scene::MpmSolid& m) {
  const bool cracked = m.cracks_size() > 0;
  const double fields = cracked ? 2 : 1;
  const double threads = std::clamp<double>(m.threads(), 1, 64);
  const double per_node = 57 + 4 + 8 + fields * (32 + 64 * threads) + (cracked ? 57 : 0);
  const double per_particle = 2 * (96 + (cracked ? 50 : 0));
  return mpm_solid_nodes(m) * per_node + mpm_solid_particles(m) * per_particle;
}

double memory_limit_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return 0;  // unknown: no check
  return 0.75 * static_cast<double>(pages) * static_cast<double>(page);
}

double mpm_solid_stable_dt(const scene::MpmSolid& m) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double fastest = 0;
  for (const auto& mat : m.materials()) {
    const double e = mat.youngs_modulus_pa(), nu = mat.poisson_ratio(), rho = mat.density_kg_m3();
    if (!(std::isfinite(e) && e > 0 && std::isfinite(rho) && rho > 0 && nu >= 0 && nu < 0.5)) return nan;
    const double p_modulus = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
    fastest = std::max(fastest, std::sqrt(p_modulus / (rho * m.density_scaling())));
  }
  const double h = m.cell_size_m(), cfl = m.cfl();
  if (m.materials_size() == 0 || !(std::isfinite(h) && h > 0 && std::isfinite(cfl) && cfl > 0) ||
      !(m.density_scaling() >= 1)) {
    return nan;
  }
  return cfl * h / fastest;
}

}  // namespace hfmpm::coupling
