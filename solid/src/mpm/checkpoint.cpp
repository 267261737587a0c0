// Checkpoints of the MPM solid: Solver::save / load and Crack::save / load.
// Everything that persists from one step to the next is written; scratch that
// each step rebuilds before reading it (the per-thread P2G accumulators and
// spans, face_slot_) is not. Doubles go through bit for bit.
#include <stdexcept>

#include "hfmpm/solid/mpm/solver.hpp"

namespace hfmpm::solid::mpm {
namespace {

template <class T>
void expect_size(const std::vector<T>& v, std::size_t n, const std::string& name) {
  if (v.size() != n) {
    throw std::runtime_error("checkpoint array " + name + " has " + std::to_string(v.size()) + " entries; this " +
                             "scene needs " + std::to_string(n));
  }
}

void save_fields(StateWriter& out, const std::string& prefix, const NodalFields& f) {
  out.put(prefix + "mass", f.mass);
  out.put(prefix + "momentum", f.momentum);
  out.put(prefix + "force", f.force);
  out.put(prefix + "displaced", f.displaced);
}

void load_fields(const StateReader& in, const std::string& prefix, NodalFields& f) {
  const std::size_t n = f.mass.size();
  in.get(prefix + "mass", f.mass);
  in.get(prefix + "momentum", f.momentum);
  in.get(prefix + "force", f.force);
  in.get(prefix + "displaced", f.displaced);
  expect_size(f.mass, n, prefix + "mass");
  expect_size(f.momentum, n, prefix + "momentum");
  expect_size(f.force, n, prefix + "force");
  expect_size(f.displaced, n, prefix + "displaced");
}

}  // namespace

void Crack::save(StateWriter& out) const {
  out.put("ids", ids_);
  out.put("plane", plane_);
  out.put("reference", reference_);
  out.put("above", above_);
  out.put("below", below_);
  out.put("pressure", pressure_);
  out.put("contact", contact_);
  out.put("stiffness", stiffness_);
  out.put("reference_width", reference_width_);
  out.put("wetted_length", wetted_length_);
  out.put("wetted_start", wetted_start_);
  out.put("next_id", next_id_);
  out.put("path", path_);
  out.put("box", std::vector<Vec2>{lo_, hi_});
  out.put("tip_tolerance", tip_tolerance_);
}

void Crack::load(const StateReader& in) {
  in.get("ids", ids_);
  in.get("plane", plane_);
  in.get("reference", reference_);
  in.get("above", above_);
  in.get("below", below_);
  expect_size(plane_, ids_.size(), "crack plane");
  expect_size(reference_, ids_.size(), "crack reference");
  expect_size(above_, ids_.size(), "crack above");
  expect_size(below_, ids_.size(), "crack below");
  in.get("pressure", pressure_);
  in.get("contact", contact_);
  in.get("stiffness", stiffness_);
  in.get("reference_width", reference_width_);
  in.get("wetted_length", wetted_length_);
  in.get("wetted_start", wetted_start_);
  in.get("next_id", next_id_);
  in.get("path", path_);
  std::vector<Vec2> box;
  in.get("box", box);
  expect_size(box, 2, "crack box");
  lo_ = box[0];
  hi_ = box[1];
  in.get("tip_tolerance", tip_tolerance_);
}

void Solver::save(StateWriter& out) const {
  out.put("t", t_);
  out.put("steps", steps_);
  out.put("contacts", contacts_);
  out.put("feedback_alpha", feedback_alpha_);
  out.put("in_situ_shear_work", in_situ_shear_work_);
  {
    std::vector<double> since, hit;
    for (const auto& tips : overloaded_since_) since.insert(since.end(), tips.begin(), tips.end());
    if (boundary_reached_) {
      const auto& b = *boundary_reached_;
      hit = {static_cast<double>(b.crack), b.at_end ? 1.0 : 0.0, b.position.x(), b.position.y(), b.t};
    }
    out.put("overloaded_since", since);
    out.put("boundary_reached", hit);
  }
  out.put("step_begun", static_cast<int>(step_begun_));
  out.put("transfer", transfer_);
  // Particles.
  const auto& p = particles_;
  out.put("particles.x", p.x);
  out.put("particles.v", p.v);
  out.put("particles.mass", p.mass);
  out.put("particles.volume", p.volume);
  out.put("particles.half_size", p.half_size);
  out.put("particles.stress", p.stress);
  out.put("particles.displacement", p.displacement);
  out.put("particles.grad_u", p.grad_u);
  out.put("particles.material", p.material);
  out.put("particles.region", p.region);
  // Cracks and their growth.
  out.put("cracks", cracks_.size());
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    PrefixedWriter crack(out, "crack" + std::to_string(c) + ".");
    cracks_[c].save(crack);
  }
  std::vector<double> grown;
  for (const auto& g : grown_at_) grown.insert(grown.end(), g.begin(), g.end());
  out.put("grown_at", grown);
  std::vector<double> arrived;
  for (const auto& a : front_arrived_at_) arrived.insert(arrived.end(), a.begin(), a.end());
  out.put("front_arrived_at", arrived);
  std::vector<double> released;  // per crack and (start, end) tip: t0, tau, length
  for (const auto& tips : releases_) {
    for (const auto& r : tips) released.insert(released.end(), {r.t0, r.tau, r.length});
  }
  out.put("releases", released);
  out.put("anchored_at", anchored_at_);
  std::vector<Vec2> drift;  // per crack particle, above then below (the crack's size known)
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    if (c >= surface_drift_.size() || surface_drift_[c].size() != cracks_[c].size()) {
      drift.assign(0, Vec2::Zero());
      break;
    }
    for (const auto& d : surface_drift_[c]) drift.insert(drift.end(), d.begin(), d.end());
  }
  out.put("surface_drift", drift);
  std::vector<std::uint64_t> tip_crack, tip_end, tip_material;
  std::vector<Vec2> tip_position, tip_direction;
  std::vector<double> tip_j, tip_j_faces, tip_k1, tip_k2, tip_kink, tip_toughness, tip_modulus;
  for (const auto& t : last_tips_) {
    tip_crack.push_back(t.crack);
    tip_end.push_back(t.at_end ? 1 : 0);
    tip_material.push_back(t.material);
    tip_position.push_back(t.position);
    tip_direction.push_back(t.direction);
    tip_j.push_back(t.j);
    tip_j_faces.push_back(t.j_faces);
    tip_k1.push_back(t.k1);
    tip_k2.push_back(t.k2);
    tip_kink.push_back(t.kink);
    tip_toughness.push_back(t.toughness);
    tip_modulus.push_back(t.modulus);
  }
  out.put("tips.crack", tip_crack);
  out.put("tips.at_end", tip_end);
  out.put("tips.material", tip_material);
  out.put("tips.position", tip_position);
  out.put("tips.direction", tip_direction);
  out.put("tips.j", tip_j);
  out.put("tips.j_faces", tip_j_faces);
  out.put("tips.k1", tip_k1);
  out.put("tips.k2", tip_k2);
  out.put("tips.kink", tip_kink);
  out.put("tips.toughness", tip_toughness);
  out.put("tips.modulus", tip_modulus);
  // The grid: what the last P2G and grid update left (read again between
  // begin_step() and step(), and where stale entries are not overwritten).
  save_fields(out, "field0.", field0_);
  save_fields(out, "field1.", field1_);
  for (int f = 0; f < 2; ++f) {
    out.put("velocity" + std::to_string(f), velocity_[f]);
    out.put("acceleration" + std::to_string(f), acceleration_[f]);
  }
  out.put("touched_in", touched_in_);
  out.put("active", active_);
  out.put("stencil_fields", stencil_fields_);
}

