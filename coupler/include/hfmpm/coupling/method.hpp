// The verified method as every scene's default (docs/scenes.md, "The derived
// method"). A scene gives the physics (body, rock, in-situ stress, crack,
// fluid, injection) and a cell size; every numerical key it leaves unset is
// derived here from that physics, with the rules `hfmpm scene` sizes its
// scenes by. A key the scene sets is kept. The coupler sends the scene with
// the derived keys filled in, so a side never re-derives them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "hfmpm/scene.pb.h"

namespace hfmpm::method {

// The plane-strain vertex solutions (zero lag, impermeable rock, Newtonian
// fluid; Q the total rate of both wings; half-length l, mouth opening w0,
// net inlet pressure p0 at time t).
struct Vertex {
  double half_length = 0, opening = 0, net_pressure = 0;
};
// Viscosity-dominated (M): Spence and Sharp 1985, Adachi and Detournay 2002.
Vertex m_vertex(double e_prime, double viscosity, double total_rate, double t);
// Toughness-dominated (K): a uniformly loaded crack with K_I = K_Ic and the injected volume.
Vertex k_vertex(double e_prime, double toughness, double total_rate, double t);
// Km = K' / (E'^3 mu' Q)^(1/4), K' = sqrt(32/pi) K_Ic, mu' = 12 mu.
double toughness_number(double e_prime, double viscosity, double total_rate, double toughness);

// The physics of a fluid-driven crack that its method is derived from.
struct Physics {
  double youngs_modulus = 0, poisson_ratio = 0, density = 0;  // the rock at the well
  double toughness = 0;                                       // K_Ic, Pa m^0.5 (0: the zero-toughness limit)
  double viscosity = 0;                                       // Pa s
  double total_rate = 0;                                      // m^2/s into both wings, at the end
  double end_s = 0;                                           // duration of the injection
  double effective_s = 0;  // time the end rate takes to inject the volume (a ramp over t_r: end - t_r / 2)
  double notch = 0;        // m, the initial length of one wing
  // The in-situ stress, compressive magnitudes (Pa): normal and shear on the
  // notch's plane, and the smaller principal stress.
  double normal_stress = 0, shear_stress = 0, minimum_stress = 0;
  // A straight notch with no in-situ shear on it in a homogeneous body (one
  // material and one in-situ stress in every region): the tips grow straight
  // on by symmetry.
  bool symmetric = true;
  // Two tips (a well inside the body): the settling wait after a growth step
  // counts the whole crack, both wings.
  bool two_wings = false;
  // m/s, the slowest shear-wave speed of the body's materials (0: the rock
  // at the well's): the turning tips' wait is longest there.
  double slowest_shear_speed = 0;
};

// What the physics leads to at the end of the injection.
struct Expected {
  double e_prime = 0, km = 0;
  bool viscosity_dominated = true;  // Km < 1: the M-vertex
  // Km < 2: the fluid front closed by the viscous tip solution matched to the
  // fluid (TIP_ASYMPTOTE_MATCHED), else the front's pressure reaches the tip
  // (FRONT_PRESSURE); 2 is the middle of the transition (Km 1 to 4).
  bool matched_closure = true;
  Vertex end;  // the regime's vertex; half_length the shorter of the two vertices'
};
Expected expect(const Physics& physics);

// One derived key: its scene path, its value in text format, and the rule
// with the numbers that gave it.
struct Setting {
  std::string key, value, rule;
};

// The numerical keys a scene chose itself, which the rest of the method
// follows: a density scaling or a growth step (> 0) used instead of the
// derived one, and the settling wait of turning tips.
struct Chosen {
  double density_scaling = 0, growth_cells = 0;
  // The tips turn (MAX_HOOP_STRESS) and wait for the fluid front (zero lag):
  // after each growth step they also wait front_settle_transits shear
  // transits of the J domain, j_outer_cells h / c_s (< 0: derived).
  bool turning_waits = false;
  double front_settle_transits = -1, j_outer_cells = 3;
};

// The numerical method of a fluid-driven crack, for a cell size and a body
// reaching `reach` metres from the well.
struct Method {
  Expected expected;
  double growth_cells = 0.25;  // cells per growth step, and the zero-lag wait
  bool settle = false;         // toughness: wait for the opening after a step
  double density_scaling = 1;
  double damping = 0;                // 1/s, mass-proportional on the grid
  double virtual_opening = 0;        // m
  double lag_pressure = 0;           // Pa, the dry tip zone's (matched closure)
  double body_omega = 0;             // rad/s, the body's lowest mode at the scaled wave speed
  double t_3 = 0;                    // s, the time the crack takes to three notch lengths
  double scaled_c = 0;               // m/s, the scaled P-wave speed
  double tip_speed = 0;              // m/s, the tip's mean speed over the injection
  double early_tip_speed = 0;        // m/s, the tip's speed when the crack reaches three notch lengths
  bool front_settle_capped = false;  // the turning tips' wait set the density scaling
  double front_settle_transits = 4;  // the turning tips' wait after each step, in J-domain transits
  std::vector<Setting> settings;
};
Method derive(const Physics& physics, double cell, double reach, const Chosen& chosen = {});

// The physics of a scene's fluid-driven crack: an MPM solid and an MPM fluid
// with a flow-rate inlet. Empty, with `why_not` saying so, otherwise.
struct ScenePhysics {
  Physics physics;
  double cell = 0, reach = 0;
  bool toughness_given = false;  // the rock at the well has a toughness: its crack can grow
};
std::optional<ScenePhysics> physics_of(const scene::Scene& scene, std::string* why_not = nullptr);

// The settings every scene gets: the fluid-driven crack's method where the
// scene has one, the general faces and in-situ reference otherwise.
// `applied` gets the settings filled in (the keys the scene left unset).
scene::Scene with_method(const scene::Scene& scene, std::vector<Setting>* applied = nullptr);

// The derived settings as text, a line each ("key: value   # rule"), for
// `hfmpm validate` and the built scene's header.
std::string describe(const std::vector<Setting>& settings, const std::string& prefix = "");

}  // namespace hfmpm::method
