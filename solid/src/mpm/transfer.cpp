// Particle-grid transfers of the MPM solid: P2G (mass, momentum, internal
// force and the displacement sum into per-thread accumulators, reduced in
// parallel) and G2P (velocities, positions, the stress update, and the check
// that stops a run whose particles run away), with the buffers they use.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "hfmpm/solid/mpm/predicates.hpp"
#include "hfmpm/solid/mpm/shape.hpp"
#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {
namespace {

// The nodes of a particle's 3 x 3 stencil, clipped to the grid if kClip.
template <bool kClip, bool kSkipZero, class Fn>
inline void stencil_nodes(const Grid& g, const Stencil1D& sx, const Stencil1D& sy, Fn&& fn) {
  for (int b = 0; b < 3; ++b) {
    const int j = sy.first + b;
    if (kClip && (j < 0 || j > g.ny)) continue;
    const double syb = sy.s[static_cast<std::size_t>(b)], gyb = sy.g[static_cast<std::size_t>(b)];
    for (int a = 0; a < 3; ++a) {
      const int i = sx.first + a;
      if (kClip && (i < 0 || i > g.nx)) continue;
      const double w = sx.s[static_cast<std::size_t>(a)] * syb;
      if (kSkipZero && w == 0) continue;
      const double gx = sx.g[static_cast<std::size_t>(a)] * syb;
      const double gy = sx.s[static_cast<std::size_t>(a)] * gyb;
      fn(b, a, static_cast<std::size_t>(g.node(i, j)), w, gx, gy);
    }
  }
}

// The one stencil loop of P2G and G2P: fn(b, a, n, w, gx, gy) for each of the
// 3 x 3 nodes n = (sx.first + a, sy.first + b) on the grid, with the
// particle's weight w there and its gradient (gx, gy). Without kSkipZero,
// nodes the particle does not reach come too, with w = gx = gy = 0: a weight
// of zero adds an exact zero (the sums stay bit for bit what they would be
// without it), and testing for it cost more than it saved in the uncracked
// step (particles a round-off off a piece's end make it a coin toss for the
// branch predictor: half the mispredicted branches of the step). With cracks
// (kSkipZero) a node costs more (the side test, the displacement sum, the
// field lookup), and skipping the zeros saves a fifth of the instructions.
// Only particles near the grid's edge need the clipping.
template <bool kSkipZero = false, class Fn>
inline void for_stencil(const Grid& g, const Stencil1D& sx, const Stencil1D& sy, Fn&& fn) {
  if (sx.first >= 0 && sx.first + 2 <= g.nx && sy.first >= 0 && sy.first + 2 <= g.ny) {
    stencil_nodes<false, kSkipZero>(g, sx, sy, fn);
  } else {
    stencil_nodes<true, kSkipZero>(g, sx, sy, fn);
  }
}

}  // namespace

// P2G: each thread finds the band of grid rows its particles reach, scatters
// its particles into its own accumulator there, and (after all have) reduces
// one slice of the nodes over every thread's band into the fields, zeroing
// the accumulators' entries as it reads them: between P2Gs they are all
// zero (one pass over the bands per step instead of two).
template <bool kCracks>
void Solver::p2g() {
  const auto threads = thread_acc_.size();
  const std::size_t count = particles_.size();
  if constexpr (kCracks) {
    if (stencil_fields_.size() != count) stencil_fields_.assign(count, 0);
  }
#pragma omp parallel num_threads(static_cast <int>(threads))
  {
    const auto k = static_cast<std::size_t>(omp_get_thread_num());
    const std::size_t begin = count * k / threads;
    const std::size_t end = count * (k + 1) / threads;
    thread_span_[k] = p2g_band(begin, end);
    p2g_scatter<kCracks>(k, begin, end);
#pragma omp barrier
    p2g_reduce<kCracks>(k);
  }
  active_.clear();
  for (const auto& part : thread_active_) active_.insert(active_.end(), part.begin(), part.end());
}

