#include "hfmpm/solid/mpm/solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "hfmpm/solid/mpm/shape.hpp"

namespace hfmpm::solid::mpm {
namespace {

Vec2 outward_normal(Edge edge) {
  switch (edge) {
    case Edge::Left:
      return {-1, 0};
    case Edge::Right:
      return {1, 0};
    case Edge::Bottom:
      return {0, -1};
    case Edge::Top:
      return {0, 1};
  }
  return {0, 0};
}

// Counter-clockwise tangent of an edge with outward normal n.
Vec2 tangent(const Vec2& n) { return {-n.y(), n.x()}; }

}  // namespace

Solver::Solver(SolidConfig config) : config_(std::move(config)) {
  if (config_.materials.empty()) throw std::invalid_argument("an MPM solid needs at least one material");
  for (const auto& m : config_.materials) {
    const double rho = m.density * config_.density_scaling;
    lambda_.push_back(m.lame_lambda());
    shear_.push_back(m.shear_modulus());
    p_modulus_.push_back(m.p_modulus());
    density_.push_back(rho);
  }
  const std::size_t n = config_.grid.node_count();
  const bool cracked = !config_.cracks.empty();
  for (std::size_t c = 0; c < config_.cracks.size(); ++c) {
    cracks_.emplace_back(static_cast<std::uint32_t>(c), config_.cracks[c]);
  }
  field0_.resize(n);
  touched_in_.assign(n, 0);
  const int fields = cracked ? 2 : 1;  // an uncracked body never touches field 1
  for (int f = 0; f < fields; ++f) {
    velocity_[f].assign(n, Vec2::Zero());
    acceleration_[f].assign(n, Vec2::Zero());
  }
  const auto threads = static_cast<std::size_t>(std::max(1, config_.threads));
  thread_acc_.resize(threads);
  thread_span_.assign(threads, {0, 0});
  thread_side_span_.assign(threads, {0, 0});
  thread_active_.resize(threads);
  for (auto& acc : thread_acc_) acc.resize(n * static_cast<std::size_t>(fields));
  if (cracked) field1_.resize(n);
  generate_particles();
  if (cracked) {
    particles_.displacement.assign(particles_.size(), Vec2::Zero());
    particles_.grad_u.assign(particles_.size(), Eigen::Matrix2d::Zero());
  }
  if (cracked) stencil_fields_.assign(particles_.size(), 0);
  build_constraints();
  find_edges();
  double lightest = std::numeric_limits<double>::infinity();
  for (double m : particles_.mass) {
    lightest = std::min(lightest, m);
    total_mass_ += m;
  }
  min_mass_ = 1e-9 * lightest;
  sliver_mass_ = config_.grid.h * config_.grid.h * *std::min_element(density_.begin(), density_.end()) / 64;
}

// Each cell is filled at one density: the largest particles_per_cell of the
// regions found in it (sampled at the particle positions of every density,
// 1 to 4 per direction), so particles of one cell never overlap and a region
// boundary inside a cell takes the finer spacing. Each particle then takes
// the material and stress of the region that wins at its own position.
// Particles stay ordered by rows of cells, as the threads' node spans expect.
void Solver::generate_particles() {
  const auto& g = config_.grid;
  constexpr int kMaxPpc = 4;
  auto density_of = [&](const Region& r) {
    return r.particles_per_cell > 0 ? r.particles_per_cell : config_.particles_per_cell;
  };
  auto winner = [&](const Vec2& x) -> const Region* {
    const Region* found = nullptr;
    for (const auto& r : config_.regions) {
      if (r.contains(x)) found = &r;  // later regions win
    }
    return found;
  };
  bool uniform = true;
  for (const auto& r : config_.regions) uniform = uniform && density_of(r) == config_.particles_per_cell;
  auto cell_density = [&](int i, int j) {
    if (uniform) return config_.particles_per_cell;
    int best = 0;
    for (int k = 1; k <= kMaxPpc; ++k) {
      for (int b = 0; b < k; ++b) {
        for (int a = 0; a < k; ++a) {
          const Region* r = winner(g.origin + Vec2((i + (a + 0.5) / k) * g.h, (j + (b + 0.5) / k) * g.h));
          if (r) best = std::max(best, density_of(*r));
        }
      }
    }
    return best > 0 ? best : config_.particles_per_cell;
  };
  std::vector<int> row_density(static_cast<std::size_t>(g.nx));
  for (int j = 0; j < g.ny; ++j) {
    for (int i = 0; i < g.nx; ++i) row_density[static_cast<std::size_t>(i)] = cell_density(i, j);
    for (int b = 0; b < kMaxPpc; ++b) {
      for (int i = 0; i < g.nx; ++i) {
        const int ppc = row_density[static_cast<std::size_t>(i)];
        if (b >= ppc) continue;
        const double spacing = g.h / ppc;
        const double volume = spacing * spacing;
        for (int a = 0; a < ppc; ++a) {
          const Vec2 x = g.origin + Vec2((i + (a + 0.5) / ppc) * g.h, (j + (b + 0.5) / ppc) * g.h);
          const Region* found = winner(x);
          if (!found) continue;
          const auto mat = static_cast<std::size_t>(found->material);
          if (config_.in_situ_reference) {
            particles_.add(x, density_[mat] * volume, volume, spacing / 2, Voigt::Zero(), found->material);
            particles_.region.push_back(static_cast<std::int32_t>(found - config_.regions.data()));
          } else {
            particles_.add(x, density_[mat] * volume, volume, spacing / 2, found->initial_stress, found->material);
          }
        }
      }
    }
  }
  if (particles_.size() == 0) throw std::invalid_argument("the regions contain no particle: the body is empty");
  particles_.shrink_to_fit();  // drop push_back's slack: up to half the particle memory
}

void Solver::build_constraints() {
  const auto& g = config_.grid;
  const double tol = 1e-9 * g.h;
  const bool cracked = !config_.cracks.empty();
  for (const auto& c : config_.constraints) {
    int count = 0;
    for (std::size_t n = 0; n < g.node_count(); ++n) {
      const Vec2 x = g.position(static_cast<int>(n));
      std::uint8_t mask = 0;
      if (c.kind == Constraint::Kind::PlaneX && std::abs(x.x() - c.coordinate) < tol) mask = 1;
      if (c.kind == Constraint::Kind::PlaneY && std::abs(x.y() - c.coordinate) < tol) mask = 2;
      if (c.kind == Constraint::Kind::Box && (x.array() >= c.lo.array() - tol).all() &&
          (x.array() <= c.hi.array() + tol).all()) {
        mask = static_cast<std::uint8_t>((c.fix_x ? 1 : 0) | (c.fix_y ? 2 : 0));
      }
      if (mask) {
        field0_.fixed[n] |= mask;
        if (cracked) field1_.fixed[n] |= mask;
        ++count;
      }
    }
    if (count == 0) {
      std::ostringstream out;
      out << "a velocity constraint selects no grid node (symmetry planes must lie on a grid line: x0 + k h)";
      throw std::invalid_argument(out.str());
    }
  }
}

void Solver::find_edges() {
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const Vec2 half = Vec2::Constant(particles_.half_size[p]);
    lo = lo.cwiseMin(particles_.x[p] - half);
    hi = hi.cwiseMax(particles_.x[p] + half);
  }
  body_lo_ = lo;
  body_hi_ = hi;
  const double tol = 1e-6 * config_.grid.h;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const Vec2 a = particles_.x[p] - Vec2::Constant(particles_.half_size[p]);
    const Vec2 b = particles_.x[p] + Vec2::Constant(particles_.half_size[p]);
    const auto id = static_cast<std::uint32_t>(p);
    if (a.x() - lo.x() < tol) edges_[static_cast<std::size_t>(Edge::Left)].push_back(id);
    if (hi.x() - b.x() < tol) edges_[static_cast<std::size_t>(Edge::Right)].push_back(id);
    if (a.y() - lo.y() < tol) edges_[static_cast<std::size_t>(Edge::Bottom)].push_back(id);
    if (hi.y() - b.y() < tol) edges_[static_cast<std::size_t>(Edge::Top)].push_back(id);
  }
}

