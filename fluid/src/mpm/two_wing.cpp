// A fluid entering a crack at an inner particle: two wings and their
// junction (two_wing.hpp; docs/fluid.md, "Injection from inside the body").
#include "hfmpm/fluid/mpm/two_wing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hfmpm::fluid::mpm {
namespace {

std::size_t inlet_of(const CrackGeometry& crack) {
  const std::string name = "fluid: crack " + std::to_string(crack.crack_id) + ": ";
  if (!crack.has_inlet) throw std::invalid_argument(name + "a two-wing fluid needs the crack's inlet_id");
  const auto at = std::find(crack.ids.begin(), crack.ids.end(), crack.inlet_id);
  if (at == crack.ids.end() || at == crack.ids.begin() || at + 1 == crack.ids.end()) {
    throw std::invalid_argument(name + "inlet_id " + std::to_string(crack.inlet_id) +
                                " is not one of the crack's inner particles");
  }
  return static_cast<std::size_t>(at - crack.ids.begin());
}

}  // namespace

CrackGeometry wing_geometry(const CrackGeometry& whole, std::size_t inlet, bool towards_end,
                            const std::vector<double>& across) {
  const std::size_t n = whole.size();
  if (inlet == 0 || inlet + 1 >= n) throw std::invalid_argument("fluid: a wing's inlet must be an inner particle");
  const std::size_t m = towards_end ? n - inlet : inlet + 1;
  auto global = [&](std::size_t i) { return towards_end ? inlet + i : inlet - i; };
  CrackGeometry g;
  g.crack_id = whole.crack_id;
  g.tip_modulus = towards_end ? whole.tip_modulus : whole.start_tip_modulus;
  g.resolution = whole.resolution;
  const double turn = towards_end ? 1.0 : -1.0;  // "above" is the left of the wing's own direction
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t k = global(i);
    g.ids.push_back(whole.ids[k]);
    g.position.push_back(whole.position[k]);
    g.normal.push_back(turn * whole.normal[k]);
    g.width.push_back(whole.width[k]);
    g.tip.push_back(i == 0 ? char{0} : whole.tip[k]);
  }
  if (whole.opening_rate.empty()) return g;
  const std::size_t B = whole.compliance_band, row = 2 * B + 1;
  const std::size_t Bw = std::min<std::size_t>(B, m - 1), wrow = 2 * Bw + 1;
  auto C = [&](std::size_t k, std::size_t j) { return whole.opening_compliance[k * row + j + B - k]; };
  auto other = [&](std::size_t j) { return towards_end ? j < inlet : j > inlet; };
  g.compliance_band = static_cast<std::uint32_t>(Bw);
  g.opening_compliance.assign(m * wrow, 0.0);
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t k = global(i);
    g.opening_rate.push_back(whole.opening_rate[k]);
    double acceleration = whole.opening_acceleration[k];
    const std::size_t lo = k >= B ? k - B : 0, hi = std::min(n - 1, k + B);
    for (std::size_t j = lo; j <= hi; ++j) {
      if (other(j)) {
        if (!across.empty()) acceleration += C(k, j) * across[j];
        continue;
      }
      const std::size_t l = towards_end ? j - inlet : inlet - j;  // the wing's own column
      if (l + Bw >= i && l <= i + Bw) g.opening_compliance[i * wrow + l + Bw - i] = C(k, j);
    }
    g.opening_acceleration.push_back(acceleration);
    if (!whole.plane_rate.empty()) {
      g.plane_rate.push_back(whole.plane_rate[k]);
      g.plane_acceleration.push_back(whole.plane_acceleration[k]);
    }
  }
  return g;
}

TwoWingFluid::TwoWingFluid(const FluidConfig& config)
    : wings_{FluidSolver(config), FluidSolver(config)},
      before_{wings_},
      flow_rate_(config.inlet.kind == InletConfig::Kind::FlowRate) {
  if (!config.implicit_interface) {
    throw std::invalid_argument(
        "fluid: a fluid entering at an inner crack particle needs the implicit interface step (implicit_interface; "
        "coupling.scheme IMPLICIT): under the explicit step one transfer between the wings per coupled step does "
        "not hold them to one pressure");
  }
}

std::vector<double> TwoWingFluid::join(const std::vector<double>& wing0, const std::vector<double>& wing1) const {
  std::vector<double> out(whole_.size(), 0.0);
  for (std::size_t i = 0; i < wing1.size() && inlet_ + i < out.size(); ++i) out[inlet_ + i] = wing1[i];
  for (std::size_t i = 0; i < wing0.size() && i <= inlet_; ++i) out[inlet_ - i] = wing0[i];
  if (!wing0.empty() && !wing1.empty() && inlet_ < out.size()) out[inlet_] = 0.5 * (wing0[0] + wing1[0]);
  return out;
}

