// Checkpoints of the MPM fluid: FluidSolver::save / load and CrackGrid::save / load.
// Scratch that every step rebuilds before reading it (drag_k_, widths_floor_)
// is not written. Doubles go through bit for bit.
#include <stdexcept>

#include "hfmpm/fluid/mpm/solver.hpp"

namespace hfmpm::fluid::mpm {

void CrackGrid::save(StateWriter& out) const {
  out.put("crack_id", crack_id_);
  out.put("ids", ids_);
  out.put("position", position_);
  out.put("arc", arc_);
  out.put("width", width_);
  out.put("crack_width", crack_width_);
  out.put("extra", extra_);
  out.put("min_spacing", min_spacing_);
  out.put("appended", appended_);
}

void CrackGrid::load(const StateReader& in) {
  in.get("crack_id", crack_id_);
  in.get("ids", ids_);
  in.get("position", position_);
  in.get("arc", arc_);
  in.get("width", width_);
  in.get("crack_width", crack_width_);
  in.get("extra", extra_);
  in.get("min_spacing", min_spacing_);
  in.get("appended", appended_);
  const std::size_t n = ids_.size();
  if (position_.size() != n || arc_.size() != n || width_.size() != n || crack_width_.size() != n ||
      extra_.size() != n) {
    throw std::runtime_error("checkpoint: the fluid's crack grid arrays differ in size");
  }
}

void FluidSolver::save(StateWriter& out) const {
  PrefixedWriter grid(out, "grid.");
  grid_.save(grid);
  const auto& P = particles_;
  out.put("particles.s", P.s);
  out.put("particles.length", P.length);
  out.put("particles.width", P.width);
  out.put("particles.mass", P.mass);
  out.put("particles.velocity", P.velocity);
  out.put("particles.gradient", P.gradient);
  out.put("particles.f11", P.f11);
  out.put("particles.f22", P.f22);
  out.put("particles.w0", P.w0);
  out.put("particles.pressure", P.pressure);
  std::vector<std::uint64_t> first, count;
  for (const auto& r : shapes_.range) {
    first.push_back(r.first);
    count.push_back(r.count);
  }
  out.put("shapes.first", first);
  out.put("shapes.count", count);
  out.put("shapes.offset", shapes_.offset);
  out.put("shapes.weight", shapes_.weight);
  out.put("shapes.gradient", shapes_.gradient);
  out.put("nodes.mass", mass_);
  out.put("nodes.momentum", momentum_);
  out.put("nodes.drag", drag_);
  out.put("nodes.force", force_);
  out.put("nodes.v_old", v_old_);
  out.put("nodes.v_new", v_new_);
  out.put("nodes.pressure", nodal_pressure_);
  out.put("nodes.pressure_at_set", pressure_at_set_);
  out.put("particle_length", particle_length_);
  out.put("t", t_);
  out.put("steps", steps_);
  out.put("injected_mass", injected_mass_);
  out.put("outflow_mass", outflow_mass_);
  out.put("inlet_flux", inlet_flux_);
  out.put("inlet_share", inlet_share_);
  out.put("inlet_transfer", inlet_transfer_);
  out.put("outlet_wetted", static_cast<int>(outlet_wetted_));
  out.put("wall.rate", wall_rate_);
  out.put("wall.acceleration", wall_acceleration_);
  out.put("wall.compliance", wall_compliance_);
  out.put("wall.band", wall_band_);
  out.put("wall.plane_rate", wall_plane_rate_);
  out.put("wall.tip_modulus", tip_modulus_);
  out.put("wall.resolution", resolution_);
  out.put("wall.plane_acceleration", wall_plane_acceleration_);
  out.put("predicted_arc", predicted_arc_);
  out.put("solved", solved_);
  std::vector<std::uint64_t> piece_count, piece_element;
  std::vector<double> piece_fraction;
  for (const auto& pieces : pieces_) {
    piece_count.push_back(pieces.size());
    for (const auto& [e, f] : pieces) {
      piece_element.push_back(e);
      piece_fraction.push_back(f);
    }
  }
  out.put("pieces.count", piece_count);
  out.put("pieces.element", piece_element);
  out.put("pieces.fraction", piece_fraction);
  out.put("interface.mismatch", interface_mismatch_);
  out.put("interface.residual", interface_residual_);
  out.put("interface.iterations", interface_iterations_);
  out.put("interface.merges", interface_merges_);
  out.put("interface.newton", interface_newton_);
  out.put("interface.unconverged", interface_unconverged_);
  out.put("interface.rescued", interface_rescued_);
  out.put("interface.subcycled", interface_subcycled_);
  out.put("interface.max_substeps", interface_max_substeps_);
  out.put("interface.committed_above", interface_committed_above_);
}

void FluidSolver::load(const StateReader& in) {
  PrefixedReader grid(in, "grid.");
  grid_.load(grid);
  auto& P = particles_;
  in.get("particles.s", P.s);
  in.get("particles.length", P.length);
  in.get("particles.width", P.width);
  in.get("particles.mass", P.mass);
  in.get("particles.velocity", P.velocity);
  in.get("particles.gradient", P.gradient);
  in.get("particles.f11", P.f11);
  in.get("particles.f22", P.f22);
  in.get("particles.w0", P.w0);
  in.get("particles.pressure", P.pressure);
  for (const auto* field :
       {&P.length, &P.width, &P.mass, &P.velocity, &P.gradient, &P.f11, &P.f22, &P.w0, &P.pressure}) {
    if (field->size() != P.s.size()) throw std::runtime_error("checkpoint: the fluid particles' arrays differ in size");
  }
  std::vector<std::uint64_t> first, count;
  in.get("shapes.first", first);
  in.get("shapes.count", count);
  if (first.size() != count.size()) throw std::runtime_error("checkpoint: the fluid's shape table is inconsistent");
  shapes_.range.resize(first.size());
  for (std::size_t p = 0; p < first.size(); ++p) shapes_.range[p] = {first[p], count[p]};
  in.get("shapes.offset", shapes_.offset);
  in.get("shapes.weight", shapes_.weight);
  in.get("shapes.gradient", shapes_.gradient);
  in.get("nodes.mass", mass_);
  in.get("nodes.momentum", momentum_);
  in.get("nodes.drag", drag_);
  in.get("nodes.force", force_);
  in.get("nodes.v_old", v_old_);
  in.get("nodes.v_new", v_new_);
  in.get("nodes.pressure", nodal_pressure_);
  in.get("nodes.pressure_at_set", pressure_at_set_);
  in.get("particle_length", particle_length_);
  in.get("t", t_);
  in.get("steps", steps_);
  in.get("injected_mass", injected_mass_);
  in.get("outflow_mass", outflow_mass_);
  in.get("inlet_flux", inlet_flux_);
  in.get("inlet_share", inlet_share_);
  in.get("inlet_transfer", inlet_transfer_);
  int wetted = 0;
  in.get("outlet_wetted", wetted);
  outlet_wetted_ = wetted != 0;
  in.get("wall.rate", wall_rate_);
  in.get("wall.acceleration", wall_acceleration_);
  in.get("wall.compliance", wall_compliance_);
  in.get("wall.band", wall_band_);
  in.get("wall.plane_rate", wall_plane_rate_);
  in.get("wall.tip_modulus", tip_modulus_);
  in.get("wall.resolution", resolution_);
  in.get("wall.plane_acceleration", wall_plane_acceleration_);
  in.get("predicted_arc", predicted_arc_);
  in.get("solved", solved_);
  std::vector<std::uint64_t> piece_count, piece_element;
  std::vector<double> piece_fraction;
  in.get("pieces.count", piece_count);
  in.get("pieces.element", piece_element);
  in.get("pieces.fraction", piece_fraction);
  if (piece_element.size() != piece_fraction.size())
    throw std::runtime_error("checkpoint: fluid pieces differ in size");
  pieces_.assign(piece_count.size(), {});
  std::size_t at = 0;
  for (std::size_t p = 0; p < piece_count.size(); ++p) {
    if (at + piece_count[p] > piece_element.size()) throw std::runtime_error("checkpoint: fluid pieces are short");
    for (std::uint64_t k = 0; k < piece_count[p]; ++k, ++at)
      pieces_[p].push_back({piece_element[at], piece_fraction[at]});
  }
  in.get("interface.mismatch", interface_mismatch_);
  in.get("interface.residual", interface_residual_);
  in.get("interface.iterations", interface_iterations_);
  in.get("interface.merges", interface_merges_);
  in.get("interface.newton", interface_newton_);
  in.get("interface.unconverged", interface_unconverged_);
  in.get("interface.rescued", interface_rescued_);
  in.get("interface.subcycled", interface_subcycled_);
  in.get("interface.max_substeps", interface_max_substeps_);
  in.get("interface.committed_above", interface_committed_above_);
}

}  // namespace hfmpm::fluid::mpm