// The rows of nodes particles [begin, end) reach (particles are stored row
// by row, so each thread's span is a band of the grid), as node indices
// [first, last).
std::array<std::size_t, 2> Solver::p2g_band(std::size_t begin, std::size_t end) const {
  const auto& g = config_.grid;
  const std::size_t row = static_cast<std::size_t>(g.nodes_x());
  double y_lo = std::numeric_limits<double>::infinity(), y_hi = -y_lo;
  for (std::size_t p = begin; p < end; ++p) {
    y_lo = std::min(y_lo, particles_.x[p].y());
    y_hi = std::max(y_hi, particles_.x[p].y());
  }
  std::array<std::size_t, 2> span{0, 0};
  if (begin < end) {
    const auto row_of = [&](double y) { return static_cast<int>(std::floor((y - g.origin.y()) / g.h + 0.5)); };
    // One row more each way than the stencil's reach, against rounding.
    const int j0 = std::clamp(row_of(y_lo) - 2, 0, g.ny);
    const int j1 = std::clamp(row_of(y_hi) + 2, 0, g.ny);
    span = {static_cast<std::size_t>(j0) * row, static_cast<std::size_t>(j1 + 1) * row};
  }
  return span;
}

// Mass, momentum, internal force (and, with cracks, the mass-weighted
// displacement and each particle's side of the crack per node) of particles
// [begin, end) into thread k's accumulator.
//
// The grid and the arrays are read through locals: the SSE2 stores may
// alias anything, so members would be reloaded at every node.
template <bool kCracks>
void Solver::p2g_scatter(std::size_t k, std::size_t begin, std::size_t end) {
  const Grid g = config_.grid;
  constexpr std::size_t F = kCracks ? 2 : 1;
  NodeAcc* const acc = thread_acc_[k].data();
  const Vec2 *const xs = particles_.x.data(), *const vs = particles_.v.data();
  const Vec2* const displacements = particles_.displacement.data();
  const double *const half_sizes = particles_.half_size.data(), *const masses = particles_.mass.data();
  const double* const volumes = particles_.volume.data();
  const Voigt* const stresses = particles_.stress.data();
  std::uint16_t* const stencil_fields = stencil_fields_.data();
  std::size_t side_first = std::numeric_limits<std::size_t>::max(), side_last = 0;  // field 1's nodes
  for (std::size_t p = begin; p < end; ++p) {
    const Vec2 x = xs[p];
    const Vec2 rel = x - g.origin;
    const StencilScale scale(g.h, half_sizes[p]);
    const auto sx = ugimp_stencil(rel.x(), scale);
    const auto sy = ugimp_stencil(rel.y(), scale);
    const double m = masses[p];
    const Vec2 mv = m * vs[p];
    const Voigt& s = stresses[p];
    // sigma . grad S = c0 gx + c1 gy with the stress's columns (s = xx, yy, xy, zz)
    const Vec2 c0(s[0], s[2]), c1(s[2], s[1]);
    const double vol = volumes[p];
    bool near = false;
    std::uint16_t sides = 0;
    Vec2 mu = Vec2::Zero();
    if constexpr (kCracks) {
      near = near_crack(x);
      if (near) sides = 1u << 15;
      mu = m * displacements[p];
    }
    for_stencil<kCracks>(g, sx, sy, [&](int b, int a, std::size_t n, double w, double gx, double gy) {
      std::size_t slot = n * F;
      if constexpr (kCracks) {
        if (near && field_of(x, g.position(static_cast<int>(n)))) {
          ++slot;
          sides = static_cast<std::uint16_t>(sides | (1u << (3 * b + a)));
          side_first = std::min(side_first, n);
          side_last = std::max(side_last, n + 1);
        }
      }
      // Both components of each vector in one SSE2 operation (the same
      // products and sums as component by component).
      NodeAcc& f = acc[slot];
      f.m += w * m;
      f.p += w * mv;
      f.f -= vol * (gx * c0 + gy * c1);  // internal force -V sigma . grad S
      if constexpr (kCracks) f.u += w * mu;
    });
    if constexpr (kCracks) stencil_fields[p] = sides;
  }
  thread_side_span_[k] = {std::min(side_first, side_last), side_last};
}

