#include "mpm_fluid_side.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>

#include "fluid_scene_rules.hpp"
#include "hfmpm/fluid/mpm/solver.hpp"
#include "hfmpm/fluid/mpm/two_wing.hpp"
#include "hfmpm/output/checkpoint_file.hpp"
#include "hfmpm/output/side_frames.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/proto/scene_rules.hpp"
#include "interface_watch.hpp"

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
      std::vector<std::uint64_t> two_wing;
      for (const auto& c : cracks_) {
        ids.push_back(c.id);
        two_wing.push_back(c.wings ? 1 : 0);
        PrefixedWriter solver(out, "fluid" + std::to_string(c.id) + ".");
        if (c.wings)
          c.wings->save(solver);
        else
          c.solver.save(solver);
      }
      out.put("side.cracks", ids);
      out.put("side.two_wing", two_wing);
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
      std::vector<std::uint64_t> two_wing;
      in.get("side.two_wing", two_wing);
      if (two_wing.size() != ids.size()) throw std::runtime_error("checkpoint: side.two_wing has the wrong size");
      std::vector<FluidCrack> restored(ids.size(), FluidCrack{0, mpm::FluidSolver(config_), std::nullopt});
      for (std::size_t i = 0; i < ids.size(); ++i) {
        restored[i].id = ids[i];
        const PrefixedReader reader(in, "fluid" + std::to_string(ids[i]) + ".");
        if (two_wing[i] != 0) {
          restored[i].wings.emplace(config_);
          restored[i].wings->load(reader);
        } else {
          restored[i].solver.load(reader);
        }
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
    for (const auto& c : cracks_) {
      for (const auto* solver : c.solvers()) dt = std::min(dt, solver->stable_dt() * substeps);
    }
    return dt;
  }

  std::string stable_dt_limit() const override {
    return config_.implicit_interface
               ? "advection, cfl l / |v| (fluid.mpm.cfl = " + std::to_string(config_.cfl) + ")"
               : "sound speed, max_substeps x cfl l / c (fluid.mpm.cfl = " + std::to_string(config_.cfl) + ")";
  }

  void advance(double dt) override {
    for (auto& c : cracks_) {
      if (c.wings) {
        substeps_ += static_cast<std::uint64_t>(c.wings->advance(dt));
        if (c.wings->last_iterations() == mpm::TwoWingFluid::kMaxIterations &&
            junction_reported_++ < kReportedRetries) {
          std::fprintf(stderr,
                       "hfmpm-fluid: crack %u: t = %.9g s: the wings' junction did not settle in %d iterations; the "
                       "inlet pressures differ by %.6g Pa with %.6g m^2/s passed to the end wing%s\n",
                       c.id, c.wings->wing(1).time(), mpm::TwoWingFluid::kMaxIterations, c.wings->junction_mismatch(),
                       c.wings->transfer(),
                       junction_reported_ == kReportedRetries ? " (further ones are only counted)" : "");
        }
      } else {
        substeps_ += static_cast<std::uint64_t>(c.solver.advance(dt));
      }
      for (const auto* solver : c.solvers()) report_retries(c.id, *solver, dt);
    }
    ++steps_;
    if (config_.implicit_interface) {
      std::uint64_t unsolved = 0, steps = 0;
      double t = 0;
      for (const auto& c : cracks_) {
        for (const auto* solver : c.solvers()) {
          unsolved += solver->interface_committed_above_bound();
          steps += solver->steps();
          t = std::max(t, solver->time());
        }
      }
      if (auto message = interface_watch_.check(unsolved, steps, t))
        notices_.push_back({"unsolved-interface", *message});
    }
  }

  std::vector<Notice> notices() const override { return notices_; }

  void publish(protocol::DataFrame& frame) override {
    auto* state = frame.mutable_fluid();  // a FluidState even when no crack holds fluid yet
    for (const auto& c : cracks_)
      proto::to_proto(c.wings ? c.wings->pressure_message() : c.solver.pressure_message(), state->add_cracks());
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
        cracks_.push_back(FluidCrack{geometry.crack_id, mpm::FluidSolver(config_), std::nullopt});
        crack = &cracks_.back();
        if (geometry.has_inlet) crack->wings.emplace(config_);  // a wellbore inside the body: two wings
      }
      if (geometry.has_inlet != crack->wings.has_value()) {
        throw proto::ProtocolError("CrackState: crack " + std::to_string(geometry.crack_id) +
                                   (geometry.has_inlet ? " has an inlet_id now but had none at step 0"
                                                       : " had an inlet_id at step 0 but has none now"));
      }
      const bool had_grid = !crack->solvers().front()->grid().empty();
      try {
        if (had_grid) {
          // A crack whose start is a tip may grow there too (ids prepended).
          std::size_t prepended = 0;
          const bool start_tip = !geometry.tip.empty() && geometry.tip.front() != 0;
          check_crack_update(geometry.crack_id, crack->wings ? crack->wings->ids() : crack->solver.grid().ids(),
                             geometry.ids, &geometry.grew, start_tip ? &prepended : nullptr);
        }
        if (crack->wings && had_grid && geometry.inlet_id != crack->wings->inlet_id()) {
          throw std::invalid_argument("crack " + std::to_string(geometry.crack_id) + ": inlet_id changed from " +
                                      std::to_string(crack->wings->inlet_id()) + " to " +
                                      std::to_string(geometry.inlet_id) +
                                      "; the fluid enters at one crack particle for the whole run");
        }
        if (crack->wings) {
          crack->wings->set_crack(geometry);
        } else {
          crack->solver.set_crack(geometry);
        }
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
    for (const auto& c : cracks_) {
      if (!c.wings || steps_ == 0) continue;
      std::fprintf(stderr,
                   "hfmpm-fluid: crack %u: two wings from the inlet: %.2f junction iterations per step, %llu steps "
                   "left above the junction's tolerance after %d; share into the end wing %.6g at the end\n",
                   c.id, static_cast<double>(c.wings->iterations_total()) / static_cast<double>(steps_),
                   static_cast<unsigned long long>(c.wings->unconverged_steps()), mpm::TwoWingFluid::kMaxIterations,
                   c.wings->share());
    }
    if (!config_.implicit_interface && steps_ > 0) {
      // The fluid's own steps per coupled step (it subcycles at its stable dt).
      std::fprintf(
          stderr, "hfmpm-fluid: %.2f fluid steps per coupled step per crack (%llu coupled steps)\n",
          static_cast<double>(substeps_) / static_cast<double>(steps_ * std::max<std::size_t>(1, cracks_.size())),
          static_cast<unsigned long long>(steps_));
    }
    for (const auto& c : cracks_) {
      for (const auto* solver : c.solvers()) {
        const auto& s = *solver;
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
  }

  SideDiagnostics diagnostics() const override {
    SideDiagnostics d;
    for (std::size_t i = 0; i < cracks_.size(); ++i) {
      const auto& c = cracks_[i];
      if (i == 0) d.inlet_pressure = c.wings ? c.wings->inlet_pressure() : c.solver.inlet_pressure();
      for (const auto* solver : c.solvers()) {
        const auto& s = *solver;
        d.kinetic_energy += s.kinetic_energy();
        d.injected_volume += s.injected_volume();  // through the mouth (an initial fill is not injected)
        d.fluid_volume += s.fluid_volume();
        d.front_position = std::max(d.front_position, s.front_position());  // from where the fluid enters
        d.fluid_particles += static_cast<std::uint32_t>(s.particles().size());
        d.coupling_lag =
            std::max(d.coupling_lag, config_.implicit_interface ? s.interface_mismatch() : s.frozen_width_rise());
      }
    }
    return d;
  }

  void write_output(std::uint64_t /*frame*/, double t) override {
    output::FrameWriter* writer = frames_.writer();
    if (!writer) return;
    writer->begin_frame(t, steps_of_first());
    for (const auto& c : cracks_) {
      const std::string id = std::to_string(c.id);
      if (c.wings) {
        write_two_wing(*writer, id, *c.wings);
        continue;
      }
      const auto& s = c.solver;
      const auto& p = s.particles();
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
    mpm::FluidSolver solver;                 // a crack whose fluid enters at its mouth
    std::optional<mpm::TwoWingFluid> wings;  // or at an inner particle (a wellbore): then this, not `solver`
    std::vector<const mpm::FluidSolver*> solvers() const {
      if (wings) return {&wings->wing(0), &wings->wing(1)};
      return {&solver};
    }
  };

  // The retried implicit steps of one solver, the first kReportedRetries times (fluid.log; the count is in the
  // summary).
  void report_retries(std::uint32_t id, const mpm::FluidSolver& s, double dt) {
    if (config_.implicit_interface && s.interface_last_above_bound() && above_reported_++ < kReportedRetries) {
      std::fprintf(stderr,
                   "hfmpm-fluid: crack %u: t = %.9g s: the implicit step of %.6g s was not solved within the bound, "
                   "whole nor in up to %d fluid substeps; taken whole at its best iterate: %s%s\n",
                   id, s.time(), dt, mpm::FluidSolver::kMaxSubsteps, s.interface_retry_why().c_str(),
                   above_reported_ == kReportedRetries ? " (further ones are only counted)" : "");
    }
    if (config_.implicit_interface && s.interface_substeps() > 1 && retries_reported_++ < kReportedRetries) {
      std::fprintf(stderr,
                   "hfmpm-fluid: crack %u: t = %.9g s: the implicit step of %.6g s taken in %d fluid substeps: %s%s\n",
                   id, s.time(), dt, s.interface_substeps(), s.interface_retry_why().c_str(),
                   retries_reported_ == kReportedRetries ? " (further ones are only counted)" : "");
    }
  }

  // Both wings as one fluid on the whole crack: particles of wing 0 then
  // wing 1, their arc lengths and velocities along the whole crack (from its
  // first node; wing 0 runs against it); the nodes of the whole crack.
  static void write_two_wing(output::FrameWriter& writer, const std::string& id, const mpm::TwoWingFluid& wings) {
    std::vector<Vec2> position;
    std::vector<double> arc, length, width, pressure, velocity, mass;
    const double at = wings.arc()[wings.inlet_index()];
    for (std::size_t w = 0; w < 2; ++w) {
      const auto& s = wings.wing(w);
      const auto& p = s.particles();
      const double sign = w == 0 ? -1.0 : 1.0;
      const auto xs = s.particle_positions();
      position.insert(position.end(), xs.begin(), xs.end());
      for (std::size_t k = 0; k < p.size(); ++k) {
        arc.push_back(at + sign * p.s[k]);
        velocity.push_back(sign * p.velocity[k]);
      }
      length.insert(length.end(), p.length.begin(), p.length.end());
      width.insert(width.end(), p.width.begin(), p.width.end());
      pressure.insert(pressure.end(), p.pressure.begin(), p.pressure.end());
      mass.insert(mass.end(), p.mass.begin(), p.mass.end());
    }
    writer.points("fluid" + id, position);
    writer.scalar("fluid" + id, "arc_length", arc);
    writer.scalar("fluid" + id, "length", length);
    writer.scalar("fluid" + id, "width", width);
    writer.scalar("fluid" + id, "pressure", pressure);
    writer.scalar("fluid" + id, "velocity", velocity);
    writer.scalar("fluid" + id, "mass", mass);
    writer.points("nodes" + id, wings.positions());
    writer.scalar("nodes" + id, "arc_length", wings.arc());
    writer.scalar("nodes" + id, "width", wings.join(wings.wing(0).grid().width(), wings.wing(1).grid().width()));
    writer.scalar("nodes" + id, "pressure", wings.join(wings.wing(0).nodal_pressure(), wings.wing(1).nodal_pressure()));
  }

  FluidCrack* find(std::uint32_t id) {
    auto it = std::find_if(cracks_.begin(), cracks_.end(), [&](const FluidCrack& c) { return c.id == id; });
    return it == cracks_.end() ? nullptr : &*it;
  }
  bool holds_fluid(const CrackGeometry& g) const {
    if (!listed_.empty()) return listed_.count(g.crack_id) > 0;
    return g.has_inlet || (!g.tip.empty() && g.tip.front() == 0);  // a wellbore inside, or a mouth
  }
  void fill(FluidCrack& crack) {
    try {
      if (crack.wings)
        crack.wings->fill(fill_->front_m(), fill_->pressure_pa());
      else
        crack.solver.fill(fill_->front_m(), fill_->pressure_pa());
    } catch (const std::invalid_argument& e) {
      throw coupling::InputError(std::string("fluid.mpm.initial_fill: ") + e.what());
    }
  }
  std::uint64_t steps_of_first() const { return cracks_.empty() ? 0 : cracks_.front().solvers().front()->steps(); }

  mpm::FluidConfig config_;
  std::set<std::uint32_t> listed_;
  std::optional<scene::FluidFill> fill_;
  std::uint32_t max_substeps_ = 1;
  std::vector<FluidCrack> cracks_;
  bool received_ = false;
  std::uint64_t substeps_ = 0, steps_ = 0;  // fluid steps (all cracks) and coupled steps
  InterfaceWatch interface_watch_;
  std::vector<Notice> notices_;
  static constexpr int kReportedRetries = 20;
  int retries_reported_ = 0, above_reported_ = 0,
      junction_reported_ = 0;  // subcycled implicit steps written to the log (not checkpointed)
  output::SideFrames frames_;  // the frame file (solid.h5 / fluid.h5) across restarts
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
