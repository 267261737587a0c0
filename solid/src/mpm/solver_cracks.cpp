// The crack parts of the MPM step (CRAMP): which velocity field a
// particle-node pair uses, crack-face pressure into each side's field, the
// faces' one-step response, the implicit face stiffness and contact. Where
// the crack surfaces are: crack_surfaces.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "hfmpm/solid/mpm/predicates.hpp"
#include "hfmpm/solid/mpm/shape.hpp"
#include "hfmpm/solid/mpm/solver.hpp"
#include "side_nodes.hpp"

namespace hfmpm::solid::mpm {

using detail::for_side_nodes;

int Solver::field_of(const Vec2& from, const Vec2& node) const {
  bool odd = false;
  for (const auto& crack : cracks_) {
    if (crack.crosses(from, node)) odd = !odd;  // an even number of crossings cancels
  }
  return odd ? 1 : 0;
}

void Solver::set_crack_pressure(std::size_t c, const std::vector<double>& pressure,
                                const std::vector<double>& stiffness, const std::vector<double>& width,
                                std::size_t offset) {
  cracks_.at(c).receive_pressure(pressure, stiffness, width, offset);
}

void Solver::set_crack_front(std::size_t c, double start, double end) { cracks_.at(c).set_wetted(start, end); }

// How the face load of one side at crack particle k is shared among the
// nodes around its surface point: the linear weights w, renormalized over the
// nodes where that side's field has mass, but a field lighter than a 64th of
// a full node's mass (rho h^2 / 64, a "sliver") takes its share in proportion
// to its mass: w m / (rho h^2 / 64). Without that limit a node whose field
// for that side held only the tail of one particle's weight (a crack just
// grown past or through a particle's centre) took a full share of the load
// on a sliver of mass: its velocity jumped by w F dt / m, that velocity
// entered the particles' strain through the shape-function gradients, and
// the particles around a fresh tip chattered at tens of m/s while J went to
// -5e4 J/m^2 (issue 18). Fields of whole material stay untouched: the
// lightest is the far row of a crack between node rows, whose field for the
// other side holds a quarter of that side's first particle row, an 8th of a
// node with 2 x 2 particles per cell (a 16th at a body edge, a 32nd at a
// corner); there the face load must balance the stress those particles
// carry (an in-situ stress without in_situ_reference), and limiting it at a
// quarter of a node blew the KGD toughness scene up within 20 steps. The
// slivers of issue 18 are far lighter: the oblique growth test gives the
// same numbers to 4 digits for limits from 1e-5 to 1/64 of a node.
// The explicit load (crack_loads) and the implicit face stiffness use the
// same shares.
struct FaceShares {
  int count = 0;
  int node[4] = {0, 0, 0, 0}, field[4] = {0, 0, 0, 0};
  double share[4] = {0, 0, 0, 0};  // sums to 1
};

FaceShares Solver::face_shares(const Crack& crack, std::size_t k, int side) const {
  const NodalFields* fields[2] = {&field0_, &field1_};
  FaceShares out;
  double total = 0;
  for_side_nodes(*this, config_.grid, fields, crack, k, side, min_mass_, [&](int nd, int f, double w) {
    out.node[out.count] = nd;
    out.field[out.count] = f;
    out.share[out.count] = w * std::min(1.0, fields[f]->mass[static_cast<std::size_t>(nd)] / sliver_mass_);
    total += out.share[out.count++];
  });
  for (int c = 0; c < out.count; ++c) out.share[c] /= total;
  return out;
}

void Solver::spread_face_force(const Crack& crack, std::size_t k, int side, const Vec2& force) {
  const FaceShares s = face_shares(crack, k, side);
  for (int c = 0; c < s.count; ++c) {
    (s.field[c] ? field1_ : field0_).force[static_cast<std::size_t>(s.node[c])] += s.share[c] * force;
  }
}

// A growth step released over time (Fracture::release_transits): the face
// load (the fluid's pressure, and the in-situ traction under
// in_situ_reference) on the part of the crack within `length` of the tip
// that grew is applied with the weight 1 - r, r = (1 + cos(pi s)) / 2,
// s = (t - t0) / tau, as a tip advancing steadily over tau would load it
// (its loaded length growing with time; the half-cosine is the smooth form of
// that ramp). The crack particles there take (1 - r) of their tributary
// length's load in crack_loads, face_response and implicit_face_stiffness
// alike, so the implicit interface solve sees the load the solid applies.
// Loaded at once, the new part opens within a few h / c: a zero-lag fluid
// cannot follow, its pressure at the tip drops by a third, and that dip runs
// to the mouth as a wave (a toughness KGD's inlet pressure dipped 10% at
// every growth step). A load switched on over a half-cosine of duration tau
// leaves a mode of period T ringing with |cos(pi tau / T) / (1 - (2 tau /
// T)^2)| of a sudden load's amplitude (docs/solid.md, "Growth").
namespace {
double release_remaining(double t, double t0, double tau, double length) {
  constexpr double kPi = 3.14159265358979323846;
  if (!(tau > 0) || !(length > 0) || !(t < t0 + tau)) return 0;
  return 0.5 * (1 + std::cos(kPi * std::clamp((t - t0) / tau, 0.0, 1.0)));
}
}  // namespace

void Solver::update_releases() {
  unloaded_.resize(cracks_.size());
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    unloaded_[c].clear();
    if (c >= releases_.size()) continue;
    const Crack& crack = cracks_[c];
    const std::size_t n = crack.size();
    std::vector<double> arc;
    for (int end = 0; end < 2; ++end) {
      const Release& r = releases_[c][static_cast<std::size_t>(end)];
      const double remaining = release_remaining(t_, r.t0, r.tau, r.length);
      if (remaining <= 0) continue;
      if (arc.empty()) arc = arc_length(crack.plane());
      if (unloaded_[c].empty()) unloaded_[c].assign(n, 0.0);
      for (std::size_t k = 0; k < n; ++k) {
        // Particle k's tributary part of the crack, as distances from this tip;
        // the part within r.length of it is unloaded by `remaining`.
        const double before = k > 0 ? 0.5 * (arc[k] - arc[k - 1]) : 0.0;
        const double after = k + 1 < n ? 0.5 * (arc[k + 1] - arc[k]) : 0.0;
        const double d = end ? arc.back() - arc[k] : arc[k] - arc.front();
        const double lo = std::max(0.0, d - (end ? after : before));
        const double hi = std::min(r.length, d + (end ? before : after));
        if (!(hi > lo)) continue;
        unloaded_[c][k] += remaining * (hi - lo);
      }
    }
  }
}

