#include "mpm_solid_side.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "hfmpm/output/checkpoint_file.hpp"
#include "hfmpm/output/side_frames.hpp"
#include "hfmpm/proto/convert.hpp"
#include "hfmpm/proto/scene_rules.hpp"
#include "hfmpm/solid/mpm/solver.hpp"
#include "solid_scene_rules.hpp"

namespace hfmpm::solid {
namespace {

Vec2 lo(const scene::Box& b) { return {b.x_min_m(), b.y_min_m()}; }
Vec2 hi(const scene::Box& b) { return {b.x_max_m(), b.y_max_m()}; }

mpm::Edge to_edge(scene::Edge e) {
  switch (e) {
    case scene::RIGHT:
      return mpm::Edge::Right;
    case scene::BOTTOM:
      return mpm::Edge::Bottom;
    case scene::TOP:
      return mpm::Edge::Top;
    default:
      return mpm::Edge::Left;
  }
}

class MpmSolidSide final : public coupling::SideModel {
 public:
  void setup(const scene::Scene& scene, const std::string& output_dir) override {
    if (!scene.solid().has_mpm()) throw coupling::InputError("this side runs solid.mpm scenes only");
    // The side's own rules, as `hfmpm validate` applies them: a scene from
    // another coupler is refused with the same messages.
    if (const auto problems = proto::side_scene_problems(scene, scene_rules()); !problems.empty()) {
      std::string message;
      for (const auto& line : problems) message += (message.empty() ? "" : "\n") + line;
      throw coupling::InputError(message);
    }
    try {
      solver_.emplace(to_solid_config(scene.solid().mpm()));
    } catch (const std::invalid_argument& e) {
      throw coupling::InputError(std::string("solid.mpm: ") + e.what());
    }
    implicit_ = scene.has_fluid() && scene.coupling().scheme() == scene::Coupling::IMPLICIT;
    // Without a fluid, a crack may carry a prescribed face pressure.
    for (const auto& crack : scene.solid().mpm().cracks()) {
      prescribed_.push_back(!scene.has_fluid() && crack.has_pressure_pa()
                                ? std::optional<TimeFunction>(proto::to_time_function(crack.pressure_pa()))
                                : std::nullopt);
    }
    frames_.setup(scene.output().hdf5() ? output_dir + "/solid.h5" : std::string(), "hfmpm solid: " + scene.name());
    if (scene.has_fluid() && scene.fluid().has_mpm()) film_ = scene.fluid().mpm().virtual_opening_m();
    end_time_ = scene.time().end_s();
    initial_strain_energy_ = solver_->strain_energy();
  }
  bool can_checkpoint() const override { return true; }
  void will_restart() override { frames_.will_restart(); }
  void save_checkpoint(const std::string& path, const CheckpointStamp& stamp) override {
    output::write_checkpoint(path, stamp, [&](StateWriter& out) {
      PrefixedWriter solver(out, "solid.");
      solver_->save(solver);
      out.put("side.published", published_);
      frames_.save(out);
    });
  }
  void load_checkpoint(const std::string& path, const CheckpointStamp& stamp) override {
    output::read_checkpoint(path, stamp, [&](const StateReader& in) {
      PrefixedReader solver(in, "solid.");
      solver_->load(solver);
      in.get("side.published", published_);
      frames_.resume(in);
    });
  }
  double stable_dt() const override { return solver_->stable_dt(); }
  std::string stable_dt_limit() const override {
    return "P-wave CFL, cfl h / c_p (solid.mpm.cfl = " + std::to_string(solver_->config().cfl) + ")";
  }
  void advance(double dt) override {
    for (std::size_t c = 0; c < prescribed_.size(); ++c) {
      if (!prescribed_[c]) continue;
      const double p = (*prescribed_[c])(solver_->time());
      solver_->set_crack_pressure(c, std::vector<double>(solver_->cracks()[c].size(), p));
    }
    solver_->step(dt);
    watch(dt);
  }
  void publish(protocol::DataFrame& frame) override {
    auto* state = frame.mutable_crack();
    published_.resize(solver_->cracks().size(), 0);
    for (std::size_t c = 0; c < solver_->cracks().size(); ++c) {
      const auto& crack = solver_->cracks()[c];
      // The implicit scheme's face response is over the coming step, which
      // places the surfaces first (Solver::begin_step): the widths sent are those.
      if (implicit_) solver_->begin_step();
      auto g = geometry(crack);
      // For a fluid's tip closure: E' where the crack ends, and the cell.
      g.tip_modulus = solver_->plane_strain_modulus_at(crack.plane().back());
      g.resolution = solver_->config().grid.h;
      if (crack.has_inlet()) {  // a fluid entering inside the body runs towards both tips
        g.has_inlet = true;
        g.inlet_id = crack.inlet_id();
        g.start_tip_modulus = solver_->plane_strain_modulus_at(crack.plane().front());
      }
      if (implicit_) {  // the faces' response over the coming step, for the fluid's interface solve
        auto r = solver_->face_response(c);
        g.opening_rate = std::move(r.rate);
        g.opening_acceleration = std::move(r.acceleration);
        g.opening_compliance = std::move(r.compliance);
        g.compliance_band = static_cast<std::uint32_t>(r.band);
        g.plane_rate = std::move(r.plane_rate);
        g.plane_acceleration = std::move(r.plane_acceleration);
      }
      g.grew = published_[c] != 0 && crack.size() > published_[c];
      published_[c] = crack.size();
      proto::to_proto(g, state->add_cracks());
    }
  }
  void receive(const protocol::DataFrame& frame) override {
    for (const auto& c : frame.fluid().cracks()) {
      if (c.crack_id() >= solver_->cracks().size()) {
        throw proto::ProtocolError("FluidState names crack " + std::to_string(c.crack_id()) + "; this solid has " +
                                   std::to_string(solver_->cracks().size()) + " crack(s)");
      }
      const auto pressure = proto::from_proto(c);
      const auto& crack = solver_->cracks()[c.crack_id()];
      const std::ptrdiff_t offset = ids_run_offset(pressure.ids, crack.ids());
      if (offset < 0) {
        throw proto::ProtocolError("FluidState crack " + std::to_string(c.crack_id()) +
                                   ": its ids must be the crack's ids in order (a contiguous run of them while the "
                                   "crack grows)");
      }
      const auto first = static_cast<std::size_t>(offset);
      solver_->set_crack_pressure(c.crack_id(), pressure.pressure, pressure.stiffness, pressure.width, first);
      // The fluid's arc lengths count from the first id it answered for; the
      // crack may have grown at its start since.
      const double shift = first > 0 ? arc_length(crack.plane())[first] : 0.0;
      solver_->set_crack_front(c.crack_id(), pressure.front_start_position + shift, pressure.front_position + shift);
    }
  }
  SideDiagnostics diagnostics() const override {
    SideDiagnostics d;
    d.kinetic_energy = solver_->kinetic_energy();
    d.strain_energy = solver_->strain_energy();
    if (!solver_->cracks().empty()) {
      const auto& crack = solver_->cracks().front();
      const auto s = arc_length(crack.plane());
      d.crack_length = s.back();
      d.mouth_opening = crack.width(crack.inlet_index());  // where the fluid enters
      for (std::size_t k = 0; k < crack.size(); ++k)
        d.crack_face_load += crack.face_pressure(k) * crack.tributary_length(k);
    }
    for (const auto& crack : solver_->cracks()) d.crack_particles += static_cast<std::uint32_t>(crack.size());
    // The in-situ energy the cracks released: with the in-situ stress as
    // reference, the work of its shear traction on the faces' slip; without,
    // the fall of the particles' strain energy (which holds the in-situ stress).
    d.released_energy = solver_->config().in_situ_reference ? std::max(0.0, solver_->in_situ_shear_work())
                                                            : std::max(0.0, initial_strain_energy_ - d.strain_energy);
    return d;
  }
  std::vector<Notice> notices() const override { return notices_; }
  std::string done_reason() const override {
    const auto& hit = solver_->boundary_reached();
    if (!hit) return {};
    std::ostringstream out;
    out << "the crack reached the boundary: crack " << hit->crack << "'s " << (hit->at_end ? "end" : "start")
        << " tip at (" << hit->position.x() << ", " << hit->position.y() << ") m would grow to within a cell of "
        << "the body's edge at t = " << hit->t << " s; the run stops there, its output kept (a larger "
        << "solid.mpm.grid and regions hold a longer crack)";
    return out.str();
  }
  void write_output(std::uint64_t /*frame*/, double t) override {
    output::FrameWriter* writer = frames_.writer();
    if (!writer) return;
    const auto& p = solver_->particles();
    writer->begin_frame(t, solver_->steps());
    writer->points("particles", p.x);
    writer->vector("particles", "velocity", p.v);
    writer->tensor("particles", "stress", solver_->total_stresses());
    writer->integer("particles", "material", p.material);
    for (const auto& crack : solver_->cracks()) {
      const std::string set = "crack" + std::to_string(crack.id());
      std::vector<double> width(crack.size());
      std::vector<Vec2> normal(crack.size());
      for (std::size_t k = 0; k < crack.size(); ++k) {
        width[k] = crack.width(k);
        normal[k] = crack.normal(k);
      }
      writer->points(set, crack.plane());
      writer->scalar(set, "width", width);
      {
        std::vector<double> face(crack.size());
        for (std::size_t k = 0; k < crack.size(); ++k) face[k] = crack.face_pressure(k);
        writer->scalar(set, "pressure", face);
      }
      writer->vector(set, "normal", normal);
      writer->points(set + "_above", crack.surface(1));
      writer->points(set + "_below", crack.surface(-1));
    }
    if (!solver_->cracks().empty()) {
      // J and K at every tip (evaluated now: without propagation J is computed only here).
      const auto tips = solver_->tips();
      std::vector<Vec2> position;
      std::vector<double> j, k1, k2, kink;
      std::vector<std::int32_t> crack_id;
      for (const auto& tip : tips) {
        position.push_back(tip.position);
        j.push_back(tip.j);
        k1.push_back(tip.k1);
        k2.push_back(tip.k2);
        kink.push_back(tip.kink);
        crack_id.push_back(static_cast<std::int32_t>(tip.crack));
      }
      writer->points("tips", position);
      writer->scalar("tips", "j", j);
      writer->scalar("tips", "k1", k1);
      writer->scalar("tips", "k2", k2);
      writer->scalar("tips", "kink_angle", kink);
      writer->integer("tips", "crack", crack_id);
    }
    writer->end_frame();
  }

