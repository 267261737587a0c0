// A scene's unset method keys filled from its physics (method::with_method),
// and the list `hfmpm validate` prints (method::describe).
#include <google/protobuf/descriptor.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "hfmpm/coupling/method.hpp"
#include "hfmpm/coupling/number_text.hpp"

namespace hfmpm::method {
namespace {

namespace pb = google::protobuf;
using text::approx;
using text::num;

// The field at a dotted path of singular fields, its message created on the
// way; null when a component is not a field.
pb::Message* parent_of(pb::Message& root, const std::string& key, const pb::FieldDescriptor** field) {
  pb::Message* message = &root;
  std::stringstream parts(key);
  std::string part;
  std::vector<std::string> components;
  while (std::getline(parts, part, '.')) components.push_back(part);
  for (std::size_t i = 0; i < components.size(); ++i) {
    const auto* f = message->GetDescriptor()->FindFieldByName(components[i]);
    if (!f || f->is_repeated()) return nullptr;
    if (i + 1 == components.size()) {
      *field = f;
      return message;
    }
    message = message->GetReflection()->MutableMessage(message, f);
  }
  return nullptr;
}

bool is_set(const scene::Scene& scene, const std::string& key) {
  scene::Scene probe = scene;  // reading must not create blocks in the scene itself
  const pb::FieldDescriptor* field = nullptr;
  pb::Message* parent = parent_of(probe, key, &field);
  return parent && parent->GetReflection()->HasField(*parent, field);
}

// Sets `key` to `value` (text format) where the scene leaves it unset, and
// records it. A value that does not parse is a bug here, not the user's.
void derive_key(scene::Scene& scene, std::vector<Setting>& applied, const std::string& key, const std::string& value,
                const std::string& rule) {
  if (is_set(scene, key)) return;
  const pb::FieldDescriptor* field = nullptr;
  pb::Message* parent = parent_of(scene, key, &field);
  if (!parent) throw std::logic_error("derived method: no scene key " + key);
  const std::string separator = field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE ? " " : ": ";
  if (!pb::TextFormat::MergeFromString(field->name() + separator + value, parent)) {
    throw std::logic_error("derived method: " + key + " = " + value + " does not parse");
  }
  applied.push_back({key, value, rule});
}

// The in-situ stress is in equilibrium on its own (the solid's rule for
// in_situ_reference: rectangles or layers, equal tractions across them).
bool in_situ_in_equilibrium(const scene::MpmSolid& m) {
  bool stressed = false;
  for (int i = 0; i < m.regions_size(); ++i) {
    const auto& r = m.regions(i);
    if (r.has_polygon()) return false;
    const auto& b = r.initial_stress();
    stressed = stressed || b.xx_pa() != 0 || b.yy_pa() != 0 || b.xy_pa() != 0;
    for (int j = 0; j < i; ++j) {
      const auto& a = m.regions(j).initial_stress();
      const bool layers = r.has_layer() && m.regions(j).has_layer();
      if (!(a.yy_pa() == b.yy_pa() && a.xy_pa() == b.xy_pa() && (layers || a.xx_pa() == b.xx_pa()))) return false;
    }
  }
  return stressed;
}

// v written so that it reads back no larger: the fill's front may not pass
// the wing it fills (to six digits a 45-degree notch's wing, 0.1499999 m,
// reads 0.15).
std::string num_at_most(double v) {
  const std::string nearest = num(v);
  return std::stod(nearest) > v ? num(text::significant(v, 6, true)) : nearest;
}

}  // namespace

scene::Scene with_method(const scene::Scene& scene, std::vector<Setting>* applied_out) {
  scene::Scene s = scene;
  std::vector<Setting> applied;
  const bool mpm_solid = s.solid().has_mpm();
  const bool mpm_fluid = s.fluid().has_mpm();
  if (!mpm_solid) {
    if (applied_out) *applied_out = applied;
    return s;
  }
  const auto& m = s.solid().mpm();
  const bool cracks = m.cracks_size() > 0;
  std::string why_not;
  const auto physics = physics_of(s, &why_not);

  if (mpm_fluid) {
    // The implicit interface: the fluid's pressure solved with the crack's
    // opening, stable for water at the solid's step.
    if (s.coupling().exchange_interval() <= 1) {
      derive_key(s, applied, "coupling.scheme", "IMPLICIT",
                 "the fluid's pressure solved with the crack's opening: any fluid, water too, at the solid's step");
    }
    if (s.coupling().scheme() == scene::Coupling::IMPLICIT) {
      derive_key(s, applied, "time.safety_factor", "0.9", "the implicit interface is stable at 0.9 of the stable step");
    }
    derive_key(s, applied, "fluid.mpm.merge_fraction", "0.5",
               "particles squeezed below half their length merge (they would set the fluid's step)");
    derive_key(s, applied, "fluid.mpm.max_substeps", "1000", "the fluid subcycles within the solid's step");
  }
  if (physics) {
    const auto& p = physics->physics;
    // The damping and the zero-lag wait follow the scene's own density
    // scaling and growth step where it sets them.
    const auto& fracture = s.solid().mpm().fracture();
    Chosen chosen;
    chosen.density_scaling = s.solid().mpm().has_density_scaling() ? s.solid().mpm().density_scaling() : 0;
    chosen.growth_cells = fracture.has_growth_cells() ? fracture.growth_cells() : 0;
    // The turning tips' settling wait, as the scene sets it or as it will be
    // derived below.
    const bool turning =
        fracture.has_direction() ? fracture.direction() == scene::FractureSpec::MAX_HOOP_STRESS : !p.symmetric;
    const bool zero_lag = fracture.has_max_lag_cells()
                              ? fracture.max_lag_cells() >= 0
                              : s.fluid().mpm().lag() != scene::MpmFluid::ZERO_PRESSURE || !is_set(s, "fluid.mpm.lag");
    chosen.turning_waits = turning && zero_lag;
    if (fracture.has_front_settle_transits()) chosen.front_settle_transits = fracture.front_settle_transits();
    if (fracture.has_j_outer_cells()) chosen.j_outer_cells = fracture.j_outer_cells();
    const Method d = derive(p, physics->cell, physics->reach, chosen);
    const Expected& x = d.expected;
    const double l_end = x.end.half_length;
    const std::string vertex = x.viscosity_dominated ? "M" : "K";
    if (physics->toughness_given) {
      derive_key(s, applied, "solid.mpm.fracture.propagate", "true",
                 "the rock at the well has a toughness: its crack grows where J reaches it");
    }
    derive_key(s, applied, "solid.mpm.density_scaling", num(d.density_scaling),
               "quasi-static: the scaled P-wave (" + approx(d.scaled_c) +
                   " m/s) crosses the expected final "
                   "half-length " +
                   approx(l_end) + " m in " + approx(100 * l_end / d.scaled_c / p.end_s) +
                   "% of the injection (target 0.5%" +
                   (d.settle ? "; with toughness, the settling wait may not cap the tip below its final speed" : "") +
                   (d.front_settle_capped ? "; the turning tips' wait after each step may not cap them below " +
                                                approx(d.early_tip_speed) + " m/s, their speed at three notch lengths"
                                          : "") +
                   ")");
    derive_key(s, applied, "solid.mpm.damping.grid_alpha_per_s", num(d.damping),
               "critical for the body's lowest mode (" + approx(d.body_omega) + " rad/s over its reach " +
                   approx(physics->reach) + " m)" +
                   (d.settle ? " or, with toughness, for the crack's quarter-wave mode at three notch lengths" : "") +
                   ", at most a 2% lag behind a load rising over " + approx(d.t_3) + " s (three notch lengths)");
    derive_key(s, applied, "solid.mpm.damping.pic_fraction", "0.5", "half PIC: the particles' noise damped");
    derive_key(s, applied, "solid.mpm.fracture.j_inner_cells", "1", "J over the tip's 3-cell square");
    derive_key(s, applied, "solid.mpm.fracture.j_outer_cells", "3", "J over the tip's 3-cell square");
    derive_key(s, applied, "solid.mpm.fracture.check_interval", "2", "tips checked every other step");
    derive_key(s, applied, "solid.mpm.fracture.growth_cells", num(d.growth_cells),
               d.settle ? "a quarter cell per growth step (toughness: the settling wait scales with its inverse)"
                        : "the tip leads the fluid front by at most 2 steps, 2.5% of three notch lengths (" +
                              approx(3 * p.notch) + " m)");
    derive_key(s, applied, "solid.mpm.fracture.direction", p.symmetric ? "STRAIGHT" : "MAX_HOOP_STRESS",
               p.symmetric ? "a straight notch with no in-situ shear on it, in a homogeneous body or one that is its "
                             "own mirror image about the notch's line: straight on by symmetry"
                           : "the in-situ stress puts " + approx(std::abs(p.shear_stress)) +
                                 " Pa of shear on the notch, the crack is bent or the body is not homogeneous: the "
                                 "tips turn by maximum hoop stress");
    if (chosen.turning_waits) {
      derive_key(s, applied, "solid.mpm.fracture.front_settle_transits", num(d.front_settle_transits),
                 "turning tips wait after each growth step 4 shear transits of the J domain per quarter cell of "
                 "step (at most 4)");
    }
    if (s.fluid().mpm().lag() != scene::MpmFluid::ZERO_PRESSURE || !is_set(s, "fluid.mpm.lag")) {
      derive_key(s, applied, "solid.mpm.fracture.max_lag_cells", num(d.growth_cells),
                 "zero lag: the tip waits for the fluid front within a growth step");
    }
    if (d.settle) {
      derive_key(s, applied, "solid.mpm.fracture.settle_transits", "2",
                 "toughness: after a step the opening follows over 2 shear transits of the crack");
      derive_key(s, applied, "solid.mpm.fracture.release_transits",
                 num(std::min(2.0, s.solid().mpm().fracture().settle_transits())),
                 "the new part's face load rises over the settling wait");
    }
    derive_key(s, applied, "fluid.mpm.virtual_opening_m", num(d.virtual_opening),
               "1% of the expected final mouth opening, " + approx(x.end.opening) + " m (" + vertex + "-vertex)");
    if (x.matched_closure) {
      derive_key(s, applied, "fluid.mpm.lag", "TIP_ASYMPTOTE_MATCHED",
                 "Km = " + approx(x.km) + " < 2: the viscous tip solution closes the fluid's front");
    } else {
      derive_key(s, applied, "fluid.mpm.lag", "FRONT_PRESSURE",
                 "Km = " + approx(x.km) + " >= 2: the front's pressure reaches the tip (zero lag)");
    }
    const auto lag = s.fluid().mpm().lag();
    if (lag == scene::MpmFluid::TIP_ASYMPTOTE_MATCHED || lag == scene::MpmFluid::TIP_ASYMPTOTE) {
      derive_key(s, applied, "fluid.mpm.lag_pressure_pa", num(d.lag_pressure),
                 p.symmetric ? "the dry tip zone carries the in-situ stress normal to the crack"
                             : "the dry tip zone carries the minimum in-situ stress the crack turns to");
    }
    derive_key(s, applied, "fluid.mpm.initial_fill",
               "{ front_m: " + num_at_most(p.notch) + " pressure_pa: " + num(std::max(0.0, p.normal_stress)) + " }",
               "the notch filled to its tip at the in-situ stress normal to it");
  } else if (mpm_fluid && cracks && applied_out) {
    applied.push_back({"(fluid-driven crack)", "not derived", why_not});
  }
  if (cracks) {
    derive_key(s, applied, "solid.mpm.fracture.surfaces_from_material", "true",
               "the faces follow the material's opening: a grown crack opens as a cut one, no drift at the tip");
  }
  if (in_situ_in_equilibrium(s.solid().mpm())) {
    derive_key(s, applied, "solid.mpm.in_situ_reference", "true",
               "the in-situ stress as the reference state: no crack-tip error scaling with it");
  }
  if (applied_out) *applied_out = applied;
  return s;
}

std::string describe(const std::vector<Setting>& settings, const std::string& prefix) {
  std::string out;
  for (const auto& setting : settings) {
    out += prefix + setting.key + ": " + setting.value + "   # " + setting.rule + "\n";
  }
  return out;
}

}  // namespace hfmpm::method
