// What a solid.mpm scene costs before it runs: nodes, particles, memory
// against the machine's, and the stable step (for the step-count check).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "solid_scene_rules.hpp"

namespace hfmpm::solid {

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

}  // namespace hfmpm::solid