// Thread k's slice of the nodes, summed over every thread's band, into the
// fields (one field, or two with cracks), and the nodes it touched; the
// entries summed are zeroed for the next P2G. Field 1 is summed only over
// the nodes where the thread's particles gave it anything (a few rows along
// the cracks): elsewhere its entries hold +0, and adding +0 changes no sum.
template <bool kCracks>
void Solver::p2g_reduce(std::size_t k) {
  constexpr std::size_t F = kCracks ? 2 : 1;
  const auto threads = thread_acc_.size();
  const std::uint32_t epoch = transfer_;
  // Reduce the spans into the fields: each thread a slice of the nodes.
  std::size_t lo = std::numeric_limits<std::size_t>::max(), hi = 0;
  for (const auto& sp : thread_span_) {
    if (sp[0] < sp[1]) {
      lo = std::min(lo, sp[0]);
      hi = std::max(hi, sp[1]);
    }
  }
  auto& active = thread_active_[k];
  active.clear();
  if (lo < hi) {
    const std::size_t first = lo + (hi - lo) * k / threads, last = lo + (hi - lo) * (k + 1) / threads;
    for (std::size_t u = first; u < last; ++u) {
      NodeAcc sum[F] = {};
      for (std::size_t t = 0; t < threads; ++t) {
        const auto& sp = thread_span_[t];
        if (u < sp[0] || u >= sp[1]) continue;
        const auto& side = thread_side_span_[t];
        const std::size_t fields = u >= side[0] && u < side[1] ? F : 1;
        for (std::size_t f = 0; f < fields; ++f) {
          NodeAcc& from = thread_acc_[t][u * F + f];
          sum[f].m += from.m;
          sum[f].p += from.p;
          sum[f].f += from.f;
          sum[f].u += from.u;
          from = NodeAcc{};
        }
      }
      bool touched = sum[0].m > 0;
      if constexpr (kCracks) touched = touched || sum[1].m > 0;
      if (!touched) continue;
      touched_in_[u] = epoch;
      active.push_back(static_cast<int>(u));
      for (std::size_t f = 0; f < F; ++f) {
        NodalFields& to = f ? field1_ : field0_;
        to.mass[u] = sum[f].m;
        to.momentum[u] = sum[f].p;
        to.force[u] = sum[f].f;
        if constexpr (kCracks) to.displaced[u] = sum[f].u;
      }
    }
  }
}

// Each near-crack particle's displacement taken to the nodes of its stencil
// with its own gradient, u_p + grad u_p (x_i - x_p), mass-weighted into the
// field P2G put it in at each node (stencil_fields_): affine_[f][i] / the
// field's mass is the field's displacement at node i, exact for a linear
// field whatever part of the stencil the field holds (a field across a crack
// holds one particle row, whose mean displacement is a third of a cell off
// the node). Every particle that reaches a node beside a crack is near it,
// so those nodes' sums are whole. Serial: only the particles near a crack
// scatter (a few hundred in the KGD scenes). For anchor_crack_surfaces.
void Solver::affine_displacement() {
  const Grid g = config_.grid;
  for (int f = 0; f < 2; ++f) {
    auto& a = affine_[static_cast<std::size_t>(f)];
    if (a.size() != field0_.mass.size()) a.assign(field0_.mass.size(), Vec2::Zero());
  }
  for (const std::size_t n : affine_touched_) affine_[0][n] = affine_[1][n] = Vec2::Zero();
  affine_touched_.clear();
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const std::uint16_t sides = stencil_fields_[p];
    if (!(sides & (1u << 15))) continue;  // not near a crack
    const Vec2 x = particles_.x[p];
    const Vec2 rel = x - g.origin;
    const StencilScale scale(g.h, particles_.half_size[p]);
    const auto sx = ugimp_stencil(rel.x(), scale);
    const auto sy = ugimp_stencil(rel.y(), scale);
    const double m = particles_.mass[p];
    const Vec2 u = particles_.displacement[p];
    const Eigen::Matrix2d& grad = particles_.grad_u[p];
    for_stencil<true>(g, sx, sy, [&](int b, int a, std::size_t n, double w, double, double) {
      const int field = (sides >> (3 * b + a)) & 1;
      Vec2& to = affine_[static_cast<std::size_t>(field)][n];
      if (to.isZero() && affine_[static_cast<std::size_t>(1 - field)][n].isZero()) affine_touched_.push_back(n);
      to += w * m * (u + grad * (g.position(static_cast<int>(n)) - x));
    });
  }
}