double Solver::stable_dt() const {
  double fastest = 0;
  for (std::size_t m = 0; m < p_modulus_.size(); ++m)
    fastest = std::max(fastest, std::sqrt(p_modulus_[m] / density_[m]));
  return config_.cfl * config_.grid.h / fastest;
}

double Solver::kinetic_energy() const {
  double e = 0;
  for (std::size_t p = 0; p < particles_.size(); ++p) e += 0.5 * particles_.mass[p] * particles_.v[p].squaredNorm();
  return e;
}

double Solver::strain_energy() const {
  double e = 0;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const Material& m = config_.materials[static_cast<std::size_t>(particles_.material[p])];
    const Voigt& s = particles_.stress[p];  // xx, yy, xy, zz
    const double nu = m.poisson_ratio;
    const double normal = s[0] * s[0] + s[1] * s[1] + s[3] * s[3] - 2 * nu * (s[0] * s[1] + s[1] * s[3] + s[3] * s[0]);
    e += particles_.volume[p] * (normal + 2 * (1 + nu) * s[2] * s[2]) / (2 * m.youngs_modulus);
  }
  return e;
}

void Solver::begin_step() {
  if (step_begun_) return;
  ++transfer_;
  if (cracks_.empty()) {
    p2g<false>();
    edge_loads();
  } else {
    record_faces();
    for (auto& crack : cracks_) {
      crack.prepare(3 * config_.grid.h, 1e-6 * config_.grid.h);
      crack.clear_contact();
    }
    update_releases();
    p2g<true>();
    if (config_.fracture.surfaces_from_material) anchor_crack_surfaces();
    contact(0.0);  // on the extrapolated momenta
    edge_loads();
    crack_loads(true, false);
  }
  step_begun_ = true;
}

