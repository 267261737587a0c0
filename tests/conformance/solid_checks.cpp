// Testing a solid side: the fake fluid that checks every CrackState (arrays,
// unit normals, widths, the tip, ids only added at a tip, `grew` exactly when they
// were) and answers with a FluidState for the same ids; and the growth check.
#include <algorithm>
#include <cmath>
#include <map>

#include "checks.hpp"
#include "hfmpm/exchange.hpp"
#include "hfmpm/proto/convert.hpp"

namespace hfmpm::conformance {
namespace {

// Trapezoidal integral of v over the arc lengths s (N/m for a pressure).
double trapezoid(const std::vector<double>& s, const std::vector<double>& v) {
  double sum = 0;
  for (std::size_t i = 1; i < s.size(); ++i) sum += 0.5 * (v[i - 1] + v[i]) * (s[i] - s[i - 1]);
  return sum;
}

class FakeFluid final : public FakePeer {
 public:
  explicit FakeFluid(const scene::Scene& scene)
      : inlet_(scene.fluid().has_prescribed_pressure()
                   ? proto::to_time_function(scene.fluid().prescribed_pressure().inlet_pressure_pa())
                   : TimeFunction::constant(1e5)) {}

  void check(const protocol::DataFrame& frame) override {
    const std::string step = "CrackState of step " + std::to_string(frame.step());
    if (frame.crack().cracks_size() == 0) fail(step + " has no crack");
    std::map<std::uint32_t, std::vector<std::uint64_t>> ids;
    std::vector<CrackGeometry> cracks;
    bool grew = false;
    for (const auto& c : frame.crack().cracks()) {
      CrackGeometry g;
      try {
        g = proto::from_proto(c);
      } catch (const proto::ProtocolError& e) {
        fail(step + ": " + e.what());
      }
      const std::string where = step + ", crack " + std::to_string(g.crack_id);
      if (ids.count(g.crack_id)) fail(where + ": the crack id appears twice");
      check_tips(g, where);
      if (const auto old = known_.find(g.crack_id); old != known_.end()) grew |= check_growth(g, old->second, where);
      ids[g.crack_id] = g.ids;
      cracks.push_back(std::move(g));
    }
    known_ = std::move(ids);
    latest_ = std::move(cracks);
    ++frames_;
    if (grew) ++growth_;
  }

  // A FluidState for the ids of the CrackState just received: the inlet pressure
  // of the scene's fluid (1e5 Pa without one) behind the tip, 0 at tips.
  protocol::DataFrame make(std::uint64_t step, double t) override {
    protocol::DataFrame frame;
    frame.set_step(step);
    frame.set_t(t);
    auto* state = frame.mutable_fluid();
    const double p = std::max(0.0, inlet_(t));
    double load = 0;
    for (const auto& g : latest_) {
      CrackPressure c;
      c.crack_id = g.crack_id;
      c.ids = g.ids;
      const auto arc = arc_length(g.position);
      for (std::size_t i = 0; i < g.size(); ++i) c.pressure.push_back(g.tip[i] ? 0.0 : p);
      c.front_position = arc.size() >= 2 ? arc[arc.size() - 2] : 0.0;
      load += trapezoid(arc, c.pressure);
      proto::to_proto(c, state->add_cracks());
    }
    sent_load_ = load;
    sent_scale_ = p * (latest_.empty() ? 0.0 : arc_length(latest_.front().position).back());
    return frame;
  }