 private:
  // The end-state watches (docs/stability.md, "When a run must not pass
  // silently"), after every step; each raises its notice once.
  void watch(double dt) {
    const double t = solver_->time();
    const auto& fracture = solver_->config().fracture;
    // A tip far above its toughness that does not grow, for a fifth of the
    // run's time and at least 100 growth checks. A viscosity-dominated tip
    // carries more than its toughness and waits for the fluid between growth
    // steps; a KGD grows by a step s in 1.5 t s / L, under a tenth of t for
    // any crack longer than 4 steps.
    if (const auto o = solver_->longest_overload();
        o && o->duration > 0.2 * end_time_ && o->duration > 100.0 * fracture.check_interval * dt) {
      std::ostringstream out;
      out << "crack " << o->crack << "'s " << (o->at_end ? "end" : "start") << " tip has carried K = " << o->k_ratio
          << " x K_Ic for " << o->duration << " s (since t = " << t - o->duration
          << " s) without growing: a quasi-static crack grows once K reaches K_Ic, so the answer from then on "
             "is not the physics'. What held it: the zero-lag wait for the fluid's front "
             "(solid.mpm.fracture.max_lag_cells), the settling waits, or K's that do not carry J, so that no "
             "direction is known (docs/solid.md, \"Growth\")";
      raise("stalled-tip", out.str());
    }
    // Faces open beyond the fluid's film while every pressure the fluid puts
    // on them is below the smallest in-situ normal stress on the crack: a
    // state no equilibrium has.
    for (std::size_t c = 0; c < solver_->cracks().size(); ++c) {
      const auto& crack = solver_->cracks()[c];
      if (open_below_since_.size() <= c) open_below_since_.resize(c + 1, -1);
      double highest = 0, lowest_normal = std::numeric_limits<double>::infinity(), volume = 0, length = 0;
      for (std::size_t k = 0; k < crack.size(); ++k) {
        highest = std::max(highest, crack.face_pressure(k));
        const Vec2 n = crack.normal(k);
        lowest_normal = std::min(lowest_normal, -n.dot(mpm::traction(solver_->in_situ_stress(crack.plane()[k]), n)));
        volume += crack.width(k) * crack.tributary_length(k);
        length += crack.tributary_length(k);
      }
      const bool wet = crack.wetted_length() >= 0;
      const double resolution = 1e-3 * solver_->config().grid.h;
      const bool forbidden =
          wet && lowest_normal > 0 && highest < 0.95 * lowest_normal && volume > (2 * film_ + resolution) * length;
      double& since = open_below_since_[c];
      if (!forbidden) {
        since = -1;
        continue;
      }
      if (since < 0) since = t;
      if (t - since > 0.1 * end_time_ && t - since > 50 * dt) {
        std::ostringstream out;
        out << "crack " << c << " is open (mean opening " << volume / length << " m, beyond the fluid's film of "
            << film_ << " m) while the highest pressure on its faces, " << highest
            << " Pa, is below the smallest in-situ normal stress on it, " << lowest_normal << " Pa, since t = " << since
            << " s: no equilibrium has that, so the faces are not following the fluid (check the "
            << "crack's path and the fluid's front in solid.h5 and fluid.h5)";
        raise("open-below-stress", out.str());
      }
    }
  }
  void raise(const std::string& code, const std::string& message) {
    for (const auto& n : notices_) {
      if (n.code == code) return;
    }
    notices_.push_back({code, message});
  }
  std::vector<Notice> notices_;
  std::vector<double> open_below_since_;  // s, per crack; -1: not in that state
  double film_ = 0;                       // m, the fluid's virtual opening
  double end_time_ = 0;                   // s, the scene's time.end_s
  double initial_strain_energy_ = 0;      // J/m

