#include "mpm_fluid_side.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>

#include "fluid_scene_rules.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"
#include "hfmpm/output/checkpoint_file.hpp"
#include "hfmpm/output/side_frames.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/proto/scene_rules.hpp"

namespace hfmpm::fluid {
namespace {

class MpmFluidSide final : public coupling::SideModel {
 public:
  void setup(const scene::Scene& scene, const std::string& output_dir) override {
    if (!scene.fluid().has_mpm()) throw coupling::InputError("this side runs fluid.mpm scenes only");
    // The side's own rules, as `hfmpm validate` applies them: a scene from
    // another coupler is refused with the same messages.
    if (const auto problems = proto::side_scene_problems(scene, scene_rules()); !problems.empty()) {
      std::string message;
      for (const auto& line : problems) message += (message.empty() ? "" : "\n") + line;
      throw coupling::InputError(message);
    }
    const auto& f = scene.fluid().mpm();
    config_ = to_fluid_config(scene);
    try {
      mpm::FluidSolver check(config_);  // the library's own range checks, before any crack arrives
    } catch (const std::invalid_argument& e) {
      throw coupling::InputError(std::string("fluid.mpm: ") + e.what());
    }
    listed_.insert(f.crack_ids().begin(), f.crack_ids().end());
    if (f.has_initial_fill()) fill_ = f.initial_fill();
    max_substeps_ = std::max<std::uint32_t>(1, f.max_substeps());
    frames_.setup(scene.output().hdf5() ? output_dir + "/fluid.h5" : std::string(), "hfmpm fluid: " + scene.name());
  }

  bool can_checkpoint() const override { return true; }
  void will_restart() override { frames_.will_restart(); }
  void save_checkpoint(const std::string& path, const CheckpointStamp& stamp) override {
    output::write_checkpoint(path, stamp, [&](StateWriter& out) {
      std::vector<std::uint32_t> ids;
      for (const auto& c : cracks_) {
        ids.push_back(c.id);
        PrefixedWriter solver(out, "fluid" + std::to_string(c.id) + ".");
        c.solver.save(solver);
      }
      out.put("side.cracks", ids);
      out.put("side.received", static_cast<int>(received_));
      out.put("side.substeps", substeps_);
      out.put("side.steps", steps_);
      frames_.save(out);
    });
  }
  void load_checkpoint(const std::string& path, const CheckpointStamp& stamp) override {
    output::read_checkpoint(path, stamp, [&](const StateReader& in) {
      std::vector<std::uint32_t> ids;
      in.get("side.cracks", ids);
      std::vector<FluidCrack> restored(ids.size(), FluidCrack{0, mpm::FluidSolver(config_)});
      for (std::size_t i = 0; i < ids.size(); ++i) {
        restored[i].id = ids[i];
        restored[i].solver.load(PrefixedReader(in, "fluid" + std::to_string(ids[i]) + "."));
      }
      cracks_ = std::move(restored);
      int received = 0;
      in.get("side.received", received);
      received_ = received != 0;
      in.get("side.substeps", substeps_);
      in.get("side.steps", steps_);
      frames_.resume(in);
    });
  }

  // The coupled step may hold max_substeps fluid steps (the fluid subcycles).
  double stable_dt() const override {
    double dt = std::numeric_limits<double>::infinity();
    // The explicit fluid subcycles up to max_substeps times within a coupled
    // step; the implicit interface step does not (FluidSolver::advance), so
    // its own limit (advection) is the coupled step's.
    const double substeps = config_.implicit_interface ? 1.0 : static_cast<double>(max_substeps_);
    for (const auto& c : cracks_) dt = std::min(dt, c.solver.stable_dt() * substeps);
    return dt;
  }

  std::string stable_dt_limit() const override {
    return config_.implicit_interface
               ? "advection, cfl l / |v| (fluid.mpm.cfl = " + std::to_string(config_.cfl) + ")"
               : "sound speed, max_substeps x cfl l / c (fluid.mpm.cfl = " + std::to_string(config_.cfl) + ")";
  }

  void advance(double dt) override {
    for (auto& c : cracks_) {
      substeps_ += static_cast<std::uint64_t>(c.solver.advance(dt));
      // An implicit step whose solve failed whole was taken in fluid
      // substeps (FluidSolver::step_implicit): say so, the first
      // kReportedRetries times (fluid.log; the count is in the summary).
      if (config_.implicit_interface && c.solver.interface_last_above_bound() && above_reported_++ < kReportedRetries) {
        std::fprintf(stderr,
                     "hfmpm-fluid: crack %u: t = %.9g s: the implicit step of %.6g s was not solved within the bound, "
                     "whole nor in up to %d fluid substeps; taken whole at its best iterate: %s%s\n",
                     c.id, c.solver.time(), dt, mpm::FluidSolver::kMaxSubsteps, c.solver.interface_retry_why().c_str(),
                     above_reported_ == kReportedRetries ? " (further ones are only counted)" : "");
      }
      if (config_.implicit_interface && c.solver.interface_substeps() > 1 && retries_reported_++ < kReportedRetries) {
        std::fprintf(
            stderr, "hfmpm-fluid: crack %u: t = %.9g s: the implicit step of %.6g s taken in %d fluid substeps: %s%s\n",
            c.id, c.solver.time(), dt, c.solver.interface_substeps(), c.solver.interface_retry_why().c_str(),
            retries_reported_ == kReportedRetries ? " (further ones are only counted)" : "");
      }
    }
    ++steps_;
  }

