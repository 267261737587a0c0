// Crack growth (CRAMP; docs/solid.md, "Growth"): which tips grow at a check
// (the energy criterion, the settling wait, the zero-lag wait for the
// fluid), where to (maximum hoop stress or straight) and how the crack's
// particles follow; and the feedback damping's update. The J and K that
// decide it come from fracture.cpp.
#include <algorithm>
#include <cmath>
#include <limits>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {
namespace {

constexpr double kForever = std::numeric_limits<double>::infinity();
// Shortest spacing of crack particles that growth creates, in cells: the
// opening the grid gives the faces is linear within a cell, so at most two
// independent openings per cell (docs/solid.md, "Growth").
constexpr double kMinSegmentCells = 0.5;
// A turning tip's growth step lengthens its short tip segment as a straight
// one does when the old tip stays within this many cells of the lengthened
// segment: the crack then moves by less than the grid resolves.
constexpr double kMergeOffsetCells = 0.01;
// A kinking tip grows only where its K's carry between this share of J and
// its inverse: kKShare J <= (K_I^2 + K_II^2) / E' <= J / kKShare
// (growth_direction_known below).
constexpr double kKShare = 0.1;

// Whether growth is driven by Irwin's (K_I^2 + K_II^2) / E' rather than J:
// where the crack bends by more than kIrwinBend within a one-material J
// domain (J's domain form then misses the kink corner's face term).
bool irwin_energy(const TipResult& tip) {
  return tip.bend > kIrwinBend && tip.one_material && tip.k1 * tip.k1 + tip.k2 * tip.k2 > 0;
}

}  // namespace

// The energy release rate that can drive growth: J without the part of a
// negative K_I, G = J (max(K_I, 0)^2 + K_II^2) / (K_I^2 + K_II^2). A crack
// closed in compression (faces in contact, K_I < 0 from the residual
// interpenetration) has no mode-I singularity, but J, a quadratic, counts
// it: in a confined body (in-situ stress 1e5 Pa, J_Ic 1e-3 J/m^2) the closed
// dry tip ahead of a fluid-filled notch then grew although it was shut.
double growth_energy(const TipResult& tip, bool mode_one_only) {
  const double k1 = std::max(0.0, tip.k1), sum = tip.k1 * tip.k1 + tip.k2 * tip.k2;
  const double driving = k1 * k1 + (mode_one_only ? 0.0 : tip.k2 * tip.k2);
  const double g = irwin_energy(tip) ? sum / tip.modulus : tip.j;
  return sum > 0 ? g * driving / sum : g;
}

// Whether a tip's K's can set its direction: they must carry the energy J
// says the tip releases, within a factor 1 / kKShare either way. Where the
// field about the tip is a crack-tip field the two agree: over the growth
// steps of the layered sweep (CI size, 1e-4 to 1e-2 Pa s, both starts, 200
// steps) the share (K_I^2 + K_II^2) / (E' J) was 0.16-4.5 (the K's from the
// interaction integral and J from the domain integral, each with its
// discretisation error). Five steps lay outside: four at 4e-4 to 0.03 (J of
// 5-14 J/m^2 with K's a hundredth of sqrt(J E'): the tip shut, K_I about 0,
// while the crack behind it opened) and one at 51; their "direction" turned
// the crack by 14 to 71 degrees. The stiff 1e-4 Pa s start hooked into a curl
// at 0.98 s, its tip stalled against itself and the fluid's solve struggled
// there to the end (213 Newton iterations per step). The K's then say nothing
// of where the crack goes: such a tip waits, as it waits for the fluid, until
// they do. A straight tip needs no direction and does not wait. Behind a kink
// sharper than kIrwinBend in one material the K's are the energy growth uses
// (growth_energy) and J is the one known to miss a term: nothing to check.
bool growth_direction_known(const TipResult& tip) {
  if (irwin_energy(tip)) return true;
  const double carried = (tip.k1 * tip.k1 + tip.k2 * tip.k2) / tip.modulus;
  return carried >= kKShare * tip.j && carried * kKShare <= tip.j;
}