void Solver::crack_loads(bool in_situ, bool pressure) {
  const bool with_in_situ = in_situ && config_.in_situ_reference;
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    const Crack& crack = cracks_[c];
    for (std::size_t k = 0; k < crack.size(); ++k) {
      const Vec2 n = crack.normal(k);
      // Pressure opens the crack: +n into the field above, -n into the field
      // below. With the in-situ stress as reference the faces also give up
      // the in-situ traction sigma0 n that the uncut body carried across them.
      // A part being released (update_releases) takes only its loaded share.
      Vec2 t = Vec2::Zero();
      if (pressure) t += crack.face_pressure(k) * n;
      if (with_in_situ) t += traction(in_situ_stress(crack.plane()[k]), n);
      const Vec2 force = (crack.tributary_length(k) - unloaded_length(c, k)) * t;
      if (force.squaredNorm() == 0) continue;
      for (int side : {1, -1}) spread_face_force(crack, k, side, side * force);
    }
  }
}

// The work the in-situ shear traction on the faces has done over the step
// (in_situ_reference): the faces carry sigma0 n (crack_loads), whose part
// along the crack does work on the faces' slip. That is elastic energy of the
// in-situ state the crack releases (frictionless faces under in-situ shear
// slide at once), which the energy check must count as a source.
void Solver::record_faces() {
  if (!config_.in_situ_reference) return;
  faces_before_.resize(cracks_.size());
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    const Crack& crack = cracks_[c];
    auto& before = faces_before_[c];
    before.resize(crack.size());
    for (std::size_t k = 0; k < crack.size(); ++k) before[k] = crack.surface(1)[k] - crack.surface(-1)[k];
  }
}

