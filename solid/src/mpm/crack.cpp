#include "hfmpm/solid/mpm/crack.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hfmpm/solid/mpm/predicates.hpp"

namespace hfmpm::solid::mpm {
namespace {

Vec2 left_normal(const Vec2& a, const Vec2& b) {
  const Vec2 d = (b - a).normalized();
  return {-d.y(), d.x()};
}

// The mean of the left normals of point k's segments on the polyline x.
Vec2 mean_normal(const std::vector<Vec2>& x, std::size_t k) {
  Vec2 n = Vec2::Zero();
  if (k > 0) n += left_normal(x[k - 1], x[k]);
  if (k + 1 < x.size()) n += left_normal(x[k], x[k + 1]);
  return n.normalized();
}

}  // namespace

Crack::Crack(std::uint32_t id, const CrackSpec& spec)
    : id_(id), start_is_tip_(spec.start_is_tip), end_is_tip_(spec.end_is_tip), friction_(spec.friction) {
  if (spec.points.size() < 2) throw std::invalid_argument("a crack needs at least 2 points");
  if (!(spec.friction >= 0) || !std::isfinite(spec.friction)) {
    throw std::invalid_argument("a crack's friction coefficient must be finite and >= 0; got " +
                                std::to_string(spec.friction));
  }
  for (const auto& p : spec.points) append(p);
  if (spec.inlet >= 0) {
    if (!start_is_tip_ || !end_is_tip_ || spec.inlet == 0 || static_cast<std::size_t>(spec.inlet) + 1 >= size()) {
      throw std::invalid_argument("a crack's inlet must be an inner particle (1 to " + std::to_string(size() - 2) +
                                  ") of a crack whose two ends are tips; got " + std::to_string(spec.inlet));
    }
    has_inlet_ = true;
    inlet_id_ = ids_[static_cast<std::size_t>(spec.inlet)];
  }
}

std::size_t Crack::inlet_index() const {
  if (!has_inlet_) return 0;
  return static_cast<std::size_t>(std::find(ids_.begin(), ids_.end(), inlet_id_) - ids_.begin());
}

void Crack::append(const Vec2& position) { append(position, position); }

void Crack::append(const Vec2& position, const Vec2& reference) {
  ids_.push_back(next_id_++);
  plane_.push_back(position);
  reference_.push_back(reference);
  above_.push_back(position);
  below_.push_back(position);
  pressure_.push_back(0.0);
  stiffness_.push_back(0.0);
  reference_width_.push_back(0.0);
  contact_.push_back(Vec2::Zero());
}

void Crack::prepend(const Vec2& position) { prepend(position, position); }

void Crack::prepend(const Vec2& position, const Vec2& reference) {
  append(position, reference);  // then move the new last particle to the front
  auto to_front = [](auto& v) { std::rotate(v.rbegin(), v.rbegin() + 1, v.rend()); };
  to_front(ids_);
  to_front(plane_);
  to_front(reference_);
  to_front(above_);
  to_front(below_);
  to_front(pressure_);
  to_front(stiffness_);
  to_front(reference_width_);
  to_front(contact_);
  shift_wetted((plane_[1] - plane_[0]).norm());  // arc lengths count from the new first particle
}

void Crack::shift_wetted(double by) {
  if (wetted_length_ < 0) return;
  wetted_start_ += by;
  wetted_length_ += by;
}

void Crack::move_tip(bool at_end, const Vec2& position, const Vec2& reference) {
  const std::size_t k = at_end ? plane_.size() - 1 : 0;
  const double before = (plane_[1] - plane_[0]).norm();
  plane_[k] = above_[k] = below_[k] = position;
  if (!at_end) shift_wetted((plane_[1] - plane_[0]).norm() - before);
  reference_[k] = reference;
}

Vec2 Crack::normal(std::size_t k) const { return mean_normal(plane_, k); }

Vec2 Crack::opening_normal(std::size_t k) const { return mean_normal(reference_, k); }

double Crack::tributary_length(std::size_t k) const {
  double l = 0;
  if (k > 0) l += 0.5 * (plane_[k] - plane_[k - 1]).norm();
  if (k + 1 < plane_.size()) l += 0.5 * (plane_[k + 1] - plane_[k]).norm();
  return l;
}

void Crack::clear_contact() { std::fill(contact_.begin(), contact_.end(), Vec2::Zero()); }

void Crack::finish_contact(double dt) {
  for (std::size_t k = 0; k < size(); ++k) {
    const double length = tributary_length(k);
    contact_[k] = dt > 0 && length > 0 ? Vec2(contact_[k] / (dt * length)) : Vec2::Zero();
  }
}

double Crack::width(std::size_t k) const { return std::max(0.0, (above_[k] - below_[k]).dot(opening_normal(k))); }

void Crack::receive_pressure(const std::vector<double>& pressure, const std::vector<double>& stiffness,
                             const std::vector<double>& width, std::size_t offset) {
  const bool stiff = !stiffness.empty() && stiffness.size() == pressure.size() && width.size() == pressure.size();
  for (std::size_t k = 0; k < size(); ++k) {
    const bool given = k >= offset && k - offset < pressure.size();
    const std::size_t i = given ? k - offset : 0;
    pressure_[k] = given ? pressure[i] : 0.0;
    stiffness_[k] = given && stiff ? stiffness[i] : 0.0;
    reference_width_[k] = given && stiff ? width[i] : 0.0;
  }
}

double Crack::face_pressure(std::size_t k) const {
  const double p = pressure_[k], s = stiffness_[k];
  if (s == 0 || p == 0) return p;
  return std::max(0.0, p - s * (width(k) - reference_width_[k]));
}

void Crack::prepare(double extension, double tip_tolerance) {
  tip_tolerance_ = tip_tolerance;
  path_.clear();
  const std::size_t n = plane_.size();
  if (!start_is_tip_) path_.push_back(plane_[0] - extension * (plane_[1] - plane_[0]).normalized());
  path_.insert(path_.end(), plane_.begin(), plane_.end());
  if (!end_is_tip_) path_.push_back(plane_[n - 1] + extension * (plane_[n - 1] - plane_[n - 2]).normalized());
  lo_ = hi_ = path_.front();
  for (const auto& p : path_) {
    lo_ = lo_.cwiseMin(p);
    hi_ = hi_.cwiseMax(p);
  }
}

bool Crack::crosses(const Vec2& p, const Vec2& q) const {
  const Vec2 lo = p.cwiseMin(q), hi = p.cwiseMax(q);
  bool odd = false;
  for (std::size_t s = 0; s + 1 < path_.size(); ++s) {
    const Vec2& a = path_[s];
    const Vec2& b = path_[s + 1];
    // Cheap rejection by bounding boxes before the exact test.
    if (std::max(a.x(), b.x()) < lo.x() || std::min(a.x(), b.x()) > hi.x() || std::max(a.y(), b.y()) < lo.y() ||
        std::min(a.y(), b.y()) > hi.y()) {
      continue;
    }
    // A particle-node line through a tip point itself passes the crack's end:
    // not a crossing (the material is whole at the tip, and a node at the tip
    // keeps one field). "Through" means within tip_tolerance_ (a millionth of
    // a cell) of the tip, so that a tip sitting on a node, as it does when a
    // crack runs along a grid line, does not connect and cut that node from
    // one step to the next as round-off moves the tip by 1e-16 m.
    auto through = [&](const Vec2& tip) {
      const Vec2 d = q - p;
      const double t = std::clamp((tip - p).dot(d) / d.squaredNorm(), 0.0, 1.0);
      return (p + t * d - tip).squaredNorm() <= tip_tolerance_ * tip_tolerance_;
    };
    const bool tip_a = s == 0 && start_is_tip_, tip_b = s + 2 == path_.size() && end_is_tip_;
    if ((tip_a && through(a)) || (tip_b && through(b)) || !segments_cross(p, q, a, b)) continue;
    odd = !odd;
  }
  return odd;
}

void Crack::update_plane() {
  for (std::size_t k = 0; k < plane_.size(); ++k) plane_[k] = 0.5 * (above_[k] + below_[k]);
}

}  // namespace hfmpm::solid::mpm