void Solver::load(const StateReader& in) {
  const std::size_t count = particles_.size();
  in.get("t", t_);
  in.get("steps", steps_);
  in.get("contacts", contacts_);
  in.get("feedback_alpha", feedback_alpha_);
  in.get("in_situ_shear_work", in_situ_shear_work_);
  {
    std::vector<double> since, hit;
    in.get("overloaded_since", since);
    in.get("boundary_reached", hit);
    overloaded_since_.assign(since.size() / 2, {0, 0});
    for (std::size_t c = 0; c < overloaded_since_.size(); ++c) overloaded_since_[c] = {since[2 * c], since[2 * c + 1]};
    boundary_reached_.reset();
    if (hit.size() == 5) {
      boundary_reached_ = BoundaryHit{static_cast<std::size_t>(hit[0]), hit[1] != 0, Vec2(hit[2], hit[3]), hit[4]};
    }
  }
  int begun = 0;
  in.get("step_begun", begun);
  step_begun_ = begun != 0;
  in.get("transfer", transfer_);
  auto& p = particles_;
  in.get("particles.x", p.x);
  in.get("particles.v", p.v);
  in.get("particles.mass", p.mass);
  in.get("particles.volume", p.volume);
  in.get("particles.half_size", p.half_size);
  in.get("particles.stress", p.stress);
  in.get("particles.displacement", p.displacement);
  in.get("particles.grad_u", p.grad_u);
  in.get("particles.material", p.material);
  in.get("particles.region", p.region);
  expect_size(p.x, count, "particles.x");
  expect_size(p.v, count, "particles.v");
  expect_size(p.mass, count, "particles.mass");
  expect_size(p.volume, count, "particles.volume");
  expect_size(p.half_size, count, "particles.half_size");
  expect_size(p.stress, count, "particles.stress");
  expect_size(p.material, count, "particles.material");
  std::size_t cracks = 0;
  in.get("cracks", cracks);
  if (cracks != cracks_.size()) {
    throw std::runtime_error("the checkpoint has " + std::to_string(cracks) + " crack(s); this scene has " +
                             std::to_string(cracks_.size()));
  }
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    PrefixedReader crack(in, "crack" + std::to_string(c) + ".");
    cracks_[c].load(crack);
  }
  std::vector<double> grown;
  in.get("grown_at", grown);
  if (grown.size() % 2 != 0) throw std::runtime_error("checkpoint array grown_at has an odd size");
  grown_at_.resize(grown.size() / 2);
  for (std::size_t i = 0; i < grown_at_.size(); ++i) grown_at_[i] = {grown[2 * i], grown[2 * i + 1]};
  std::vector<double> arrived;
  in.get("front_arrived_at", arrived);
  front_arrived_at_.resize(arrived.size() / 2);
  for (std::size_t i = 0; i < front_arrived_at_.size(); ++i)
    front_arrived_at_[i] = {arrived[2 * i], arrived[2 * i + 1]};
  std::vector<double> released;
  in.get("releases", released);
  if (released.size() % 6 != 0) throw std::runtime_error("checkpoint array releases has a size not a multiple of 6");
  releases_.resize(released.size() / 6);
  for (std::size_t i = 0; i < releases_.size(); ++i) {
    for (std::size_t e = 0; e < 2; ++e) {
      const double* r = &released[6 * i + 3 * e];
      releases_[i][e] = {r[0], r[1], r[2]};
    }
  }
  in.get("anchored_at", anchored_at_);
  std::vector<double> drift;
  in.get("surface_drift", drift);
  surface_drift_.clear();
  if (!drift.empty()) {
    std::size_t want = 0;
    for (const auto& crack : cracks_) want += 4 * crack.size();
    if (drift.size() != want) {
      throw std::runtime_error("checkpoint array surface_drift has " + std::to_string(drift.size()) +
                               " values; the cracks' particles need " + std::to_string(want));
    }
    std::size_t i = 0;
    surface_drift_.resize(cracks_.size());
    for (std::size_t c = 0; c < cracks_.size(); ++c) {
      surface_drift_[c].resize(cracks_[c].size());
      for (auto& d : surface_drift_[c]) {
        d = {Vec2(drift[i], drift[i + 1]), Vec2(drift[i + 2], drift[i + 3])};
        i += 4;
      }
    }
  }
  std::vector<std::uint64_t> tip_crack, tip_end, tip_material;
  std::vector<Vec2> tip_position, tip_direction;
  std::vector<double> tip_j, tip_j_faces, tip_k1, tip_k2, tip_kink, tip_toughness, tip_modulus;
  in.get("tips.crack", tip_crack);
  in.get("tips.at_end", tip_end);
  in.get("tips.material", tip_material);
  in.get("tips.position", tip_position);
  in.get("tips.direction", tip_direction);
  in.get("tips.j", tip_j);
  in.get("tips.j_faces", tip_j_faces);
  in.get("tips.k1", tip_k1);
  in.get("tips.k2", tip_k2);
  in.get("tips.kink", tip_kink);
  in.get("tips.toughness", tip_toughness);
  in.get("tips.modulus", tip_modulus);
  const std::size_t tips = tip_crack.size();
  for (const auto* v : {&tip_j, &tip_j_faces, &tip_k1, &tip_k2, &tip_kink, &tip_toughness, &tip_modulus}) {
    expect_size(*v, tips, "tips");
  }
  expect_size(tip_position, tips, "tips.position");
  expect_size(tip_direction, tips, "tips.direction");
  expect_size(tip_end, tips, "tips.at_end");
  expect_size(tip_material, tips, "tips.material");
  last_tips_.assign(tips, TipResult{});
  for (std::size_t i = 0; i < tips; ++i) {
    auto& t = last_tips_[i];
    t.crack = tip_crack[i];
    t.at_end = tip_end[i] != 0;
    t.material = tip_material[i];
    t.position = tip_position[i];
    t.direction = tip_direction[i];
    t.j = tip_j[i];
    t.j_faces = tip_j_faces[i];
    t.k1 = tip_k1[i];
    t.k2 = tip_k2[i];
    t.kink = tip_kink[i];
    t.toughness = tip_toughness[i];
    t.modulus = tip_modulus[i];
  }
  load_fields(in, "field0.", field0_);
  if (!field1_.mass.empty()) load_fields(in, "field1.", field1_);
  for (int f = 0; f < 2; ++f) {
    const std::size_t n = velocity_[f].size();
    in.get("velocity" + std::to_string(f), velocity_[f]);
    in.get("acceleration" + std::to_string(f), acceleration_[f]);
    expect_size(velocity_[f], n, "velocity" + std::to_string(f));
    expect_size(acceleration_[f], n, "acceleration" + std::to_string(f));
  }
  const std::size_t nodes = touched_in_.size();
  in.get("touched_in", touched_in_);
  expect_size(touched_in_, nodes, "touched_in");
  in.get("active", active_);
  in.get("stencil_fields", stencil_fields_);
  update_releases();  // derived from the time, the releases and the cracks (as begin_step does)
}

}  // namespace hfmpm::solid::mpm