void Solver::account_in_situ_shear_work() {
  if (!config_.in_situ_reference || faces_before_.size() != cracks_.size()) return;
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    const Crack& crack = cracks_[c];
    if (faces_before_[c].size() != crack.size()) continue;
    for (std::size_t k = 0; k < crack.size(); ++k) {
      const Vec2 n = crack.normal(k);
      const Vec2 t = traction(in_situ_stress(crack.plane()[k]), n);
      const Vec2 shear = t - t.dot(n) * n;
      const Vec2 moved = crack.surface(1)[k] - crack.surface(-1)[k] - faces_before_[c][k];
      in_situ_shear_work_ += (crack.tributary_length(k) - unloaded_length(c, k)) * shear.dot(moved);
    }
  }
}

Solver::FaceResponse Solver::face_response(std::size_t c) const {
  if (!step_begun_) throw std::logic_error("Solver::face_response needs begin_step() first");
  const Crack& crack = cracks_.at(c);
  const std::size_t count = crack.size();
  const NodalFields* fields[2] = {&field0_, &field1_};
  const double alpha = config_.damping.grid_alpha + feedback_alpha_;
  auto key = [](int node, int field) { return static_cast<std::size_t>(node) * 2 + static_cast<std::size_t>(field); };
  auto tip = [&](std::size_t k) { return (k == 0 && crack.start_is_tip()) || (k + 1 == count && crack.end_is_tip()); };
  // Per node field: the acceleration a unit face pressure at crack particle
  // j gives it (as crack_loads spreads the load), for every j that loads it.
  std::unordered_map<std::size_t, std::vector<std::pair<std::size_t, Vec2>>> loaded;
  for (std::size_t j = 0; j < count; ++j) {
    const Vec2 force = (crack.tributary_length(j) - unloaded_length(c, j)) * crack.normal(j);
    for (int side : {1, -1}) {
      const FaceShares s = face_shares(crack, j, side);
      for (int i = 0; i < s.count; ++i) {
        const auto u = static_cast<std::size_t>(s.node[i]);
        const NodalFields& nd = *fields[s.field[i]];
        Vec2 a = side * s.share[i] * force / nd.mass[u];
        if (nd.fixed[u] & 1) a.x() = 0;
        if (nd.fixed[u] & 2) a.y() = 0;
        loaded[key(s.node[i], s.field[i])].push_back({j, a});
      }
    }
  }
  // The plane (the mean of the surfaces) moves under the face pressure too
  // wherever the two sides' nodes differ in mass (a kink's corner, beside a
  // tip): the pressure the faces carry now, as the fluid's next pressure is
  // not known here. Without it the plane's predicted step missed by up to
  // 2.6e-5 m at an inclined notch's corners and tips, 100 times the step
  // itself, and the fluid, which moves its nodes by this prediction, took the
  // error as MPa of interface mismatch.
  std::unordered_map<std::size_t, Vec2> pressure_acceleration;
  for (const auto& [node_key, loads] : loaded) {
    Vec2 a = Vec2::Zero();
    for (const auto& [j, per_pa] : loads) a += crack.face_pressure(j) * per_pa;
    pressure_acceleration[node_key] = a;
  }
  FaceResponse out;
  out.rate.assign(count, 0.0);
  out.acceleration.assign(count, 0.0);
  out.plane_rate.assign(count, Vec2::Zero());
  out.plane_acceleration.assign(count, Vec2::Zero());
  // Each surface moves with the mass-weighted velocity of its side's nodes
  // (move_crack_surfaces); collect its weights first, then the band.
  struct Read {
    std::size_t key;
    double weight;  // signed: + above, - below
  };
  std::vector<std::vector<Read>> reads(count);
  const auto* drift = surface_drift(c);  // the surfaces' drift toward the material this step, if any
  for (std::size_t k = 0; k < count; ++k) {
    const Vec2 n = crack.opening_normal(k);  // the opening is read along it (Crack::width)
    double side_mass[2] = {0, 0};
    Vec2 side_v[2] = {Vec2::Zero(), Vec2::Zero()}, side_a[2] = {Vec2::Zero(), Vec2::Zero()};
    Vec2 side_pressure_a[2] = {Vec2::Zero(), Vec2::Zero()};
    for (int s = 0; s < 2; ++s) {
      const int side = s == 0 ? 1 : -1;
      double mass = 0;
      Vec2 v_sum = Vec2::Zero(), a_sum = Vec2::Zero(), pressure_a_sum = Vec2::Zero();
      std::vector<Read> mine;
      for_side_nodes(*this, config_.grid, fields, crack, k, side, min_mass_, [&](int nd, int f, double w) {
        const auto u = static_cast<std::size_t>(nd);
        const NodalFields& field = *fields[f];
        const double m = field.mass[u];
        Vec2 v = field.momentum[u] / m, a = (field.force[u] - alpha * field.momentum[u]) / m;
        if (field.fixed[u] & 1) v.x() = a.x() = 0;
        if (field.fixed[u] & 2) v.y() = a.y() = 0;
        mass += w * m;
        v_sum += w * m * v;
        a_sum += w * m * a;
        if (const auto it = pressure_acceleration.find(key(nd, f)); it != pressure_acceleration.end())
          pressure_a_sum += w * m * it->second;
        mine.push_back({key(nd, f), w * m});
      });
      if (!(mass > 0)) continue;
      side_mass[s] = mass;
      side_v[s] = v_sum / mass;
      side_a[s] = a_sum / mass;
      side_pressure_a[s] = pressure_a_sum / mass;
      if (tip(k)) continue;  // both surfaces of a tip move together: no opening
      out.rate[k] += side * v_sum.dot(n) / mass;
      if (drift) out.rate[k] += side * (*drift)[k][static_cast<std::size_t>(s)].dot(n);  // anchor_crack_surfaces
      out.acceleration[k] += side * a_sum.dot(n) / mass;
      for (auto& r : mine) reads[k].push_back({r.key, side * r.weight / mass});
    }
    // The plane is the mean of the surfaces (Crack::update_plane); a tip's
    // surfaces move with their joint momentum (move_crack_surfaces).
    if (tip(k)) {
      const double m = side_mass[0] + side_mass[1];
      if (m > 0) {
        out.plane_rate[k] = (side_mass[0] * side_v[0] + side_mass[1] * side_v[1]) / m;
        out.plane_acceleration[k] =
            (side_mass[0] * (side_a[0] + side_pressure_a[0]) + side_mass[1] * (side_a[1] + side_pressure_a[1])) / m;
      }
    } else {
      out.plane_rate[k] = 0.5 * (side_v[0] + side_v[1]);
      out.plane_acceleration[k] = 0.5 * (side_a[0] + side_pressure_a[0] + side_a[1] + side_pressure_a[1]);
    }
  }
  // The band: C_kj = d(opening acceleration at k) / d(pressure at j).
  std::size_t band = 0;
  std::vector<std::vector<std::pair<std::size_t, double>>> rows(count);
  for (std::size_t k = 0; k < count; ++k) {
    const Vec2 n = crack.opening_normal(k);  // the opening is read along it (Crack::width)
    for (const auto& r : reads[k]) {
      const auto it = loaded.find(r.key);
      if (it == loaded.end()) continue;
      for (const auto& [j, a] : it->second) {
        rows[k].push_back({j, r.weight * a.dot(n)});
        band = std::max(band, j > k ? j - k : k - j);
      }
    }
  }
  out.band = band;
  const std::size_t width = 2 * band + 1;
  out.compliance.assign(count * width, 0.0);
  for (std::size_t k = 0; k < count; ++k) {
    for (const auto& [j, value] : rows[k]) out.compliance[k * width + (j + band - k)] += value;
  }
  return out;
}

