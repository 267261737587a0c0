// Rules for solid.mpm: grid, materials, regions, constraints, tractions
// (geometry: scene_rules_geometry.cpp; cost: scene_size.cpp).
#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "solid_scene_rules.hpp"

namespace hfmpm::solid {

using proto::check_time_function;
using proto::Checker;
using proto::kInf;
using proto::text;
namespace {

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
    // 0: a material that holds no crack (the zero-toughness, viscosity-dominated limit).
    if (mat.has_toughness_j_m2()) c.non_negative(k + "toughness_j_m2", mat.toughness_j_m2(), "J/m^2");
    if (mat.has_toughness_pa_sqrt_m()) c.non_negative(k + "toughness_pa_sqrt_m", mat.toughness_pa_sqrt_m(), "Pa m^0.5");
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
  c.range(key + "fracture.release_transits", f.release_transits(), 0, 1e3, false, "shear-wave transits of the crack");
  if (std::isfinite(f.release_transits()) && f.release_transits() > f.settle_transits()) {
    // A tip grows again only once its last step is released (one release per tip).
    c.bad(key + "fracture.release_transits", text(f.release_transits()),
          "at most fracture.settle_transits (" + text(f.settle_transits()) + ")");
  }
  c.range(key + "fracture.front_settle_transits", f.front_settle_transits(), 0, 1e3, false,
          "shear-wave transits of the J domain");
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

}  // namespace hfmpm::solid
