// Geometry rules for solid.mpm: cracks (length, self-crossing, inside the
// grid and the body, mouth on an edge or a symmetry line, distance between
// cracks) and regions inside the grid.
#include <algorithm>
#include <cmath>
#include <vector>

#include "solid_scene_rules.hpp"

namespace hfmpm::solid {

using proto::Checker;
using proto::kInf;
using proto::text;
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
}  // namespace

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
    // A fluid entering inside the body (a wellbore) enters at an inner vertex
    // of a crack whose two ends are tips, and flows towards both.
    if (cr.has_inlet_vertex()) {
      const auto v = static_cast<std::size_t>(cr.inlet_vertex());
      if (!cr.start_is_tip() || !cr.end_is_tip()) {
        c.bad(k + ".inlet_vertex", std::to_string(v),
              "unset for a crack with a mouth (the fluid enters there); an inlet vertex is for a crack inside the "
              "body, start_is_tip: true and end_is_tip: true");
        bad = true;
      } else if (v < 1 || v + 1 >= pts.size()) {
        c.bad(k + ".inlet_vertex", std::to_string(v),
              "an inner vertex of the crack, 1 to " + std::to_string(pts.size() - 2) + " (of x_m / y_m)");
        bad = true;
      }
    }
    if (!(cr.friction_coefficient() >= 0) || !std::isfinite(cr.friction_coefficient())) {
      c.bad(k + ".friction_coefficient", std::to_string(cr.friction_coefficient()),
            "a finite number >= 0 (0: frictionless faces; a rock joint's is typically 0.6)");
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

}  // namespace hfmpm::solid