// Implicit face stiffness. The face pressure p - s (w - w_ref) is a spring
// of stiffness s (Pa/m) across the crack; near a fluid-filled tip s ~ K / w
// is far stiffer than the solid, and applied explicitly it is unstable for
// dt above about sqrt(rho h w / K) (the fluid's stiffness against the mass of
// the face nodes), which for K = 1e7 Pa, w = 0.1 mm is 50x below the solid's
// own step. So the change of the pressure over this step, -s dw with
// dw = dt (v_above - v_below) . n at the new velocities, is taken
// implicitly, node by node (backward Euler for the spring, row-sum lumped):
// at a node with one field above and one below the crack, with
// k = sum over crack particles of (lumped weight x tributary length x s),
//   r_new = r / (1 + dt^2 k (1/m_above + 1/m_below)),  r = (v_above - v_below) . n,
// by equal and opposite impulses (momentum conserved). The explicit part
// (crack_loads) uses the current width, so over the steps the faces carry
// the fluid's pressure at their actual width; only the approach to it is
// damped where the spring is stiff.
// A fixed component of node u's field f stays fixed after a velocity change.
void Solver::keep_fixed(std::size_t u, int f) {
  const std::uint8_t fixed = (f ? field1_ : field0_).fixed[u];
  if (fixed & 1) velocity_[f][u].x() = acceleration_[f][u].x() = 0;
  if (fixed & 2) velocity_[f][u].y() = acceleration_[f][u].y() = 0;
}