int Solver::propagate() {
  last_tips_ = tips();
  const double h = config_.grid.h;
  int added = 0;
  std::vector<std::array<Vec2, 2>> cut;  // the new segments, old tip to new
  if (grown_at_.size() != cracks_.size()) grown_at_.resize(cracks_.size(), {-kForever, -kForever});
  if (front_arrived_at_.size() != cracks_.size()) front_arrived_at_.resize(cracks_.size(), {-kForever, -kForever});
  if (releases_.size() != cracks_.size()) releases_.resize(cracks_.size());
  // Each crack's length before this check grows any tip: the settling wait of
  // its second tip must not count the growth of its first in the same check
  // (it did, and the two tips of a point-symmetric crack grew at alternate
  // checks).
  std::vector<double> lengths;
  for (const auto& crack : cracks_) lengths.push_back(arc_length(crack.plane()).back());
  if (overloaded_since_.size() != cracks_.size()) overloaded_since_.resize(cracks_.size(), {kForever, kForever});
  for (const auto& tip : last_tips_) {
    const bool straight = config_.fracture.straight;
    double& grown_at = grown_at_[tip.crack][tip.at_end ? 1 : 0];
    // Watch for a tip that carries far more than its toughness and does not
    // grow (watch_overload below); a growth this check resets it.
    double& overloaded_since = overloaded_since_[tip.crack][tip.at_end ? 1 : 0];
    const double energy = growth_energy(tip, straight);
    if (energy >= kOverload * tip.toughness && energy > 0) {
      overloaded_since = std::min(overloaded_since, t_);
    } else {
      overloaded_since = kForever;
    }
    if (config_.fracture.settle_transits > 0 && grown_at > -kForever) {
      const double length = lengths[tip.crack];
      const double c_s = std::sqrt(shear_[tip.material] / density_[tip.material]);
      if (t_ - grown_at < config_.fracture.settle_transits * length / c_s) continue;  // still settling
    }
    // A start tip waits for the fluid only when the fluid enters inside the
    // crack (a wellbore, Crack::has_inlet): at a mouth crack the start is no tip.
    const auto& wet = cracks_[tip.crack];
    if ((tip.at_end || wet.has_inlet()) && config_.fracture.max_lag_cells >= 0 && wet.wetted_length() >= 0) {
      // The front need not enter the tip segment (its faces close to nothing at
      // the tip): the allowed lag is at least that segment.
      const auto& plane = wet.plane();
      const std::vector<double> arc = arc_length(plane);
      const double dry = tip.at_end ? arc.back() - wet.wetted_length() : wet.wetted_start();
      // At most half a cell of it: straight growth lengthens the tip segment
      // (Crack::move_tip), and an allowance that grew with it let the tip run
      // two growth steps ahead of the fluid within a few steps, which threw
      // the implicit interface solve off (a 1.8 GPa mismatch for a step and a
      // 30 kPa dip of the inlet pressure in a built lab KGD).
      const double last = tip.at_end ? arc.back() - arc[arc.size() - 2] : arc[1];
      const double segment = std::min(last, kMinSegmentCells * h);
      const double allowed = std::max(config_.fracture.max_lag_cells * h, segment);
      double& arrived_at = front_arrived_at_[tip.crack][tip.at_end ? 1 : 0];
      if (dry > allowed * (1 + 1e-9)) {  // wait for the fluid (zero-lag closure)
        arrived_at = -kForever;
        continue;
      }
      // The front has come within reach: the fluid's pressure behind it (below
      // the confining stress near a front) loads the faces near the tip at
      // once, and the body needs a few shear-wave transits of the J domain to
      // follow; K's read before that set a direction from a field that is not
      // the one the load makes (docs/solid.md, "Growth"). A straight tip's
      // direction does not depend on them: it does not wait.
      if (arrived_at == -kForever) arrived_at = t_;
      const double c_s = std::sqrt(shear_[tip.material] / density_[tip.material]);
      const double domain = config_.fracture.outer_cells * h;
      if (!straight && t_ - arrived_at < config_.fracture.front_settle_transits * domain / c_s) continue;
    }
    // Energy must be released, not only reach the toughness: with a toughness
    // of 0 (a material that holds no crack) an unloaded tip's J of 0 would.
    const double released = growth_energy(tip, straight);
    if (!(released >= tip.toughness && released > 0)) continue;
    if (!straight && !growth_direction_known(tip)) continue;  // its K's do not carry J: no direction yet
    const double kink = straight ? 0.0 : tip.kink;
    const double c = std::cos(kink), s = std::sin(kink);
    const Vec2 d(c * tip.direction.x() - s * tip.direction.y(), s * tip.direction.x() + c * tip.direction.y());
    const Vec2 next = tip.position + config_.fracture.growth_cells * h * d;
    // Stop a cell short of the body's edge: the crack has run through (the
    // side reports it and the run stops, boundary_reached()).
    if ((next.array() < (body_lo_.array() + h)).any() || (next.array() > (body_hi_.array() - h)).any()) {
      if (!boundary_reached_) boundary_reached_ = BoundaryHit{tip.crack, tip.at_end, tip.position, t_};
      continue;
    }
    // The new particle's reference position (Crack::reference): the tip's,
    // plus the step less the mean displacement gradient of the particles
    // within a cell of it.
    const Vec2 mid = 0.5 * (tip.position + next);
    Eigen::Matrix2d gradient = Eigen::Matrix2d::Zero();
    double count = 0;
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      if ((particles_.x[p] - mid).squaredNorm() >= h * h) continue;
      gradient += particles_.grad_u[p];
      count += 1;
    }
    if (count > 0) gradient /= count;
    auto& crack = cracks_[tip.crack];
    const Vec2& tip_reference = tip.at_end ? crack.reference().back() : crack.reference().front();
    const Vec2 reference = tip_reference + (Eigen::Matrix2d::Identity() - gradient) * (next - tip.position);
    // Straight growth (mode I by symmetry, along the crack's own direction)
    // lengthens a tip segment shorter than kMinSegmentCells instead of adding
    // a new one, while the result stays within half a growth step of
    // kMinSegmentCells (the plane's own motion makes segment lengths inexact):
    // the faces' opening is linear within a cell, so crack particles closer
    // than half a cell give the fluid pressure nodes whose differences the
    // solid cannot resist (docs/solid.md, "Crack particles at least half a
    // cell apart"). The moved tip particle stands for the material point at
    // its new place, so its reference position moves with it by the same
    // estimate a new particle there would get.
    // A turning tip does the same when the old tip lies within
    // kMergeOffsetCells of the lengthened segment (it turns by less than the
    // grid resolves; sixteenth-cell particles of a turning field well made
    // the fluid's Newton steps stall).
    const auto& plane = crack.plane();
    const std::size_t n = plane.size();
    const Vec2& before = tip.at_end ? plane[n - 2] : plane[1];
    const Vec2& last = tip.at_end ? plane[n - 1] : plane[0];
    const double length = (last - before).norm();
    const double grown = length + config_.fracture.growth_cells * h;
    const Vec2 chord = next - before;
    const Vec2 off = last - before;
    const double offset = std::abs(chord.x() * off.y() - chord.y() * off.x()) / chord.norm();
    // ... and the step carries the segment on past the old tip (a step that
    // turns back along its own segment would shorten it).
    const bool ahead = chord.dot(off) >= length * (length + 0.5 * config_.fracture.growth_cells * h);
    const bool in_line = straight || (offset <= kMergeOffsetCells * h && ahead);
    if (in_line && grown <= (kMinSegmentCells + 0.5 * config_.fracture.growth_cells) * h) {
      crack.move_tip(tip.at_end, next, reference);
    } else if (tip.at_end) {
      crack.append(next, reference);
    } else {
      crack.prepend(next, reference);
    }
    cut.push_back({tip.position, next});
    if (config_.fracture.release_transits > 0) {
      // The new part's face load is applied over release_transits x L / c_s,
      // L the crack's length before the step (Solver::update_releases).
      const double c_s = std::sqrt(shear_[tip.material] / density_[tip.material]);
      releases_[tip.crack][tip.at_end ? 1 : 0] = {t_, config_.fracture.release_transits * lengths[tip.crack] / c_s,
                                                  config_.fracture.growth_cells * h};
    }
    grown_at = t_;
    overloaded_since = kForever;
    front_arrived_at_[tip.crack][tip.at_end ? 1 : 0] = -kForever;
    ++added;
  }
  if (!cut.empty() && config_.fracture.reproject_grown) {
    for (auto& crack : cracks_) crack.prepare(3 * h, 1e-6 * h);
    reproject_strains(cut);
  }
  return added;
}

std::optional<Solver::Overload> Solver::longest_overload() const {
  std::optional<Overload> worst;
  for (const auto& tip : last_tips_) {
    if (tip.crack >= overloaded_since_.size()) continue;
    const double since = overloaded_since_[tip.crack][tip.at_end ? 1 : 0];
    if (since == kForever) continue;
    const double energy = growth_energy(tip, config_.fracture.straight);
    const Overload o{tip.crack, tip.at_end, t_ - since,
                     tip.toughness > 0 ? std::sqrt(energy / tip.toughness) : kForever};
    if (!worst || o.duration > worst->duration) worst = o;
  }
  return worst;
}

// Feedback (Nose-Hoover) damping: d alpha / dt = (2 KE - 2 KE_target) / (M q).
void Solver::update_feedback(double dt) {
  const double ke = kinetic_energy();
  const auto& d = config_.damping;
  feedback_alpha_ += dt * 2 * (ke - d.feedback_target_ke) / (total_mass_ * d.feedback_q);
  feedback_alpha_ = std::max(0.0, feedback_alpha_);
}

}  // namespace hfmpm::solid::mpm
