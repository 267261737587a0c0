// Testing a fluid side: the fake solid that publishes a straight crack with an
// elliptic opening (closed at the tip) that grows by one or two particles every
// third exchange, and checks that each FluidState names exactly the ids of the
// CrackState the fluid had (in order), with finite pressures >= 0; and the growth check.
#include <cmath>
#include <numbers>

#include "checks.hpp"
#include "hfmpm/exchange.hpp"
#include "hfmpm/proto/convert.hpp"

namespace hfmpm::conformance {
namespace {

class FakeSolid final : public FakePeer {
 public:
  // The scene's prescribed crack if it has one, else 0.2 m from the origin along x, every 0.01 m, 1 mm open.
  explicit FakeSolid(const scene::Scene& scene)
      : gauss_seidel_(scene.coupling().scheme() == scene::Coupling::GAUSS_SEIDEL) {
    if (scene.solid().has_prescribed_crack()) {
      const auto& p = scene.solid().prescribed_crack();
      mouth_ = Vec2(p.mouth_x_m(), p.mouth_y_m());
      const double angle = p.angle_deg() * std::numbers::pi / 180.0;
      direction_ = Vec2(std::cos(angle), std::sin(angle));
      const double segments = std::max(1.0, std::round(p.initial_length_m() / p.spacing_m()));
      spacing_ = p.initial_length_m() / segments;
      count_ = static_cast<std::size_t>(segments) + 1;
      opening_ = proto::to_time_function(p.mouth_opening_m());
    }
  }

  protocol::DataFrame make(std::uint64_t step, double t) override {
    std::size_t added = 0;
    if (step > 0 && ++exchanges_ % 3 == 0 && count_ < 2000) added = growth_ % 2 == 0 ? 1 : 2;
    count_ += added;
    if (added > 0) ++growth_;
    CrackGeometry g;
    g.crack_id = 0;
    g.grew = added > 0;
    const double length = spacing_ * static_cast<double>(count_ - 1);
    const double w_mouth = std::max(0.0, opening_(t));
    for (std::size_t i = 0; i < count_; ++i) {
      const double s = spacing_ * static_cast<double>(i);
      const double r = s / length;
      g.ids.push_back(i);
      g.position.push_back(mouth_ + s * direction_);
      g.normal.emplace_back(-direction_.y(), direction_.x());
      g.width.push_back(i + 1 == count_ ? 0.0 : w_mouth * std::sqrt(std::max(0.0, 1.0 - r * r)));
      g.tip.push_back(i + 1 == count_ ? 1 : 0);
    }
    sent_.emplace_back(step, g.ids);
    protocol::DataFrame frame;
    frame.set_step(step);
    frame.set_t(t);
    proto::to_proto(g, frame.mutable_crack()->add_cracks());
    return frame;
  }

  void check(const protocol::DataFrame& frame) override {
    const std::string where = "FluidState of step " + std::to_string(frame.step());
    const auto& state = frame.fluid();
    if (state.cracks_size() != 1 || state.cracks(0).crack_id() != 0) {
      fail(where + " has " + std::to_string(state.cracks_size()) +
           " cracks; the conformance solid publishes one crack, id 0, and the fluid answers for it");
    }
    CrackPressure p;
    try {
      p = proto::from_proto(state.cracks(0));
    } catch (const proto::ProtocolError& e) {
      fail(where + ": " + e.what());
    }
    const auto& [crack_step, ids] = crack_seen(frame.step());
    if (p.ids != ids) {
      std::size_t i = 0;
      while (i < p.ids.size() && i < ids.size() && p.ids[i] == ids[i]) ++i;
      fail(where + ": " + std::to_string(p.ids.size()) + " ids, differing at index " + std::to_string(i) +
           " from the " + std::to_string(ids.size()) + " ids of the CrackState of step " + std::to_string(crack_step) +
           ", the last one the fluid had; pressures follow the crack's ids, in order");
    }
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.pressure[i] < 0) {
        fail(where + ": pressure[" + std::to_string(i) + "] = " + fmt(p.pressure[i]) + " Pa; pressures are >= 0");
      }
    }
    if (p.front_position < 0 || p.fluid_volume < 0) {
      fail(where + ": front_position " + fmt(p.front_position) + " m, fluid_volume " + fmt(p.fluid_volume) +
           " m^2; both are >= 0");
    }
    ++frames_;
  }

  // Finite; pressure, volumes and the front >= 0, the front no farther than the crack is long.
  void check_diagnostics(const protocol::Diagnostics& d, const std::string& where) const override {
    for (double v : {d.inlet_pressure(), d.injected_volume(), d.fluid_volume(), d.front_position()}) {
      if (!(std::isfinite(v) && v >= 0)) {
        fail(where + ": inlet_pressure, injected_volume, fluid_volume and front_position are finite and >= 0; got " +
             fmt(d.inlet_pressure()) + ", " + fmt(d.injected_volume()) + ", " + fmt(d.fluid_volume()) + ", " +
             fmt(d.front_position()));
      }
    }
    const double length = spacing_ * static_cast<double>(count_ - 1);  // the longest it has been
    if (d.front_position() > length * (1 + 1e-9)) {
      fail(where + ": diagnostics.front_position = " + fmt(d.front_position()) + " m is beyond the tip of the " +
           fmt(length) + " m crack");
    }
  }

  std::size_t frames_checked() const override { return frames_; }

  // The CrackState the fluid had when it published its frame of `step`: of the same step at
  // step 0 and under Gauss-Seidel, of the exchange before under Jacobi (the fluid publishes first).
  const std::pair<std::uint64_t, std::vector<std::uint64_t>>& crack_seen(std::uint64_t step) const {
    const bool same = step == 0 || gauss_seidel_;
    for (auto it = sent_.rbegin(); it != sent_.rend(); ++it) {
      if (same ? it->first == step : it->first < step) return *it;
    }
    fail("a FluidState for step " + std::to_string(step) + " before the fluid can have had a CrackState for it");
  }
  std::size_t growth_events() const override { return growth_; }

 private:
  Vec2 mouth_ = Vec2::Zero();                            // m
  Vec2 direction_ = Vec2(1, 0);                          // mouth -> tip
  double spacing_ = 0.01;                                // m
  std::size_t count_ = 21;                               // crack particles
  TimeFunction opening_ = TimeFunction::constant(1e-3);  // m, width at the mouth
  std::size_t exchanges_ = 0, growth_ = 0, frames_ = 0;
  bool gauss_seidel_ = false;
  std::vector<std::pair<std::uint64_t, std::vector<std::uint64_t>>> sent_;  // step, ids of each CrackState sent
};

// The fake solid grows every third exchange; the fluid's ids must follow each time.
std::string check_fluid_growth(Context& context) {
  Session s(context);
  s.start();
  const std::uint32_t n = 10 * s.exchange_interval();
  while (s.peer().growth_events() < 6) s.run_command(n);
  s.run_command(n);  // the fluid has answered for the newest ids too
  return "the fluid followed " + std::to_string(s.peer().growth_events()) + " growth events over " +
         std::to_string(s.step()) + " steps: FluidState ids = the last CrackState's ids each time";
}

}  // namespace

std::unique_ptr<FakePeer> make_fake_solid(const scene::Scene& scene) { return std::make_unique<FakeSolid>(scene); }

Check fluid_growth_check() {
  return {"growth", "the crack grows by 1 or 2 particles every 3rd exchange; FluidState ids follow, in order",
          check_fluid_growth};
}

}  // namespace hfmpm::conformance