// A crack that grows under load must leave the body as a crack cut at its
// new length would (docs/solid.md, "The strain of the particles a growth
// step cuts"). A particle's displacement gradient is the sum of its velocity
// gradients, which the uncut body's nodes gave it; once a new segment cuts
// a line from it to one of its stencil nodes, that node's field holds only
// the particle's own side, and the gradient the particle carries is not the
// gradient of any displacement its nodes can have. The difference acts as a
// stress the new faces cannot relieve: particles beside a grown crack kept
// +-2 MPa under a 0.7 MPa tension, and the grown part opened 0.86-0.96 of
// the cut crack's (the material's opening; tests/solid/propagation_test.cpp).
// So each particle that uses a node whose particles the new segments
// re-sort (the line from some particle to it crosses a new segment) takes the
// gradient of its fields' nodal displacements (every particle's displacement
// carried to its stencil nodes with its own gradient, mass weighted per
// field: exact for a linear field), and its stress changes by C : the
// change of its strain. Serial and local: only particles within a few cells
// of the new segments take part.
int Solver::reproject_strains(const std::vector<std::array<Vec2, 2>>& segments) {
  if (segments.empty() || particles_.grad_u.empty()) return 0;
  const Grid g = config_.grid;
  // A stencil node lies within 1.5 h + lp <= 2 h of its particle in each
  // direction, so within reach = 2 sqrt(2) h: a re-sorted node lies within
  // reach of a new segment (the line to it from some particle crosses the
  // segment), a particle using it within 2 reach, that particle's nodes
  // within 3 reach, and every particle that contributes to them within
  // 4 reach: the sums over gathered particles are whole at every node a
  // target reads.
  const double reach = 2 * std::sqrt(2.0) * g.h, gather = 4 * reach;
  auto distance = [&](const Vec2& x) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& s : segments) {
      const Vec2 d = s[1] - s[0];
      const double len2 = d.squaredNorm();
      const double t = len2 > 0 ? std::clamp((x - s[0]).dot(d) / len2, 0.0, 1.0) : 0.0;
      best = std::min(best, (s[0] + t * d - x).norm());
    }
    return best;
  };
  struct Sum {
    double m = 0;
    Vec2 mu = Vec2::Zero();
  };
  std::unordered_map<std::size_t, Sum> nodes;  // key: node * 2 + field
  auto for_nodes = [&](std::size_t p, auto&& fn) {
    const Vec2 x = particles_.x[p];
    const Vec2 rel = x - g.origin;
    const StencilScale scale(g.h, particles_.half_size[p]);
    const auto sx = ugimp_stencil(rel.x(), scale);
    const auto sy = ugimp_stencil(rel.y(), scale);
    const bool near = near_crack(x);
    for_stencil<true>(g, sx, sy, [&](int, int, std::size_t n, double w, double gx, double gy) {
      const Vec2 node = g.position(static_cast<int>(n));
      const std::size_t f = near && field_of(x, node) ? 1 : 0;
      fn(n * 2 + f, node, w, gx, gy);
    });
  };
  std::vector<std::size_t> gathered;
  std::unordered_set<std::size_t> changed;  // nodes a new segment cuts from some particle
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const double d = distance(particles_.x[p]);
    if (d > gather) continue;
    gathered.push_back(p);
    const Vec2 x = particles_.x[p];
    const double m = particles_.mass[p];
    const Vec2 u = particles_.displacement[p];
    const Eigen::Matrix2d& grad = particles_.grad_u[p];
    for_nodes(p, [&](std::size_t key, const Vec2& node, double w, double, double) {
      Sum& s = nodes[key];
      s.m += w * m;
      s.mu += w * m * (u + grad * (node - x));
      if (d > reach) return;
      for (const auto& seg : segments) {
        if (segments_cross(x, node, seg[0], seg[1])) changed.insert(key / 2);
      }
    });
  }
  std::vector<std::size_t> targets;
  for (const std::size_t p : gathered) {
    bool touches = false;
    for_nodes(
        p, [&](std::size_t key, const Vec2&, double, double, double) { touches = touches || changed.count(key / 2); });
    if (touches) targets.push_back(p);
  }
  std::vector<Eigen::Matrix2d> gradient(targets.size(), Eigen::Matrix2d::Zero());
  for (std::size_t k = 0; k < targets.size(); ++k) {
    for_nodes(targets[k], [&](std::size_t key, const Vec2&, double, double gx, double gy) {
      const Sum& s = nodes[key];
      if (s.m <= min_mass_) return;
      const Vec2 un = s.mu / s.m;
      gradient[k].col(0) += gx * un;
      gradient[k].col(1) += gy * un;
    });
  }
  // Written after all are read: a target is also a contributor.
  for (std::size_t k = 0; k < targets.size(); ++k) {
    const std::size_t p = targets[k];
    const Eigen::Matrix2d d = gradient[k] - particles_.grad_u[p];
    const double dxx = d(0, 0), dyy = d(1, 1), dxy = 0.5 * (d(0, 1) + d(1, 0)), tr = dxx + dyy;
    const auto mat = static_cast<std::size_t>(particles_.material[p]);
    const double lam = lambda_[mat], mu = shear_[mat];
    particles_.stress[p] += Voigt(lam * tr + 2 * mu * dxx, lam * tr + 2 * mu * dyy, 2 * mu * dxy, lam * tr);
    particles_.grad_u[p] = gradient[k];
  }
  return static_cast<int>(targets.size());
}