  // crack_particles counts the particles of the last CrackState, crack_length and mouth_opening
  // are those of its (first) crack, crack_face_load integrates the pressures it last received.
  void check_diagnostics(const protocol::Diagnostics& d, const std::string& where) const override {
    for (double v : {d.kinetic_energy(), d.crack_length(), d.mouth_opening(), d.crack_face_load()}) {
      if (!std::isfinite(v)) fail(where + ": a diagnostic of the solid is not finite");
    }
    std::size_t particles = 0;
    for (const auto& g : latest_) particles += g.size();
    if (d.crack_particles() != particles) {
      fail(where + ": diagnostics.crack_particles = " + std::to_string(d.crack_particles()) + " but the last " +
           "CrackState has " + std::to_string(particles) + " crack particles");
    }
    if (latest_.empty()) return;
    const auto& g = latest_.front();
    const double length = arc_length(g.position).back();
    if (std::abs(d.crack_length() - length) > 1e-6 * length) {
      fail(where + ": diagnostics.crack_length = " + fmt(d.crack_length()) + " m but crack " +
           std::to_string(g.crack_id) + " measures " + fmt(length) + " m from the mouth to the tip");
    }
    if (std::abs(d.mouth_opening() - g.width.front()) > 1e-9 * std::abs(g.width.front()) + 1e-15) {
      fail(where + ": diagnostics.mouth_opening = " + fmt(d.mouth_opening()) + " m but width[0] of the last " +
           "CrackState is " + fmt(g.width.front()) + " m");
    }
    if (std::abs(d.crack_face_load() - sent_load_) > 1e-6 * sent_scale_ + 1e-12) {
      fail(where + ": diagnostics.crack_face_load = " + fmt(d.crack_face_load()) + " N/m but the pressures the " +
           "solid last received integrate to " + fmt(sent_load_) + " N/m along the crack");
    }
  }

  std::size_t frames_checked() const override { return frames_; }
  std::size_t growth_events() const override { return growth_; }

 private:
  // Arrays run from the mouth to the tip: the last particle is a tip, and a crack is closed at its tips.
  static void check_tips(const CrackGeometry& g, const std::string& where) {
    if (!g.tip.back()) {
      fail(where + ": the last particle (id " + std::to_string(g.ids.back()) +
           ") is not flagged tip; arrays run from the mouth to the tip");
    }
    const double widest = *std::max_element(g.width.begin(), g.width.end());
    for (std::size_t i = 0; i < g.size(); ++i) {
      if (g.tip[i] && g.width[i] > 1e-9 * widest) {
        fail(where + ": tip particle " + std::to_string(i) + " (id " + std::to_string(g.ids[i]) + ") has width " +
             fmt(g.width[i]) + " m; a crack is closed at its tip (a new particle starts with width 0)");
      }
    }
  }

  // Old ids stay a contiguous run in the same order: new ones are appended at
  // the end, or prepended at a start that is a tip (an interior crack);
  // `grew` is true exactly when ids were added (the protocol's rule,
  // hfmpm::check_crack_update).
  static bool check_growth(const CrackGeometry& g, const std::vector<std::uint64_t>& old, const std::string& where) {
    const bool start_tip = !g.tip.empty() && g.tip.front() != 0;
    std::size_t prepended = 0, appended = 0;
    try {
      appended = check_crack_update(g.crack_id, old, g.ids, &g.grew, start_tip ? &prepended : nullptr);
    } catch (const std::invalid_argument& e) {
      fail(where + ": " + e.what());
    }
    return appended + prepended > 0;
  }

  TimeFunction inlet_;
  std::map<std::uint32_t, std::vector<std::uint64_t>> known_;
  std::vector<CrackGeometry> latest_;
  double sent_load_ = 0;   // N/m, integral of the pressures last sent
  double sent_scale_ = 0;  // N/m, pressure x crack length, for the tolerance
  std::size_t frames_ = 0, growth_ = 0;
};

// Runs until the crack has grown in 3 frames (the scene must make it grow).
std::string check_solid_growth(Context& context) {
  Session s(context);
  s.start();
  const std::uint32_t n = 50 * s.exchange_interval();
  const auto start = Clock::now();
  while (s.peer().growth_events() < 3) {
    if (s.step() >= 20000 || Clock::now() - start > std::chrono::seconds(30)) {
      fail("the crack grew in " + std::to_string(s.peer().growth_events()) + " frames over " +
           std::to_string(s.step()) + " steps (t = " + fmt(s.t()) +
           " s); this check needs a scene whose crack grows (e.g. prescribed_crack.growth_speed_m_per_s > 0)");
    }
    s.run_command(n);
  }
  return "the crack grew in " + std::to_string(s.peer().growth_events()) + " frames over " + std::to_string(s.step()) +
         " steps (t = " + fmt(s.t()) + " s): ids appended only, grew set exactly then, tips closed";
}

}  // namespace

std::unique_ptr<FakePeer> make_fake_fluid(const scene::Scene& scene) { return std::make_unique<FakeFluid>(scene); }

Check solid_growth_check() {
  return {"growth", "crack growth: old ids stay a prefix, grew exactly when ids were appended, the tip closed",
          check_solid_growth};
}

}  // namespace hfmpm::conformance