  void publish(protocol::DataFrame& frame) override {
    auto* state = frame.mutable_fluid();  // a FluidState even when no crack holds fluid yet
    for (const auto& c : cracks_) proto::to_proto(c.solver.pressure_message(), state->add_cracks());
  }

  void receive(const protocol::DataFrame& frame) override {
    const bool first = !received_;
    received_ = true;
    for (const auto& message : frame.crack().cracks()) {
      const auto geometry = proto::from_proto(message);
      auto* crack = find(geometry.crack_id);
      if (!crack) {
        if (!first) {
          if (holds_fluid(geometry)) {
            throw proto::ProtocolError("CrackState: crack " + std::to_string(geometry.crack_id) +
                                       " appeared after step 0; the fluid builds its cracks at the step-0 exchange");
          }
          continue;
        }
        if (!holds_fluid(geometry)) continue;
        cracks_.push_back(FluidCrack{geometry.crack_id, mpm::FluidSolver(config_)});
        crack = &cracks_.back();
      }
      const bool had_grid = !crack->solver.grid().empty();
      try {
        if (had_grid) check_crack_update(geometry.crack_id, crack->solver.grid().ids(), geometry.ids, &geometry.grew);
        crack->solver.set_crack(geometry);
      } catch (const std::invalid_argument& e) {
        throw proto::ProtocolError(std::string("CrackState: ") + e.what());
      }
      if (!had_grid && fill_) fill(*crack);
    }
    if (first) {
      for (auto id : listed_) {
        if (!find(id)) {
          throw proto::ProtocolError("CrackState at step 0 has no crack " + std::to_string(id) +
                                     ", which fluid.mpm.crack_ids lists");
        }
      }
    }
  }

  void finish() override {
    if (!config_.implicit_interface && steps_ > 0) {
      // The fluid's own steps per coupled step (it subcycles at its stable dt).
      std::fprintf(
          stderr, "hfmpm-fluid: %.2f fluid steps per coupled step per crack (%llu coupled steps)\n",
          static_cast<double>(substeps_) / static_cast<double>(steps_ * std::max<std::size_t>(1, cracks_.size())),
          static_cast<unsigned long long>(steps_));
    }
    for (const auto& c : cracks_) {
      const auto& s = c.solver;
      if (!config_.implicit_interface || s.steps() == 0) continue;
      std::fprintf(stderr,
                   "hfmpm-fluid: crack %u: %llu implicit steps, %.2f Newton iterations per step, %llu particles "
                   "merged before a step; %llu solves finished by the careful Jacobian, %llu stopped above "
                   "tolerance (committed if no element misfit exceeds 1e-8 of the fluid, else retried): %llu steps "
                   "taken in fluid substeps (at most %llu), %llu taken whole above the bound after every retry\n",
                   c.id, static_cast<unsigned long long>(s.steps()),
                   static_cast<double>(s.interface_newton_total()) / static_cast<double>(s.steps()),
                   static_cast<unsigned long long>(s.interface_merges()),
                   static_cast<unsigned long long>(s.interface_rescued()),
                   static_cast<unsigned long long>(s.interface_unconverged_steps()),
                   static_cast<unsigned long long>(s.interface_subcycled_steps()),
                   static_cast<unsigned long long>(s.interface_max_substeps()),
                   static_cast<unsigned long long>(s.interface_committed_above_bound()));
    }
  }

  SideDiagnostics diagnostics() const override {
    SideDiagnostics d;
    for (std::size_t i = 0; i < cracks_.size(); ++i) {
      const auto& s = cracks_[i].solver;
      if (i == 0) d.inlet_pressure = s.inlet_pressure();
      d.kinetic_energy += s.kinetic_energy();
      d.injected_volume += s.injected_volume();  // through the mouth (an initial fill is not injected)
      d.fluid_volume += s.fluid_volume();
      d.front_position = std::max(d.front_position, s.front_position());
      d.fluid_particles += static_cast<std::uint32_t>(s.particles().size());
      d.coupling_lag =
          std::max(d.coupling_lag, config_.implicit_interface ? s.interface_mismatch() : s.frozen_width_rise());
    }
    return d;
  }