void Solver::implicit_face_stiffness(double dt) {
  const NodalFields* fields[2] = {&field0_, &field1_};
  struct FaceNode {
    int node = -1;
    int field[2] = {-1, -1};  // [0] above, [1] below
    double k[2] = {0, 0};     // N/m per m of width change
    Vec2 normal = Vec2::Zero();
    bool conflict = false;
  };
  std::vector<FaceNode> faces;
  if (face_slot_.size() != field0_.mass.size()) face_slot_.assign(field0_.mass.size(), -1);
  for (std::size_t ci = 0; ci < cracks_.size(); ++ci) {
    const Crack& crack = cracks_[ci];
    for (std::size_t k = 0; k < crack.size(); ++k) {
      const double s = crack.pressure_stiffness()[k];
      if (s <= 0 || crack.face_pressure(k) <= 0) continue;
      const double weight = s * (crack.tributary_length(k) - unloaded_length(ci, k));
      const Vec2 n = crack.opening_normal(k);  // the width's own normal (Crack::width)
      for (int side : {1, -1}) {
        const int slot = side > 0 ? 0 : 1;
        const FaceShares shares = face_shares(crack, k, side);
        for (int c = 0; c < shares.count; ++c) {
          const int nd = shares.node[c], f = shares.field[c];
          const double w = shares.share[c];
          int& slot_of_node = face_slot_[static_cast<std::size_t>(nd)];
          if (slot_of_node < 0) {
            slot_of_node = static_cast<int>(faces.size());
            faces.push_back({});
            faces.back().node = nd;
          }
          FaceNode* it = &faces[static_cast<std::size_t>(slot_of_node)];
          if (it->field[slot] >= 0 && it->field[slot] != f) it->conflict = true;
          it->field[slot] = f;
          it->k[slot] += w * weight;
          if (side > 0) it->normal += w * weight * n;
        }
      }
    }
  }
  for (const auto& e : faces) face_slot_[static_cast<std::size_t>(e.node)] = -1;
  for (const auto& e : faces) {
    const int fa = e.field[0], fb = e.field[1];
    if (e.conflict || fa < 0 || fb < 0 || fa == fb || e.normal.squaredNorm() == 0) continue;
    const auto u = static_cast<std::size_t>(e.node);
    const double ma = fields[fa]->mass[u], mb = fields[fb]->mass[u];
    const Vec2 n = e.normal.normalized();
    const double a = dt * dt * 0.5 * (e.k[0] + e.k[1]);
    const double inverse_mass = 1 / ma + 1 / mb;
    const double r = (velocity_[fa][u] - velocity_[fb][u]).dot(n);
    const double impulse = (r / (1 + a * inverse_mass) - r) / inverse_mass;  // on the field above, along n
    velocity_[fa][u] += impulse / ma * n;
    velocity_[fb][u] -= impulse / mb * n;
    acceleration_[fa][u] += impulse / (ma * dt) * n;
    acceleration_[fb][u] -= impulse / (mb * dt) * n;
    keep_fixed(u, fa);
    keep_fixed(u, fb);
  }
}

