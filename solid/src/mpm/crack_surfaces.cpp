// Where the crack surfaces are: read from the material (anchor_crack_surfaces,
// with surfaces_from_material) and moved by their own side's field
// (move_crack_surfaces).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "hfmpm/solid/mpm/solver.hpp"
#include "side_nodes.hpp"

namespace hfmpm::solid::mpm {

using detail::for_side_nodes;

// The crack surfaces at the start of a step, read from the material: at each
// crack particle the opening is the jump of the displacement across the
// crack, u_above - u_below, each side's displacement the mass-weighted mean
// of its field at the nodes around the surface point (the same nodes and
// weights as the velocity update), taken to the nodes with the particles'
// own gradients (affine_displacement). The displacement is since the start,
// when the body was whole where the crack is now, so the jump is the whole
// opening. The plane does not move: the fields and the contact test of this
// step were sorted against it. The first call sets the surfaces about the
// plane with that opening; later calls set a drift velocity toward it
// (Fracture::surface_relax_transits), which move_crack_surfaces adds to the
// fields' velocities over the step and face_response reports, so the
// response still predicts the step exactly.
//
// Why not only the velocities: a surface made at a growing tip integrates its
// side's velocity from the moment it is made, and while the nodes around it
// still hold one field for both sides (the crack has not yet cut their lines
// to the particles beyond) both surfaces move alike and the opening the
// material makes then is never read. A crack grown under load read 0.65-0.82
// of the opening of a crack cut at that length, in proportion to the load it
// grew under, while the material beside it opened 0.86-0.96 (the edge-crack
// comparison, docs/verification.md "The grown crack"); read from the
// material, 0.96-1.00. The particles' displacement carries what a surface
// missed, which is read as soon as its fields part.
void Solver::anchor_crack_surfaces() {
  const auto& g = config_.grid;
  const NodalFields* fields[2] = {&field0_, &field1_};
  affine_displacement();
  // The relaxation is a drift velocity the surfaces add to their fields'
  // over the coming step (move_crack_surfaces), and face_response reports it
  // with the faces' opening rate, so the fluid's implicit solve sees it
  // coming. Over the last step's length dt it closes the fraction
  // 1 - exp(-dt / tau) of the gap: (target - surface) (1 - exp(-dt / tau)) / dt.
  // The first anchoring, and tau = 0, set the surfaces outright.
  const double elapsed = anchored_at_ >= 0 ? t_ - anchored_at_ : -1;
  anchored_at_ = t_;
  surface_drift_.resize(cracks_.size());
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    auto& crack = cracks_[c];
    const double tau = config_.fracture.surface_relax_transits * crack_transit(c);
    const bool drift = elapsed > 0 && tau > 0;
    const double rate = drift ? -std::expm1(-elapsed / tau) / elapsed : 0.0;  // 1/s
    const std::size_t count = crack.size();
    auto& velocity = surface_drift_[c];
    velocity.assign(count, {Vec2::Zero(), Vec2::Zero()});
    for (std::size_t k = 0; k < count; ++k) {
      if ((k == 0 && crack.start_is_tip()) || (k + 1 == count && crack.end_is_tip())) {
        crack.surface(1)[k] = crack.surface(-1)[k] = crack.plane()[k];  // the faces meet at a tip
        continue;
      }
      Vec2 u[2] = {Vec2::Zero(), Vec2::Zero()};
      double mass[2] = {0, 0};
      for (int s = 0; s < 2; ++s) {
        for_side_nodes(*this, g, fields, crack, k, s == 0 ? 1 : -1, min_mass_, [&](int nd, int f, double w) {
          const auto n = static_cast<std::size_t>(nd);
          mass[s] += w * fields[f]->mass[n];
          u[s] += w * affine_[static_cast<std::size_t>(f)][n];
        });
      }
      if (!(mass[0] > 0 && mass[1] > 0)) continue;  // a side with no material here: as it was
      const Vec2 half_jump = 0.5 * (u[0] / mass[0] - u[1] / mass[1]);
      if (drift) {
        velocity[k][0] = rate * (crack.plane()[k] + half_jump - crack.surface(1)[k]);
        velocity[k][1] = rate * (crack.plane()[k] - half_jump - crack.surface(-1)[k]);
      } else {
        crack.surface(1)[k] = crack.plane()[k] + half_jump;
        crack.surface(-1)[k] = crack.plane()[k] - half_jump;
      }
    }
  }
}

const std::vector<std::array<Vec2, 2>>* Solver::surface_drift(std::size_t c) const {
  return c < surface_drift_.size() && surface_drift_[c].size() == cracks_[c].size() ? &surface_drift_[c] : nullptr;
}

double Solver::crack_transit(std::size_t c) const {
  const Crack& crack = cracks_[c];
  double slowest = std::numeric_limits<double>::infinity();
  for (int end = 0; end < 2; ++end) {
    if (!(end == 0 ? crack.start_is_tip() : crack.end_is_tip())) continue;
    const std::size_t m = material_at(end == 0 ? crack.plane().front() : crack.plane().back());
    slowest = std::min(slowest, std::sqrt(shear_[m] / density_[m]));
  }
  if (!std::isfinite(slowest)) {  // no tip: the slowest material
    for (std::size_t m = 0; m < shear_.size(); ++m) slowest = std::min(slowest, std::sqrt(shear_[m] / density_[m]));
  }
  return arc_length(crack.plane()).back() / slowest;
}

void Solver::move_crack_surfaces(double dt) {
  const auto& g = config_.grid;
  const NodalFields* fields[2] = {&field0_, &field1_};
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    auto& crack = cracks_[c];
    const std::size_t count = crack.size();
    std::vector<Vec2> momentum[2];
    std::vector<double> mass[2];
    for (int s = 0; s < 2; ++s) {
      const int side = s == 0 ? 1 : -1;
      momentum[s].assign(count, Vec2::Zero());
      mass[s].assign(count, 0.0);
      for (std::size_t k = 0; k < count; ++k) {
        // Mass-weighted velocity of the side's own field.
        for_side_nodes(*this, g, fields, crack, k, side, min_mass_, [&](int nd, int f, double w) {
          const double m = fields[f]->mass[static_cast<std::size_t>(nd)];
          mass[s][k] += w * m;
          momentum[s][k] += w * m * velocity_[f][static_cast<std::size_t>(nd)];
        });
      }
    }
    // The faces meet at a tip: both surfaces of a tip particle move together.
    auto close_tip = [&](std::size_t k) {
      const double m = mass[0][k] + mass[1][k];
      const Vec2 p = momentum[0][k] + momentum[1][k];
      for (int s = 0; s < 2; ++s) {
        momentum[s][k] = p;
        mass[s][k] = m;
      }
    };
    if (crack.start_is_tip()) close_tip(0);
    if (crack.end_is_tip()) close_tip(count - 1);
    // With surfaces from the material: the drift toward the material's
    // opening that anchor_crack_surfaces set for this step.
    const auto* drift = surface_drift(c);
    for (int s = 0; s < 2; ++s) {
      auto& surface = crack.surface(s == 0 ? 1 : -1);
      for (std::size_t k = 0; k < count; ++k) {
        if (mass[s][k] > 0) surface[k] += dt * momentum[s][k] / mass[s][k];
        if (drift) surface[k] += dt * (*drift)[k][static_cast<std::size_t>(s)];
      }
    }
    crack.update_plane();
  }
}

}  // namespace hfmpm::solid::mpm