  void write_output(std::uint64_t /*frame*/, double t) override {
    output::FrameWriter* writer = frames_.writer();
    if (!writer) return;
    writer->begin_frame(t, steps_of_first());
    for (const auto& c : cracks_) {
      const auto& s = c.solver;
      const auto& p = s.particles();
      const std::string id = std::to_string(c.id);
      writer->points("fluid" + id, s.particle_positions());
      writer->scalar("fluid" + id, "arc_length", p.s);
      writer->scalar("fluid" + id, "length", p.length);
      writer->scalar("fluid" + id, "width", p.width);
      writer->scalar("fluid" + id, "pressure", p.pressure);
      writer->scalar("fluid" + id, "velocity", p.velocity);
      writer->scalar("fluid" + id, "mass", p.mass);
      const auto& g = s.grid();
      writer->points("nodes" + id, g.position());
      writer->scalar("nodes" + id, "arc_length", g.arc());
      writer->scalar("nodes" + id, "width", g.width());
      writer->scalar("nodes" + id, "pressure", s.nodal_pressure());
    }
    writer->end_frame();
  }

 private:
  struct FluidCrack {
    std::uint32_t id;
    mpm::FluidSolver solver;
  };

  FluidCrack* find(std::uint32_t id) {
    auto it = std::find_if(cracks_.begin(), cracks_.end(), [&](const FluidCrack& c) { return c.id == id; });
    return it == cracks_.end() ? nullptr : &*it;
  }
  bool holds_fluid(const CrackGeometry& g) const {
    if (!listed_.empty()) return listed_.count(g.crack_id) > 0;
    return !g.tip.empty() && g.tip.front() == 0;  // a mouth
  }
  void fill(FluidCrack& crack) {
    try {
      crack.solver.fill(fill_->front_m(), fill_->pressure_pa());
    } catch (const std::invalid_argument& e) {
      throw coupling::InputError(std::string("fluid.mpm.initial_fill: ") + e.what());
    }
  }
  std::uint64_t steps_of_first() const { return cracks_.empty() ? 0 : cracks_.front().solver.steps(); }

  mpm::FluidConfig config_;
  std::set<std::uint32_t> listed_;
  std::optional<scene::FluidFill> fill_;
  std::uint32_t max_substeps_ = 1;
  std::vector<FluidCrack> cracks_;
  bool received_ = false;
  std::uint64_t substeps_ = 0, steps_ = 0;  // fluid steps (all cracks) and coupled steps
  static constexpr int kReportedRetries = 20;
  int retries_reported_ = 0, above_reported_ = 0;  // subcycled implicit steps written to the log (not checkpointed)
  output::SideFrames frames_;                      // the frame file (solid.h5 / fluid.h5) across restarts
};

}  // namespace

mpm::FluidConfig to_fluid_config(const scene::Scene& scene) {
  const scene::MpmFluid& f = scene.fluid().mpm();
  mpm::FluidConfig c;
  c.implicit_interface = scene.coupling().scheme() == scene::Coupling::IMPLICIT;
  c.density = f.density_kg_m3();
  c.bulk_modulus = f.bulk_modulus_pa();
  c.tait_c = f.tait_c();
  c.viscosity = f.viscosity_pa_s();
  c.cfl = f.cfl();
  c.particle_length = f.particle_length_m();
  c.merge_fraction = f.merge_fraction();
  c.flip = f.flip_fraction();
  c.affine = f.affine_transfer();
  c.smooth_jacobian = f.element_pressure();
  c.min_width = f.min_width_m();
  const auto& in = f.inlet();
  if (in.has_pressure_pa()) {
    c.inlet.kind = mpm::InletConfig::Kind::Pressure;
    c.inlet.pressure = proto::to_time_function(in.pressure_pa());
  } else {
    c.inlet.kind = mpm::InletConfig::Kind::FlowRate;
    if (in.has_flow_rate_m2_s()) c.inlet.flow_rate = proto::to_time_function(in.flow_rate_m2_s());
  }
  c.inlet.pre_opening = in.pre_opening_m();
  c.inlet.pre_opening_length = in.pre_opening_length_m();
  c.virtual_opening = f.virtual_opening_m();
  c.lag = f.lag() == scene::MpmFluid::FRONT_PRESSURE   ? mpm::FluidConfig::Lag::Front
          : f.lag() == scene::MpmFluid::FIXED_PRESSURE ? mpm::FluidConfig::Lag::Fixed
          : f.lag() == scene::MpmFluid::TIP_ASYMPTOTE || f.lag() == scene::MpmFluid::TIP_ASYMPTOTE_MATCHED
              ? mpm::FluidConfig::Lag::TipAsymptote
              : mpm::FluidConfig::Lag::Zero;
  c.tip_level_matched = f.lag() == scene::MpmFluid::TIP_ASYMPTOTE_MATCHED;
  c.lag_pressure = f.lag_pressure_pa();
  if (f.has_outlet()) {
    c.outlet.enabled = true;
    c.outlet.pressure = proto::to_time_function(f.outlet().pressure_pa());
  }
  return c;
}

std::unique_ptr<coupling::SideModel> make_mpm_fluid_side() { return std::make_unique<MpmFluidSide>(); }

}  // namespace hfmpm::fluid
