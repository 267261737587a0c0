#include "mpm_solid_side.hpp"

#include <cmath>
#include <map>
#include <optional>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid {
namespace {

Vec2 lo(const scene::Box& b) { return {b.x_min_m(), b.y_min_m()}; }
Vec2 hi(const scene::Box& b) { return {b.x_max_m(), b.y_max_m()}; }

mpm::Edge to_edge(scene::Edge e) {
  switch (e) {
    case scene::RIGHT: return mpm::Edge::Right;
    case scene::BOTTOM: return mpm::Edge::Bottom;
    case scene::TOP: return mpm::Edge::Top;
    default: return mpm::Edge::Left;
  }
}

class MpmSolidSide final : public coupling::SideModel {
 public:
  void setup(const scene::Scene& scene, const std::string& /*output_dir*/) override {
    if (!scene.solid().has_mpm()) throw coupling::InputError("this side runs solid.mpm scenes only");
    try {
      solver_.emplace(to_solid_config(scene.solid().mpm()));
    } catch (const std::invalid_argument& e) {
      throw coupling::InputError(std::string("solid.mpm: ") + e.what());
    }
  }
  double stable_dt() const override { return solver_->stable_dt(); }
  void advance(double dt) override { solver_->step(dt); }
  void publish(protocol::DataFrame& frame) override {
    frame.mutable_crack();  // no crack yet: an empty CrackState
  }
  void receive(const protocol::DataFrame& frame) override {
    if (frame.fluid().cracks_size() > 0) {
      throw proto::ProtocolError("FluidState has pressures for " + std::to_string(frame.fluid().cracks_size()) +
                                 " crack(s) but this solid has no crack");
    }
  }
  SideDiagnostics diagnostics() const override {
    SideDiagnostics d;
    d.kinetic_energy = solver_->kinetic_energy();
    return d;
  }

 private:
  std::optional<mpm::Solver> solver_;
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
    c.materials.push_back({m.name(), m.youngs_modulus_pa(), m.poisson_ratio(), m.density_kg_m3()});
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
      for (int i = 0; i < r.polygon().x_m_size(); ++i) region.polygon.emplace_back(r.polygon().x_m(i), r.polygon().y_m(i));
    } else {
      region.kind = mpm::Region::Kind::Layer;
      region.lo = Vec2(0, r.layer().y_min_m());
      region.hi = Vec2(0, r.layer().y_max_m());
    }
    const auto& st = r.initial_stress();
    const double nu = c.materials[static_cast<std::size_t>(region.material)].poisson_ratio;
    region.initial_stress = mpm::Voigt(st.xx_pa(), st.yy_pa(), st.xy_pa(),
                                       st.has_zz_pa() ? st.zz_pa() : nu * (st.xx_pa() + st.yy_pa()));
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
  c.threads = static_cast<int>(s.threads());
  return c;
}

std::unique_ptr<coupling::SideModel> make_mpm_solid_side() { return std::make_unique<MpmSolidSide>(); }

}  // namespace hfmpm::solid
