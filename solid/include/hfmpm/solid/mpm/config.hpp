// What an MPM solid is built from: grid, materials, regions (bonded into one
// body), constraints, edge tractions, silent edges, damping. Plain C++; the
// side adapter fills it from the scene. The member defaults are the
// library's, for programs and tests that build a config themselves; a run's
// defaults are the scene schema's (proto/hfmpm/scene.proto), which the
// adapter's to_solid_config sets for every member a scene key stands for.
// They agree but for threads (docs/architecture.md, "Defaults").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hfmpm/solid/mpm/crack.hpp"
#include "hfmpm/solid/mpm/grid.hpp"
#include "hfmpm/solid/mpm/material.hpp"
#include "hfmpm/solid/mpm/particles.hpp"
#include "hfmpm/time_function.hpp"

namespace hfmpm::solid::mpm {

// A part of the body with one material and one initial (in-situ) stress.
// Regions are bonded; where they overlap, the later one wins.
struct Region {
  enum class Kind { Rectangle, Polygon, Layer };
  Kind kind = Kind::Rectangle;
  Vec2 lo = Vec2::Zero(), hi = Vec2::Zero();  // Rectangle corners; Layer uses lo.y() .. hi.y()
  std::vector<Vec2> polygon;                  // Polygon vertices, either orientation
  int material = 0;
  Voigt initial_stress = Voigt::Zero();  // Pa, (xx, yy, xy, zz), tension positive
  int particles_per_cell = 0;            // per direction, 1 to 4; 0: SolidConfig's

