// Fracture mechanics at the crack tips: J-integral, stress intensity factors,
// growth direction and propagation.
//
// J is evaluated as an equivalent domain integral (Shih, Moran and Nakamura
// 1986, Eng. Fract. Mech. 25; the area form of the contour integral a few
// cells out). In the tip frame (x1 along the crack, out of it; x2 to its left),
// with a weight q that is 1 near the tip and 0 on the domain's outer edge,
//   J = sum_p V_p (sigma_ij du_i/dx1 - W delta_1j) dq/dx_j
//       - integral over the faces q (p n + sigma0 n) . d[u]/dx1 ds,
// where [u] = u_above - u_below is the displacement jump across the crack and
// n the normal towards the upper face. The second line is the work of the
// loads on the crack faces inside the domain, which the area integral alone
// does not see (DESIGN section 2: "J_tip = J - traction work", with the
// traction work on the faces entering with its sign).
// Fields are increments from the initial (in-situ) state: displacement
// gradient grad_u, stress C : sym(grad_u), W = sigma : eps / 2. By
// superposition the in-situ stress sigma0 then acts as a face load
// sigma0 n on the faces, and J is the energy release rate of the prestressed
// body. Each particle carries its own side's field, so the domain needs no
// special treatment where the crack crosses it. The domain must lie in one
// material and inside the body (a free edge crossing it would add W n1).
//
// Mode split by the crack opening behind the tip (DESIGN section 2): in plane
// strain [u_2] = 8 K_I sqrt(r / 2 pi) / E' and [u_1] = 8 K_II sqrt(r / 2 pi) / E',
// so K_II / K_I = [u_1] / [u_2], and J = (K_I^2 + K_II^2) / E'.
// Growth direction by maximum hoop stress (Erdogan and Sih 1963):
//   theta = 2 atan((K_I - sqrt(K_I^2 + 8 K_II^2)) / (4 K_II)).
#include <algorithm>
#include <cmath>
#include <limits>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {
namespace {

// 1D plateau: 1 for r <= ri, linear to 0 at ro; value and d/dr.
struct Ramp {
  double f = 0, df = 0;
};

Ramp ramp(double r, double ri, double ro) {
  if (r <= ri) return {1, 0};
  if (r >= ro) return {0, 0};
  return {(ro - r) / (ro - ri), -1 / (ro - ri)};
}

// Weight q of the square domain around the tip and its gradient, in the tip frame.
struct DomainWeight {
  double q = 0, dq1 = 0, dq2 = 0;
};

DomainWeight domain_weight(double x1, double x2, double ri, double ro) {
  const Ramp a = ramp(std::abs(x1), ri, ro);
  const Ramp b = ramp(std::abs(x2), ri, ro);
  return {a.f * b.f, a.df * (x1 < 0 ? -1 : 1) * b.f, a.f * b.df * (x2 < 0 ? -1 : 1)};
}

}  // namespace

int Solver::region_at(const Vec2& x) const {
  int found = -1;
  for (std::size_t r = 0; r < config_.regions.size(); ++r) {
    if (config_.regions[r].contains(x)) found = static_cast<int>(r);  // later regions win
  }
  return found;
}

std::vector<TipResult> Solver::tips() const {
  std::vector<TipResult> out;
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    if (cracks_[c].start_is_tip()) out.push_back(evaluate_tip(c, false));
    if (cracks_[c].end_is_tip()) out.push_back(evaluate_tip(c, true));
  }
  return out;
}