void Solver::step(double dt) {
  begin_step();
  step_begun_ = false;
  if (cracks_.empty()) {
    grid_update(dt);
    g2p<false>(dt);
  } else {
    crack_loads(false, true);
    grid_update(dt);
    if (config_.implicit_face_stiffness) implicit_face_stiffness(dt);
    contact(dt);  // on the updated momenta, forces made consistent
    for (auto& crack : cracks_) crack.finish_contact(dt);
    g2p<true>(dt);
    move_crack_surfaces(dt);
    account_in_situ_shear_work();
  }
  t_ += dt;
  ++steps_;
  if (config_.damping.feedback_q > 0) update_feedback(dt);
  if (config_.fracture.propagate && !cracks_.empty() &&
      steps_ % static_cast<std::uint64_t>(std::max(1, config_.fracture.check_interval)) == 0) {
    propagate();
  }
}

// Tractions and dashpots act on the body's edge: each edge particle carries
// traction x its edge length 2 lp, spread along the edge with its uGIMP
// weights and across it with the linear weights at the edge line itself, so a
// uniform stress held by equal tractions is in exact equilibrium.
void Solver::edge_loads() {
  const auto& g = config_.grid;
  auto spread = [&](std::uint32_t p, const Vec2& n, const Vec2& force) {
    const double lp = particles_.half_size[p];
    const Vec2 rel = particles_.x[p] + lp * n - g.origin;  // point on the edge line
    const bool vertical_edge = n.x() != 0;
    const auto along = ugimp_stencil(vertical_edge ? rel.y() : rel.x(), g.h, lp);
    const double across = vertical_edge ? rel.x() : rel.y();
    const int base = static_cast<int>(std::floor(across / g.h));
    for (int c = 0; c < 2; ++c) {
      const double w_across = linear_1d(across - (base + c) * g.h, g.h).s;
      if (w_across == 0) continue;
      for (int a = 0; a < 3; ++a) {
        const double w = w_across * along.s[static_cast<std::size_t>(a)];
        if (w == 0) continue;
        const int i = vertical_edge ? base + c : along.first + a;
        const int j = vertical_edge ? along.first + a : base + c;
        if (!g.inside(i, j)) continue;
        const auto node = static_cast<std::size_t>(g.node(i, j));
        if (touched_in_[node] != transfer_) continue;  // no mass there: nothing to push
        // Near a crack the force goes to the field of the particle's side.
        const bool other = !cracks_.empty() && near_crack(particles_.x[p]) &&
                           field_of(particles_.x[p], g.position(static_cast<int>(node)));
        (other ? field1_ : field0_).force[node] += w * force;
      }
    }
  };
  for (const auto& traction : config_.tractions) {
    const Vec2 n = outward_normal(traction.edge);
    const Vec2 t = traction.normal(t_) * n + traction.shear(t_) * tangent(n);
    for (std::uint32_t p : edges_[static_cast<std::size_t>(traction.edge)]) {
      spread(p, n, t * 2 * particles_.half_size[p]);
    }
  }
  if (config_.in_situ_reference) {
    // The particles carry no in-situ stress, so no edge holds its traction
    // sigma0 n: every edge gets -sigma0 n on top of its own load (on a
    // symmetry plane the constraint takes the normal part).
    for (Edge edge : {Edge::Left, Edge::Right, Edge::Bottom, Edge::Top}) {
      const Vec2 n = outward_normal(edge);
      for (std::uint32_t p : edges_[static_cast<std::size_t>(edge)]) {
        const Voigt& s0 = config_.regions[static_cast<std::size_t>(particles_.region[p])].initial_stress;
        const Vec2 t0 = traction(s0, n);
        if (t0.squaredNorm() > 0) spread(p, n, -t0 * 2 * particles_.half_size[p]);
      }
    }
  }
  for (Edge edge : config_.silent_edges) {
    // Lysmer-Kuhlemeyer dashpots: t = -rho (c_p v_n n + c_s v_t t)
    const Vec2 n = outward_normal(edge);
    const Vec2 tg = tangent(n);
    for (std::uint32_t p : edges_[static_cast<std::size_t>(edge)]) {
      const auto m = static_cast<std::size_t>(particles_.material[p]);
      const double rho = density_[m];
      const double cp = std::sqrt(p_modulus_[m] / rho), cs = std::sqrt(shear_[m] / rho);
      const Vec2& v = particles_.v[p];
      const Vec2 traction = -rho * (cp * v.dot(n) * n + cs * v.dot(tg) * tg);
      spread(p, n, traction * 2 * particles_.half_size[p]);
    }
  }
}