// The grid and the arrays through locals, as in p2g_scatter.
template <bool kCracks>
void Solver::g2p(double dt) {
  const Grid g = config_.grid;
  const Vec2* const velocity[2] = {velocity_[0].data(), velocity_[1].data()};
  const Vec2* const acceleration[2] = {acceleration_[0].data(), acceleration_[1].data()};
  const std::uint16_t* const stencil_fields = stencil_fields_.data();
  Vec2 *const xs = particles_.x.data(), *const vs = particles_.v.data();
  Vec2* const displacements = particles_.displacement.data();
  Eigen::Matrix2d* const grad_us = particles_.grad_u.data();
  Voigt* const stresses = particles_.stress.data();
  const double* const half_sizes = particles_.half_size.data();
  const std::int32_t* const materials = particles_.material.data();
  const double *const lambdas = lambda_.data(), *const shears = shear_.data();
  const double pic = config_.damping.pic_fraction;
  const Vec2 lo = g.origin, hi = g.origin + g.h * Vec2(g.nx, g.ny);
  const auto count = static_cast<std::int64_t>(particles_.size());
  std::int64_t escaped = -1;
  const double runaway = g.h;  // m per step
#pragma omp parallel for num_threads(static_cast <int>(thread_acc_.size())) schedule(static)
  for (std::int64_t q = 0; q < count; ++q) {
    const auto p = static_cast<std::size_t>(q);
    const Vec2 rel = xs[p] - g.origin;
    const StencilScale scale(g.h, half_sizes[p]);
    const auto sx = ugimp_stencil(rel.x(), scale);
    const auto sy = ugimp_stencil(rel.y(), scale);
    std::uint16_t sides = 0;
    if constexpr (kCracks) sides = stencil_fields[p];  // the fields P2G found for its nodes
    Vec2 v_new = Vec2::Zero(), a = Vec2::Zero();
    // The velocity gradient L = grad v by columns: (L00, L10) and (L01, L11).
    Vec2 l_x = Vec2::Zero(), l_y = Vec2::Zero();
    for_stencil<kCracks>(g, sx, sy, [&](int b, int c, std::size_t n, double w, double gx, double gy) {
      const int field = (sides >> (3 * b + c)) & 1;
      const Vec2& vn = velocity[field][n];
      v_new += w * vn;
      a += w * acceleration[field][n];
      l_x += gx * vn;
      l_y += gy * vn;
    });
    const double l00 = l_x.x(), l01 = l_y.x(), l10 = l_x.y(), l11 = l_y.y();
    vs[p] = (1 - pic) * (vs[p] + dt * a) + pic * v_new;
    xs[p] += dt * v_new;
    if constexpr (kCracks) {
      displacements[p] += dt * v_new;
      auto& gu = grad_us[p];
      gu(0, 0) += dt * l00;
      gu(0, 1) += dt * l01;
      gu(1, 0) += dt * l10;
      gu(1, 1) += dt * l11;
    }
    // Small-strain elastic update, plane strain (eps_zz = 0).
    const double dxx = l00 * dt, dyy = l11 * dt, dxy = 0.5 * (l01 + l10) * dt;
    const auto m = static_cast<std::size_t>(materials[p]);
    const double lam = lambdas[m], mu = shears[m];
    const double tr = dxx + dyy;
    stresses[p] += Voigt(lam * tr + 2 * mu * dxx, lam * tr + 2 * mu * dyy, 2 * mu * dxy, lam * tr);
    const Vec2& x = xs[p];
    // A particle that leaves the grid, becomes NaN, or moves more than a
    // cell in one step (|v| > 2 c_p at the largest valid CFL factor; the
    // shape functions cannot follow that) has run away.
    if (!(x.x() >= lo.x() && x.y() >= lo.y() && x.x() <= hi.x() && x.y() <= hi.y()) ||
        !(dt * v_new.norm() <= runaway)) {
#pragma omp critical
      escaped = q;
    }
  }
  if (escaped >= 0) throw std::runtime_error(runaway_report(static_cast<std::size_t>(escaped), dt));
}

