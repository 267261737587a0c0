// An explicit crack (CRAMP; Nairn 2003, "Material point method calculations
// with explicit cracks", CMES 4(6); Guo and Nairn 2004): a chain of massless
// crack particles joined by segments. Each particle has a position on the
// crack plane and two surface positions, above and below. "Above" is the
// left of the direction from the first particle to the last.
#pragma once

#include <cstdint>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::solid::mpm {

struct CrackSpec {
  std::vector<Vec2> points;   // initial crack particles, in order; at least 2
  bool start_is_tip = false;  // false: the first particle is a mouth on the body's edge
  bool end_is_tip = true;
  // Index into `points` of the particle where a fluid enters an interior
  // crack (a wellbore inside the body), or -1: the first particle, a mouth.
  // An inner particle of a crack whose two ends are tips.
  std::ptrdiff_t inlet = -1;
  // Coulomb friction between the faces where they touch (contact): the
  // tangential traction is at most friction x the normal compression. 0:
  // frictionless. A friction of the faces, so it holds at any orientation of
  // the crack to the grid (Solver::contact).
  double friction = 0;
};

class Crack {
 public:
  Crack(std::uint32_t id, const CrackSpec& spec);

  std::uint32_t id() const { return id_; }
  std::size_t size() const { return plane_.size(); }
  const std::vector<Vec2>& plane() const { return plane_; }
  // Where each crack particle's plane point was in the reference state (the
  // start): plane() less the faces' mean displacement. The crack's initial
  // points are their own; a grown particle's is estimated when it is added.
  const std::vector<Vec2>& reference() const { return reference_; }
  const std::vector<Vec2>& surface(int side) const { return side > 0 ? above_ : below_; }
  std::vector<Vec2>& surface(int side) { return side > 0 ? above_ : below_; }
  const std::vector<std::uint64_t>& ids() const { return ids_; }
  // The fluid's pressure as received (Pa), with its stiffness -dp/dw (Pa/m,
  // 0: none given) and the widths it was computed from (m).
  std::vector<double>& pressure() { return pressure_; }
  const std::vector<double>& pressure() const { return pressure_; }
  const std::vector<double>& pressure_stiffness() const { return stiffness_; }
  // Take a new fluid pressure; see Solver::set_crack_pressure.
  void receive_pressure(const std::vector<double>& pressure, const std::vector<double>& stiffness,
                        const std::vector<double>& width, std::size_t offset = 0);
  // Pa, the pressure on the faces at the current width w:
  // max(0, p - stiffness (w - reference width)).
  double face_pressure(std::size_t k) const;
  // Pa, the traction the faces' contact (and friction) put on the face above
  // at each crack particle over the last step (0 where open): what the J and
  // K face terms add to the face load where the faces touch (Solver::contact).
  const std::vector<Vec2>& contact_traction() const { return contact_; }
  // During a step: the contact's impulses on the face above, summed per crack
  // particle (N s / m), then finish_contact turns them into tractions.
  void clear_contact();
  void add_contact_impulse(std::size_t k, const Vec2& impulse) { contact_[k] += impulse; }
  void finish_contact(double dt);
  // Arc length from the first particle that the fluid has wetted (its front,
  // m), or negative when no fluid reports one; and where the wetted part
  // begins (0 at a mouth; the start-side front of a fluid entering at an
  // interior inlet).
  double wetted_length() const { return wetted_length_; }
  double wetted_start() const { return wetted_start_; }
  void set_wetted(double start, double end) {
    wetted_start_ = start;
    wetted_length_ = end;
  }
  // Moves the wetted part's arc lengths by `by` (m; the start grew), if known.
  void shift_wetted(double by);
  // The particle a fluid enters at (CrackSpec::inlet), by id; has_inlet()
  // false: the first particle.
  bool has_inlet() const { return has_inlet_; }
  std::uint64_t inlet_id() const { return inlet_id_; }
  // Its index now (the crack may have grown at its start), or 0 without one.
  std::size_t inlet_index() const;
  bool start_is_tip() const { return start_is_tip_; }
  double friction() const { return friction_; }
  bool end_is_tip() const { return end_is_tip_; }

  // Unit normal at particle k: the mean of the left normals of its segments.
  Vec2 normal(std::size_t k) const;
  // The same normal in the reference state (of reference()): the direction
  // the opening is read along. The current normal turns with the plane, and
  // at a kink, where the faces' jump holds the slip of the segment before,
  // that turn alone changed the opening read along it by up to 1.6e-7 m a
  // step (an inclined notch's corner), which no face response predicts and a
  // water-filled crack turns into MPa of interface mismatch. In the small
  // strains of this solid the reference normal is the normal of the strain
  // measure; along a straight crack the two agree.
  Vec2 opening_normal(std::size_t k) const;
  // Length the particle stands for: half the distance to each neighbour.
  double tributary_length(std::size_t k) const;
  // Opening (x_above - x_below) . opening_normal, never negative.
  double width(std::size_t k) const;

  // Before each step: segment bounding boxes; `extension` is how far a mouth
  // (non-tip) end is extended beyond the body for the side tests; a
  // particle-node line passing within `tip_tolerance` of a tip does not cross.
  void prepare(double extension, double tip_tolerance);
  // Parity of crossings of the segment p-q with the crack (extended at mouths).
  bool crosses(const Vec2& p, const Vec2& q) const;
  // Axis-aligned box around the crack (with extensions), grown by `margin`.
  // (Inline: P2G asks it for every particle.)
  bool near(const Vec2& p, double margin) const {
    return p.x() >= lo_.x() - margin && p.x() <= hi_.x() + margin && p.y() >= lo_.y() - margin &&
           p.y() <= hi_.y() + margin;
  }

  // Crack plane = midpoint of the surfaces (after the surfaces moved).
  void update_plane();

  // Appends a crack particle at the end (growth); it starts closed. Without
  // a reference position: the position (a crack of the initial state).
  void append(const Vec2& position);
  void append(const Vec2& position, const Vec2& reference);
  // Inserts a crack particle before the first (growth of a start tip, of a
  // crack inside the body); it starts closed.
  void prepend(const Vec2& position);
  void prepend(const Vec2& position, const Vec2& reference);
  // Moves the tip particle (the last one, or the first with at_end false) to
  // `position` (growth that lengthens the tip segment instead of adding one),
  // with its reference position (that of the material point now at the tip);
  // it stays closed.
  void move_tip(bool at_end, const Vec2& position, const Vec2& reference);

  // Checkpoints: every member but the id and the tip flags (which the scene fixes); load()
  // restores this crack bit for bit (solid/src/mpm/checkpoint.cpp).
  void save(StateWriter& out) const;
  void load(const StateReader& in);

 private:
  std::uint32_t id_;
  bool start_is_tip_, end_is_tip_;
  double friction_;
  std::vector<std::uint64_t> ids_;
  std::vector<Vec2> plane_, above_, below_, reference_;
  std::vector<double> pressure_;                     // Pa, on the faces, per crack particle
  std::vector<double> stiffness_, reference_width_;  // Pa/m and m, per crack particle
  std::vector<Vec2> contact_;                        // Pa, the contact's traction on the face above
  double wetted_length_ = -1, wetted_start_ = 0;
  bool has_inlet_ = false;
  std::uint64_t inlet_id_ = 0;
  std::uint64_t next_id_ = 0;
  // Side-test geometry: the plane polyline with extended mouth ends.
  std::vector<Vec2> path_;
  Vec2 lo_ = Vec2::Zero(), hi_ = Vec2::Zero();
  double tip_tolerance_ = 0;
};

}  // namespace hfmpm::solid::mpm