  bool contains(const Vec2& p) const;
};

enum class Edge { Left, Right, Bottom, Top };

// Zero grid velocity components: on a symmetry plane x = c (or y = c) the
// normal component; in a box, the chosen components.
struct Constraint {
  enum class Kind { PlaneX, PlaneY, Box };
  Kind kind = Kind::PlaneX;
  double coordinate = 0;                      // m, PlaneX / PlaneY; must lie on a grid line
  Vec2 lo = Vec2::Zero(), hi = Vec2::Zero();  // Box
  bool fix_x = true, fix_y = true;            // Box
};

// Traction on the particles along one edge of the body: normal (tension
// positive, so a confining stress S is normal = -S) and shear (along the edge,
// counter-clockwise positive), both functions of time, Pa.
struct Traction {
  Edge edge = Edge::Left;
  TimeFunction normal = TimeFunction::constant(0);
  TimeFunction shear = TimeFunction::constant(0);
};

struct Damping {
  double grid_alpha = 0;    // 1/s: grid force -= alpha * momentum
  double pic_fraction = 0;  // 0 = pure FLIP, 1 = pure PIC velocity update
  // Feedback (Nose-Hoover) damping for quasi-static loading: a second grid
  // damping coefficient alpha_f >= 0 that follows
  //   d alpha_f / dt = (2 KE / M - 2 KE_target / M) / feedback_q,
  // so it rises while the body moves and relaxes when it is still. 0: off.
  // feedback_q (m^2) sets how fast: alpha_f climbs by v^2 / q per second at
  // a mean speed v; q ~ v^2 / omega^2 for the lowest frequency omega you want to damp.
  double feedback_q = 0;
  double feedback_target_ke = 0;  // J/m
};

// J-integral, stress intensity and growth of the cracks' tips.
struct Fracture {
  // The J domain around a tip is a square in the tip's frame: weight q = 1
  // within inner_cells cells of the tip, falling linearly to 0 at outer_cells.
  double inner_cells = 2.0;
  double outer_cells = 5.0;
  bool propagate = false;     // grow tips where J >= J_Ic of the material there
  double growth_cells = 0.5;  // a new crack particle this many cells ahead of the tip
  int check_interval = 10;    // steps between checks while propagating (as the scene default)
  // Mode I by symmetry (a crack on a symmetry line, as in KGD): grow straight
  // on, driven by the mode-I part of J only; K_II there is discretization
  // noise (the side tests put a crack lying on a grid line on one side).
  bool straight = false;
  // Zero-lag closure for fluid-driven cracks: an end tip does not grow while
  // it lies more than max_lag_cells cells (along the crack) beyond the fluid
  // front the fluid reported. Negative: no limit (and no effect without a fluid).
  double max_lag_cells = -1;
  // After a tip grows it is not checked again for settle_transits x L / c_s
  // (L its crack's length, c_s the shear-wave speed at the tip, with the
  // scaled density): the time the crack's opening needs to follow the new
  // length. 0: no wait.
  double settle_transits = 0;
  // The face load on a grown part of a crack is applied over
  // release_transits x L / c_s (L the crack's length before the step), rising
  // as a half-cosine, as a tip advancing steadily over that time would apply
  // it (Solver::update_releases). 0: at once. At most settle_transits.
  double release_transits = 0;
  // With the zero-lag closure (max_lag_cells >= 0 and a fluid front), for
  // tips that kink (not straight): once the front has come within the
  // allowed lag, the tip grows only after this many shear-wave transits of
  // its J domain (outer_cells h / c_s) have passed, so that the K's that set
  // its direction are read on the field the front's pressure has made.
  // 0: grows at the first check.
  double front_settle_transits = 4;
  // The crack surfaces follow the material's opening, the jump of its
  // displacement across the crack: set to it at the first step, then moved
  // by their fields' velocities plus a drift toward it (below;
  // Solver::anchor_crack_surfaces); false: the surfaces only integrate
  // their fields' velocities.
  bool surfaces_from_material = false;
  // With surfaces_from_material, the surfaces still move with their fields'
  // velocities, and relax onto the material's opening with the time constant
  // surface_relax_transits x L / c_s (L the crack's length, c_s the slowest
  // shear-wave speed at its tips, with the scaled density): a growth step
  // re-sorts the nodes about the new segment into two fields, and the
  // material's opening there jumps by the strain the uncut cell held; set at
  // once, that jump is a void the stiff fluid at a zero-lag tip cannot fill
  // in one step (its pressure at the last nodes fell to zero and rose to
  // 5 times the net pressure, and the kick stalled a toughness-dominated
  // KGD; docs/solid.md, "Surfaces from the material"). The relaxation is a
  // drift velocity the face response reports, so the implicit interface
  // scheme predicts it. 0: set to the material's opening at every step.
  double surface_relax_transits = 1;
  // After a growth step, the particles using a node the new segment re-sorts
  // into fields take the strain of their fields' nodal displacements (the strain a crack
  // cut there from the start gives them; Solver::reproject_strains). false:
  // they keep the strain the uncut body gave them (for comparison only).
  bool reproject_grown = true;
};

struct SolidConfig {
  Grid grid;
  std::vector<Material> materials;
  std::vector<Region> regions;
  int particles_per_cell = 2;  // per direction
  double cfl = 0.4;            // dt = cfl * h / c_p (with scaled density)
  double density_scaling = 1;  // every density is multiplied by this (>= 1 for quasi-static speed)
  std::vector<Constraint> constraints;
  std::vector<Traction> tractions;
  std::vector<Edge> silent_edges;  // absorbing (dashpot) edges
  Damping damping;
  std::vector<CrackSpec> cracks;
  Fracture fracture;
  // Where the fluid gives its stiffness -dp/dw, the change of the face
  // pressure over a step is taken implicitly at the nodes the crack cuts
  // (solver_cracks.cpp). Off: the pressure is explicit, which is unstable
  // for dt above about sqrt(rho h w / K_fluid).
  bool implicit_face_stiffness = true;
  // The regions' initial stress as the reference state: particles carry only
  // the change of stress from it, and every load acts as its change from the
  // in-situ tractions (edges: t - sigma0 n; crack faces: p n + sigma0 n).
  // For linear elasticity and frictionless contact this is the same problem
  // (superposition) when the in-situ stress is in equilibrium (uniform in
  // each region, tractions continuous across region interfaces). It removes
  // what the discretization gets wrong in proportion to the in-situ stress:
  // the load a crack tip particle cannot carry (its two sides fall in one
  // field) and the in-situ stress the first row of particles along a grown
  // crack loses as the tip passes (docs/solid.md).
  bool in_situ_reference = false;
  int threads = 1;  // the scene's default is 2 (solid.mpm.threads)
};

}  // namespace hfmpm::solid::mpm