void Solver::grid_update(double dt) {
  const double alpha = config_.damping.grid_alpha + feedback_alpha_;
  const int fields = cracks_.empty() ? 1 : 2;
  for (int field = 0; field < fields; ++field) {
    const NodalFields& nodes = field ? field1_ : field0_;
    auto& velocity = velocity_[field];
    auto& acceleration = acceleration_[field];
    for (int n : active_) {
      const auto u = static_cast<std::size_t>(n);
      const double m = nodes.mass[u];
      if (m <= min_mass_) {
        velocity[u].setZero();
        acceleration[u].setZero();
        continue;
      }
      Vec2 f = nodes.force[u] - alpha * nodes.momentum[u];
      Vec2 p = nodes.momentum[u] + dt * f;
      const std::uint8_t fixed = nodes.fixed[u];
      if (fixed & 1) f.x() = p.x() = 0;
      if (fixed & 2) f.y() = p.y() = 0;
      velocity[u] = p / m;
      acceleration[u] = f / m;
    }
  }
}

Voigt Solver::total_stress(std::size_t p) const {
  if (!config_.in_situ_reference) return particles_.stress[p];
  return particles_.stress[p] + config_.regions[static_cast<std::size_t>(particles_.region[p])].initial_stress;
}

std::vector<Voigt> Solver::total_stresses() const {
  std::vector<Voigt> out(particles_.size());
  for (std::size_t p = 0; p < out.size(); ++p) out[p] = total_stress(p);
  return out;
}

// Where a point lies: the region there (the last that holds it), or -1.
int Solver::region_at(const Vec2& x) const {
  int found = -1;
  for (std::size_t r = 0; r < config_.regions.size(); ++r) {
    if (config_.regions[r].contains(x)) found = static_cast<int>(r);  // later regions win
  }
  return found;
}

// Material at a point: the region there, else the nearest particle's.
std::size_t Solver::material_at(const Vec2& x) const {
  const int r = region_at(x);
  if (r >= 0) return static_cast<std::size_t>(config_.regions[static_cast<std::size_t>(r)].material);
  std::size_t material = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const double dist = (particles_.x[p] - x).squaredNorm();
    if (dist < best) {
      best = dist;
      material = static_cast<std::size_t>(particles_.material[p]);
    }
  }
  return material;
}

Voigt Solver::in_situ_stress(const Vec2& x) const {
  int r = region_at(x);
  if (r < 0) {
    // A crack's mouth on the body's edge may sit a round-off outside it:
    // take the nearest region (by its bounding box) within a cell.
    double best = config_.grid.h;
    for (std::size_t k = 0; k < config_.regions.size(); ++k) {
      const Region& reg = config_.regions[k];
      Vec2 lo = reg.lo, hi = reg.hi;
      if (reg.kind == Region::Kind::Layer) {
        lo.x() = -std::numeric_limits<double>::infinity();
        hi.x() = std::numeric_limits<double>::infinity();
      } else if (reg.kind == Region::Kind::Polygon && !reg.polygon.empty()) {
        lo = hi = reg.polygon.front();
        for (const auto& v : reg.polygon) {
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
      }
      const double d = (x - x.cwiseMax(lo).cwiseMin(hi)).norm();
      if (d <= best) {
        best = d;
        r = static_cast<int>(k);
      }
    }
  }
  return r < 0 ? Voigt::Zero() : config_.regions[static_cast<std::size_t>(r)].initial_stress;
}

bool Region::contains(const Vec2& p) const {
  switch (kind) {
    case Kind::Rectangle:
      return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
    case Kind::Layer:
      return p.y() >= lo.y() && p.y() <= hi.y();
    case Kind::Polygon: {
      // Even-odd rule by crossings of a ray in +x.
      bool inside = false;
      for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
        const Vec2& a = polygon[i];
        const Vec2& b = polygon[j];
        if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
          inside = !inside;
        }
      }
      return inside;
    }
  }
  return false;
}

}  // namespace hfmpm::solid::mpm