  static CrackGeometry geometry(const mpm::Crack& crack) {
    CrackGeometry g;
    g.crack_id = crack.id();
    g.ids = crack.ids();
    g.position = crack.plane();
    g.normal.resize(crack.size());
    g.width.resize(crack.size());
    g.tip.assign(crack.size(), 0);
    for (std::size_t k = 0; k < crack.size(); ++k) {
      g.normal[k] = crack.normal(k);
      g.width[k] = crack.width(k);
    }
    if (crack.start_is_tip()) g.tip.front() = 1;
    if (crack.end_is_tip()) g.tip.back() = 1;
    return g;
  }

  std::optional<mpm::Solver> solver_;
  std::vector<std::optional<TimeFunction>> prescribed_;
  bool implicit_ = false;               // coupling.scheme IMPLICIT: publish the faces' response
  std::vector<std::size_t> published_;  // crack sizes at the last publication (growth flag)
  output::SideFrames frames_;           // the frame file (solid.h5 / fluid.h5) across restarts
};

}  // namespace

mpm::SolidConfig to_solid_config(const scene::MpmSolid& s) {
  mpm::SolidConfig c;
  const double h = s.cell_size_m();
  c.grid.origin = lo(s.grid());
  c.grid.h = h;
  c.grid.nx = static_cast<int>(std::lround((s.grid().x_max_m() - s.grid().x_min_m()) / h));
  c.grid.ny = static_cast<int>(std::lround((s.grid().y_max_m() - s.grid().y_min_m()) / h));
  std::map<std::string, int> index;
  for (const auto& m : s.materials()) {
    index[m.name()] = static_cast<int>(c.materials.size());
    mpm::Material mat{m.name(), m.youngs_modulus_pa(), m.poisson_ratio(), m.density_kg_m3()};
    if (m.has_toughness_j_m2()) mat.toughness = m.toughness_j_m2();
    if (m.has_toughness_pa_sqrt_m()) mat.toughness = std::pow(m.toughness_pa_sqrt_m(), 2) / mat.plane_strain_modulus();
    c.materials.push_back(mat);
  }
  for (const auto& r : s.regions()) {
    mpm::Region region;
    region.material = index.at(r.material());
    if (r.has_rectangle()) {
      region.kind = mpm::Region::Kind::Rectangle;
      region.lo = lo(r.rectangle());
      region.hi = hi(r.rectangle());
    } else if (r.has_polygon()) {
      region.kind = mpm::Region::Kind::Polygon;
      for (int i = 0; i < r.polygon().x_m_size(); ++i)
        region.polygon.emplace_back(r.polygon().x_m(i), r.polygon().y_m(i));
    } else {
      region.kind = mpm::Region::Kind::Layer;
      region.lo = Vec2(0, r.layer().y_min_m());
      region.hi = Vec2(0, r.layer().y_max_m());
    }
    const auto& st = r.initial_stress();
    const double nu = c.materials[static_cast<std::size_t>(region.material)].poisson_ratio;
    region.initial_stress =
        mpm::Voigt(st.xx_pa(), st.yy_pa(), st.xy_pa(), st.has_zz_pa() ? st.zz_pa() : nu * (st.xx_pa() + st.yy_pa()));
    if (r.has_particles_per_cell()) region.particles_per_cell = static_cast<int>(r.particles_per_cell());
    c.regions.push_back(region);
  }
  c.particles_per_cell = static_cast<int>(s.particles_per_cell());
  c.cfl = s.cfl();
  c.density_scaling = s.density_scaling();
  for (const auto& con : s.constraints()) {
    mpm::Constraint constraint;
    if (con.has_symmetry_x_m()) {
      constraint.kind = mpm::Constraint::Kind::PlaneX;
      constraint.coordinate = con.symmetry_x_m();
    } else if (con.has_symmetry_y_m()) {
      constraint.kind = mpm::Constraint::Kind::PlaneY;
      constraint.coordinate = con.symmetry_y_m();
    } else {
      constraint.kind = mpm::Constraint::Kind::Box;
      constraint.lo = lo(con.fixed_box());
      constraint.hi = hi(con.fixed_box());
      constraint.fix_x = con.fix_x();
      constraint.fix_y = con.fix_y();
    }
    c.constraints.push_back(constraint);
  }
  for (const auto& t : s.tractions()) {
    mpm::Traction traction;
    traction.edge = to_edge(t.edge());
    if (t.has_normal_pa()) traction.normal = proto::to_time_function(t.normal_pa());
    if (t.has_shear_pa()) traction.shear = proto::to_time_function(t.shear_pa());
    c.tractions.push_back(traction);
  }
  for (int e : s.silent_edges()) c.silent_edges.push_back(to_edge(static_cast<scene::Edge>(e)));
  c.damping.grid_alpha = s.damping().grid_alpha_per_s();
  c.damping.pic_fraction = s.damping().pic_fraction();
  c.damping.feedback_q = s.damping().feedback_q_m2();
  c.damping.feedback_target_ke = s.damping().feedback_target_kinetic_energy_j();
  c.fracture.inner_cells = s.fracture().j_inner_cells();
  c.fracture.outer_cells = s.fracture().j_outer_cells();
  c.fracture.propagate = s.fracture().propagate();
  c.fracture.growth_cells = s.fracture().growth_cells();
  c.fracture.check_interval = static_cast<int>(s.fracture().check_interval());
  c.fracture.straight = s.fracture().direction() == scene::FractureSpec::STRAIGHT;
  if (s.fracture().has_max_lag_cells()) c.fracture.max_lag_cells = s.fracture().max_lag_cells();
  c.fracture.settle_transits = s.fracture().settle_transits();
  c.fracture.release_transits = s.fracture().release_transits();
  c.fracture.front_settle_transits = s.fracture().front_settle_transits();
  c.fracture.surfaces_from_material = s.fracture().surfaces_from_material();
  c.implicit_face_stiffness = s.implicit_face_stiffness();
  c.in_situ_reference = s.in_situ_reference();
  c.threads = static_cast<int>(s.threads());
  for (const auto& cr : s.cracks()) {
    mpm::CrackSpec spec;
    spec.start_is_tip = cr.start_is_tip();
    spec.end_is_tip = cr.end_is_tip();
    spec.friction = cr.friction_coefficient();
    const double spacing = cr.has_spacing_m() ? cr.spacing_m() : h / 2;
    // Resample each polyline segment into pieces no longer than the spacing.
    spec.points.emplace_back(cr.x_m(0), cr.y_m(0));
    for (int i = 1; i < cr.x_m_size(); ++i) {
      const Vec2 a(cr.x_m(i - 1), cr.y_m(i - 1)), b(cr.x_m(i), cr.y_m(i));
      const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing - 1e-9)));
      for (int k = 1; k <= pieces; ++k) spec.points.push_back(a + (b - a) * (static_cast<double>(k) / pieces));
      // The inlet vertex keeps its own crack particle.
      if (cr.has_inlet_vertex() && static_cast<int>(cr.inlet_vertex()) == i)
        spec.inlet = static_cast<std::ptrdiff_t>(spec.points.size()) - 1;
    }
    c.cracks.push_back(spec);
  }
  return c;
}

std::unique_ptr<coupling::SideModel> make_mpm_solid_side() { return std::make_unique<MpmSolidSide>(); }

}  // namespace hfmpm::solid