// What a run that blew up needs to be told: which particle, where, how fast,
// and the loads that can drive it, with what to change.
std::string Solver::runaway_report(std::size_t p, double dt) const {
  const auto& g = config_.grid;
  std::ostringstream out;
  out << "the solid ran away at step " << steps_ + 1 << " (t = " << t_ + dt << " s): particle " << p << " at x = ("
      << particles_.x[p].x() << ", " << particles_.x[p].y() << ") m moved at v = (" << particles_.v[p].x() << ", "
      << particles_.v[p].y() << ") m/s, " << dt * particles_.v[p].norm() / g.h
      << " cells in one step (the limit is 1; NaN or off the grid counts too). ";
  // The largest crack face pressure: a fluid pressure spike (a flow-rate
  // inlet into a film too thin to carry it) shows here.
  double p_max = 0;
  Vec2 where = Vec2::Zero();
  std::uint32_t crack_id = 0;
  for (const auto& crack : cracks_) {
    for (std::size_t k = 0; k < crack.size(); ++k) {
      if (crack.face_pressure(k) > p_max) {
        p_max = crack.face_pressure(k);
        where = crack.plane()[k];
        crack_id = crack.id();
      }
    }
  }
  double stress_max = 0;
  for (const auto& m : config_.regions) stress_max = std::max(stress_max, m.initial_stress.cwiseAbs().maxCoeff());
  if (!cracks_.empty()) {
    out << "Largest crack face pressure: " << p_max << " Pa on crack " << crack_id << " at (" << where.x() << ", "
        << where.y() << ") m";
    if (p_max > 10 * std::max(stress_max, 1.0)) {
      out << ", more than 10 x the largest in-situ stress (" << stress_max
          << " Pa): a pressure spike from the fluid; give the fluid room (a larger fluid.mpm.virtual_opening_m or "
             "a pre-opening), ramp the inlet more slowly, or soften the fluid (bulk_modulus_pa). ";
    } else {
      out << ". ";
    }
  }
  out << "Otherwise lower solid.mpm.cfl or time.safety_factor, or check the boundary conditions and loads.";
  return out.str();
}

std::size_t Solver::grid_bytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  auto fields = [&](const NodalFields& f) {
    return bytes(f.mass) + bytes(f.momentum) + bytes(f.force) + bytes(f.displaced) + bytes(f.fixed);
  };
  std::size_t total = fields(field0_) + fields(field1_) + bytes(touched_in_) + bytes(active_);
  for (int f = 0; f < 2; ++f) total += bytes(velocity_[f]) + bytes(acceleration_[f]);
  for (const auto& acc : thread_acc_) total += bytes(acc);
  return total;
}

template void Solver::p2g<false>();
template void Solver::p2g<true>();
template void Solver::g2p<false>(double);
template void Solver::g2p<true>(double);

}  // namespace hfmpm::solid::mpm