std::vector<double> TwoWingFluid::merged(const std::array<FluidSolver, 2>& wings) const {
  return join(wings[0].nodal_pressure(), wings[1].nodal_pressure());
}

void TwoWingFluid::set_wings(std::array<FluidSolver, 2>& wings, const std::vector<double>& across) const {
  for (std::size_t w = 0; w < 2; ++w) wings[w].set_crack(wing_geometry(whole_, inlet_, w == 1, across));
}

void TwoWingFluid::set_crack(const CrackGeometry& crack) {
  const std::size_t inlet = inlet_of(crack);
  whole_ = crack;
  inlet_ = inlet;
  arc_ = arc_length(crack.position);
  // The pressures across the inlet after the last step, on the new crack
  // (the wings count from the inlet, so growth at either end keeps them in place).
  const std::vector<double> across = wings_[0].grid().empty() ? std::vector<double>{} : merged(wings_);
  before_ = wings_;
  set_wings(wings_, across);
}

void TwoWingFluid::fill(double front, double pressure) {
  if (wings_[0].grid().empty()) throw std::logic_error("fluid: set_crack() must be called before fill()");
  for (auto& w : wings_) w.fill(std::min(front, w.grid().length()), pressure);
  // A later iteration of the first step starts from here: set to the crack
  // already, and set again to the same crack its particles move by round-off only.
  before_ = wings_;
}

int TwoWingFluid::advance(double dt) {
  const bool response = !whole_.opening_rate.empty();  // the faces' response couples the wings across the inlet
  int steps = 0;
  std::array<FluidSolver, 2> trial = wings_;  // set with the loads across from the step before
  std::vector<double> across = merged(before_);
  double x = transfer_, x_prev = 0, r_prev = 0;
  bool have_prev = false;
  for (int it = 1;; ++it) {
    if (it > 1) {
      trial = before_;
      set_wings(trial, across);
    }
    trial[0].set_inlet_split(flow_rate_ ? 0.5 : 1, flow_rate_ ? -x : 0);
    trial[1].set_inlet_split(flow_rate_ ? 0.5 : 1, flow_rate_ ? x : 0);
    for (auto& w : trial) steps += w.advance(dt);
    const double p0 = trial[0].inlet_pressure(), p1 = trial[1].inlet_pressure(), r = p1 - p0;
    const std::vector<double> found = merged(trial);
    double change = 0, largest = std::max(p0, p1);
    for (double p : found) largest = std::max(largest, p);
    if (response) {
      const std::size_t B = whole_.compliance_band;
      const std::size_t lo = inlet_ >= B ? inlet_ - B : 0, hi = std::min(found.size() - 1, inlet_ + B);
      for (std::size_t j = lo; j <= hi; ++j) {
        if (j != inlet_ && j < across.size()) change = std::max(change, std::abs(found[j] - across[j]));
      }
    }
    const double tolerance = kTolerance * largest;
    const bool agree = !flow_rate_ || std::abs(r) <= tolerance;
    const bool converged = agree && change <= tolerance;
    if (converged || it == kMaxIterations) {
      wings_ = std::move(trial);
      transfer_ = x;
      mismatch_ = r;
      last_iterations_ = it;
      iterations_total_ += static_cast<std::uint64_t>(it);
      if (!converged) ++unconverged_;
      return steps;
    }
    if (!agree) {
      // The secant rule on r(x) = p1 - p0, which rises with x (more flow into
      // wing 1 raises its pressure and lowers wing 0's); its slope is kept
      // from step to step. Without one yet, a probe of 1% of the flow.
      if (have_prev && x != x_prev) {
        const double slope = (r - r_prev) / (x - x_prev);
        if (slope > 0) slope_ = slope;
      }
      r_prev = r;
      x_prev = x;
      have_prev = true;
      const double q = std::abs(wings_[0].config().inlet.flow_rate(wings_[0].time() + dt));
      x = slope_ > 0 ? x - r / slope_ : x - (r > 0 ? 1 : -1) * 1e-2 * std::max({q, std::abs(x), 1e-12});
      // Through the well a wing can give the other no more than its share of
      // the inflow and half the fluid its inlet particle holds over the step.
      auto most = [&](const FluidSolver& w) {
        const double m0 = w.particles().mass.empty() ? 0.0 : w.particles().mass.front();
        return 0.5 * q + 0.5 * m0 / (w.config().density * dt);
      };
      x = std::clamp(x, -most(wings_[1]), most(wings_[0]));
    }
    across = found;
  }
}

double TwoWingFluid::share() const {
  const double q0 = wings_[0].inlet_flux(), q1 = wings_[1].inlet_flux();
  return q0 + q1 != 0 ? q1 / (q0 + q1) : 0.5;
}

double TwoWingFluid::inlet_pressure() const { return 0.5 * (wings_[0].inlet_pressure() + wings_[1].inlet_pressure()); }