// Contact (Nairn 2003, section 2.3): where a node has both fields, the crack
// surfaces there are in contact if the displacement-based opening along the
// crack normal is not positive (to 1e-6 h) AND they approach; then the normal components of
// the two fields' velocities are made equal, conserving momentum, and their
// tangential ones as far as the crack's Coulomb friction allows.
void Solver::contact(double dt) {
  const auto& g = config_.grid;
  const double contact_tolerance = 1e-6 * g.h;
  for (int n : active_) {
    const auto u = static_cast<std::size_t>(n);
    const double m0 = field0_.mass[u], m1 = field1_.mass[u];
    if (m0 <= min_mass_ || m1 <= min_mass_) continue;
    // Normal from the nearest crack particle; the side of the node from the
    // nearer of its two segments, with the same exact predicate and the same
    // convention (on the line counts as left, i.e. above) as the side tests
    // that filled the fields. (A tolerance-free distance test would flip with
    // round-off when the node lies on the crack.)
    const Vec2 x = g.position(n);
    double best = std::numeric_limits<double>::infinity();
    std::size_t nearest_c = 0, nearest_k = 0;
    for (std::size_t c = 0; c < cracks_.size(); ++c) {
      for (std::size_t k = 0; k < cracks_[c].size(); ++k) {
        const double d = (cracks_[c].plane()[k] - x).squaredNorm();
        if (d < best) {
          best = d;
          nearest_c = c;
          nearest_k = k;
        }
      }
    }
    const Crack* nearest = &cracks_[nearest_c];
    const auto& pl = nearest->plane();
    auto distance_to = [&](std::size_t a) {
      const Vec2 ab = pl[a + 1] - pl[a];
      const double t = std::clamp((x - pl[a]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      return (pl[a] + t * ab - x).squaredNorm();
    };
    std::size_t seg = nearest_k + 1 < pl.size() ? nearest_k : nearest_k - 1;
    if (nearest_k > 0 && nearest_k + 1 < pl.size() && distance_to(nearest_k - 1) < distance_to(nearest_k)) {
      seg = nearest_k - 1;
    }
    const Vec2 normal = nearest->normal(nearest_k);
    // Field 0 holds the node's own side; above if the node is left of the crack.
    const bool field0_above = orient2d(pl[seg], pl[seg + 1], x) >= 0;
    const Vec2 n_up = field0_above ? normal : Vec2(-normal);  // from field 1 towards field 0
    const Vec2 p0 = dt > 0 ? Vec2(m0 * velocity_[0][u]) : field0_.momentum[u];
    const Vec2 p1 = dt > 0 ? Vec2(m1 * velocity_[1][u]) : field1_.momentum[u];
    // Opening = (u_field0 - u_field1) . n_up; approach = (v_field0 - v_field1) . n_up < 0.
    const double opening = (field0_.displaced[u] / m0 - field1_.displaced[u] / m1).dot(n_up);
    const double approach = (p0 / m0 - p1 / m1).dot(n_up);
    // Touching counts as contact: a crack closed by an in-situ stress has
    // zero opening from the first step, and round-off (1e-16 m) must not
    // switch its contact off (the faces would overlap, then chatter). The
    // 1e-6 h tolerance is far below any opening of interest.
    if (!(opening <= contact_tolerance && approach < 0)) continue;
    // The momentum to field 0 that would give both fields one velocity; its
    // normal part (> 0: they approach) is the contact's, and of its
    // tangential part Coulomb friction takes at most friction x that normal
    // impulse (Nairn 2003, section 2.3): stick below, slide at the limit.
    const Vec2 stick = (m0 * p1 - m1 * p0) / (m0 + m1);
    const double normal_impulse = stick.dot(n_up);
    Vec2 dp = normal_impulse * n_up;
    if (const double mu = nearest->friction(); mu > 0) {
      const Vec2 slide = stick - dp;
      const double limit = mu * normal_impulse, magnitude = slide.norm();
      dp += magnitude <= limit ? slide : Vec2((limit / magnitude) * slide);
    }
    // The faces' contact traction for J and K (Crack::contact_traction): the
    // impulse on the face above, shared by the two crack particles of the
    // nearer segment by where the node projects onto it. Only the step's own
    // contact (dt > 0): the one on the extrapolated momenta corrects what the
    // transfer left, not a load (counted, it made the faces' contact carry
    // 15% more than the in-situ load that pressed them together).
    if (dt > 0) {
      const Vec2 ab = pl[seg + 1] - pl[seg];
      const double along = std::clamp((x - pl[seg]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      const Vec2 on_above = field0_above ? dp : Vec2(-dp);
      cracks_[nearest_c].add_contact_impulse(seg, (1 - along) * on_above);
      cracks_[nearest_c].add_contact_impulse(seg + 1, along * on_above);
    }
    if (dt > 0) {
      velocity_[0][u] += dp / m0;
      velocity_[1][u] -= dp / m1;
      acceleration_[0][u] += dp / (m0 * dt);
      acceleration_[1][u] -= dp / (m1 * dt);
      keep_fixed(u, 0);
      keep_fixed(u, 1);
    } else {
      field0_.momentum[u] += dp;
      field1_.momentum[u] -= dp;
    }
    ++contacts_;
  }
}

}  // namespace hfmpm::solid::mpm