TipResult Solver::evaluate_tip(std::size_t c, bool at_end) const {
  const Crack& crack = cracks_[c];
  const std::size_t n = crack.size();
  // Particles in order from the far end to the tip.
  auto at = [&](std::size_t i) { return at_end ? i : n - 1 - i; };
  const int up = at_end ? 1 : -1;  // the surface on the tip frame's +x2 side
  TipResult tip;
  tip.crack = c;
  tip.at_end = at_end;
  tip.position = crack.plane()[at(n - 1)];
  const Vec2 e1 = (tip.position - crack.plane()[at(n - 2)]).normalized();
  const Vec2 e2(-e1.y(), e1.x());
  tip.direction = e1;
  const double h = config_.grid.h;
  const double ri = config_.fracture.inner_cells * h, ro = config_.fracture.outer_cells * h;

  Eigen::Matrix2d rot;  // rows e1, e2: global -> tip frame
  rot.row(0) = e1.transpose();
  rot.row(1) = e2.transpose();

  // Area integral over the particles in the domain.
  double j_area = 0;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const Vec2 d = particles_.x[p] - tip.position;
    if (std::abs(d.x()) >= ro * 1.5 || std::abs(d.y()) >= ro * 1.5) continue;  // cheap reject (any rotation)
    const double x1 = d.dot(e1), x2 = d.dot(e2);
    const auto w = domain_weight(x1, x2, ri, ro);
    if (w.dq1 == 0 && w.dq2 == 0) continue;
    const Eigen::Matrix2d g = rot * particles_.grad_u[p] * rot.transpose();  // du_i/dx_j in the tip frame
    const auto m = static_cast<std::size_t>(particles_.material[p]);
    const double e11 = g(0, 0), e22 = g(1, 1), e12 = 0.5 * (g(0, 1) + g(1, 0));
    const double tr = e11 + e22;
    const double s11 = lambda_[m] * tr + 2 * shear_[m] * e11;
    const double s22 = lambda_[m] * tr + 2 * shear_[m] * e22;
    const double s12 = 2 * shear_[m] * e12;
    const double energy = 0.5 * (s11 * e11 + s22 * e22 + 2 * s12 * e12);
    // (sigma_i1 u_i,1 - W) q,1 + sigma_i2 u_i,1 q,2
    j_area += particles_.volume[p] *
              ((s11 * g(0, 0) + s12 * g(1, 0) - energy) * w.dq1 + (s12 * g(0, 0) + s22 * g(1, 0)) * w.dq2);
  }

  // Work of the face loads: -integral q (p n + sigma0 n) . d[u] along the faces.
  auto jump = [&](std::size_t k) -> Vec2 { return crack.surface(up)[k] - crack.surface(-up)[k]; };
  double j_faces = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const std::size_t a = at(i), b = at(i + 1);
    const Vec2 mid = 0.5 * (crack.plane()[a] + crack.plane()[b]);
    const Vec2 d = mid - tip.position;
    const double q = domain_weight(d.dot(e1), d.dot(e2), ri, ro).q;
    if (q == 0) continue;
    const Vec2 t = (crack.plane()[b] - crack.plane()[a]).normalized();
    const Vec2 n_up(-t.y(), t.x());
    Vec2 load = 0.5 * (crack.pressure()[a] + crack.pressure()[b]) * n_up;
    const int region = region_at(mid);
    if (region >= 0) {
      const Voigt& s0 = config_.regions[static_cast<std::size_t>(region)].initial_stress;
      load += Vec2(s0[0] * n_up.x() + s0[2] * n_up.y(), s0[2] * n_up.x() + s0[1] * n_up.y());
    }
    j_faces -= q * load.dot(jump(b) - jump(a));
  }
  tip.j = j_area + j_faces;
  tip.j_faces = j_faces;

  // Material at the tip (the region there, else the nearest particle's).
  const int r = region_at(tip.position);
  std::size_t material = 0;
  if (r >= 0) {
    material = static_cast<std::size_t>(config_.regions[static_cast<std::size_t>(r)].material);
  } else {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      const double dist = (particles_.x[p] - tip.position).squaredNorm();
      if (dist < best) {
        best = dist;
        material = static_cast<std::size_t>(particles_.material[p]);
      }
    }
  }
  tip.modulus = config_.materials[material].plane_strain_modulus();
  tip.toughness = config_.materials[material].toughness;

  // Mode split from the jump at the crack particles in the domain's ramp
  // (inner_cells to outer_cells behind the tip, at least 1 to 2 cells): the
  // jump within a cell of the closed tip is the least accurate part of the
  // crack, and the ratio of the two components is what the split needs.
  double open = 0, slide = 0;
  const double from = std::max(h, ri) - 1e-9 * h, to = std::max(from + h, ro) + 1e-9 * h;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const std::size_t k = at(i);
    const double dist = (crack.plane()[k] - tip.position).norm();
    if (dist < from || dist > to) continue;
    const Vec2 jmp = jump(k);
    open += jmp.dot(e2);
    slide += jmp.dot(e1);
  }
  const double k_total = std::sqrt(std::max(0.0, tip.j) * tip.modulus);
  if (open > 0) {
    const double ratio = slide / open;
    tip.k1 = k_total / std::sqrt(1 + ratio * ratio);
    tip.k2 = ratio * tip.k1;
  } else {
    tip.k2 = slide >= 0 ? k_total : -k_total;
  }
  if (std::abs(tip.k2) > 1e-12 * std::abs(tip.k1)) {
    tip.kink = 2 * std::atan((tip.k1 - std::sqrt(tip.k1 * tip.k1 + 8 * tip.k2 * tip.k2)) / (4 * tip.k2));
  }
  return tip;
}

int Solver::propagate() {
  last_tips_ = tips();
  const double h = config_.grid.h;
  int added = 0;
  for (const auto& tip : last_tips_) {
    if (!(tip.j >= tip.toughness)) continue;
    const double c = std::cos(tip.kink), s = std::sin(tip.kink);
    const Vec2 d(c * tip.direction.x() - s * tip.direction.y(), s * tip.direction.x() + c * tip.direction.y());
    const Vec2 next = tip.position + config_.fracture.growth_cells * h * d;
    // Stop a cell short of the body's edge: the crack has run through.
    if ((next.array() < (body_lo_.array() + h)).any() || (next.array() > (body_hi_.array() - h)).any()) continue;
    auto& crack = cracks_[tip.crack];
    if (tip.at_end) {
      crack.append(next);
    } else {
      crack.prepend(next);
    }
    ++added;
  }
  return added;
}

// Feedback (Nose-Hoover) damping: d alpha / dt = (2 KE - 2 KE_target) / (M q).
void Solver::update_feedback(double dt) {
  const double ke = kinetic_energy();
  const auto& d = config_.damping;
  feedback_alpha_ += dt * 2 * (ke - d.feedback_target_ke) / (total_mass_ * d.feedback_q);
  feedback_alpha_ = std::max(0.0, feedback_alpha_);
}

}  // namespace hfmpm::solid::mpm