CrackPressure TwoWingFluid::pressure_message() const {
  CrackPressure m;
  m.crack_id = whole_.crack_id;
  m.ids = whole_.ids;
  m.pressure = merged(wings_);  // the implicit step's pressures already follow the faces: no stiffness
  const double at = arc_.empty() ? 0.0 : arc_[inlet_];
  m.front_position = at + wings_[1].front_position();
  m.front_start_position = std::max(0.0, at - wings_[0].front_position());
  m.inlet_flux = wings_[0].inlet_flux() + wings_[1].inlet_flux();
  m.fluid_volume = wings_[0].fluid_volume() + wings_[1].fluid_volume();
  return m;
}

namespace {

// The whole crack as last set, response included: a checkpoint falls
// between set_crack() and advance(), and the step after a restart must see
// the crack the uninterrupted run saw.
void save_geometry(StateWriter& out, const CrackGeometry& g) {
  out.put("crack_id", g.crack_id);
  out.put("ids", g.ids);
  out.put("position", g.position);
  out.put("normal", g.normal);
  out.put("width", g.width);
  out.put("tip", std::vector<std::uint64_t>(g.tip.begin(), g.tip.end()));
  out.put("grew", static_cast<int>(g.grew));
  out.put("opening_rate", g.opening_rate);
  out.put("opening_acceleration", g.opening_acceleration);
  out.put("opening_compliance", g.opening_compliance);
  out.put("compliance_band", g.compliance_band);
  out.put("plane_rate", g.plane_rate);
  out.put("plane_acceleration", g.plane_acceleration);
  out.put("tip_modulus", g.tip_modulus);
  out.put("resolution", g.resolution);
  out.put("inlet_id", g.inlet_id);
  out.put("start_tip_modulus", g.start_tip_modulus);
}

void load_geometry(const StateReader& in, CrackGeometry& g) {
  in.get("crack_id", g.crack_id);
  in.get("ids", g.ids);
  in.get("position", g.position);
  in.get("normal", g.normal);
  in.get("width", g.width);
  std::vector<std::uint64_t> tip;
  in.get("tip", tip);
  g.tip.assign(tip.begin(), tip.end());
  int grew = 0;
  in.get("grew", grew);
  g.grew = grew != 0;
  in.get("opening_rate", g.opening_rate);
  in.get("opening_acceleration", g.opening_acceleration);
  in.get("opening_compliance", g.opening_compliance);
  in.get("compliance_band", g.compliance_band);
  in.get("plane_rate", g.plane_rate);
  in.get("plane_acceleration", g.plane_acceleration);
  in.get("tip_modulus", g.tip_modulus);
  in.get("resolution", g.resolution);
  in.get("inlet_id", g.inlet_id);
  in.get("start_tip_modulus", g.start_tip_modulus);
  g.has_inlet = true;
  const std::size_t n = g.ids.size();
  if (g.position.size() != n || g.normal.size() != n || g.width.size() != n || g.tip.size() != n) {
    throw std::runtime_error("checkpoint: the two-wing fluid's crack arrays differ in size");
  }
}

}  // namespace

void TwoWingFluid::save(StateWriter& out) const {
  for (std::size_t w = 0; w < 2; ++w) {
    PrefixedWriter wing(out, "wing" + std::to_string(w) + ".");
    wings_[w].save(wing);
    PrefixedWriter before(out, "before" + std::to_string(w) + ".");
    before_[w].save(before);
  }
  PrefixedWriter whole(out, "whole.");
  save_geometry(whole, whole_);
  out.put("inlet", static_cast<std::uint64_t>(inlet_));
  out.put("transfer", transfer_);
  out.put("slope", slope_);
  out.put("mismatch", mismatch_);
  out.put("last_iterations", last_iterations_);
  out.put("iterations_total", iterations_total_);
  out.put("unconverged", unconverged_);
}

void TwoWingFluid::load(const StateReader& in) {
  for (std::size_t w = 0; w < 2; ++w) {
    wings_[w].load(PrefixedReader(in, "wing" + std::to_string(w) + "."));
    before_[w].load(PrefixedReader(in, "before" + std::to_string(w) + "."));
  }
  load_geometry(PrefixedReader(in, "whole."), whole_);
  std::uint64_t inlet = 0;
  in.get("inlet", inlet);
  inlet_ = static_cast<std::size_t>(inlet);
  if (inlet_ == 0 || inlet_ + 1 >= whole_.size())
    throw std::runtime_error("checkpoint: the two-wing fluid's inlet is not an inner particle");
  arc_ = arc_length(whole_.position);
  in.get("transfer", transfer_);
  in.get("slope", slope_);
  in.get("mismatch", mismatch_);
  in.get("last_iterations", last_iterations_);
  in.get("iterations_total", iterations_total_);
  in.get("unconverged", unconverged_);
}

}  // namespace hfmpm::fluid::mpm
