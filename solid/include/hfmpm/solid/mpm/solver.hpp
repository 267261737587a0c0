// Explicit 2D plane-strain MPM (uGIMP shape functions, update stress last).
//
// One step (USL; Sulsky, Chen and Schreyer 1994, with uGIMP weights):
//   1. P2G: nodal mass, momentum and force (internal -V sigma . grad S, and
//      edge tractions / dashpots integrated along the body's edge);
//   2. grid: damping, momentum update p += f dt, velocity constraints;
//   3. G2P: particle velocity (FLIP with an optional PIC fraction) and position
//      from the new nodal velocities, and in the same pass the strain
//      increment dt sym(grad v) and the elastic stress update.
// USL because it needs two particle passes per step (USF needs three); the
// stress then uses the velocity at the end of the step, which suits the
// damped, quasi-static loading of hydraulic fracture.
#pragma once

#include <array>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hfmpm/solid/mpm/config.hpp"
#include "hfmpm/solid/mpm/crack.hpp"
#include "hfmpm/solid/mpm/grid.hpp"
#include "hfmpm/solid/mpm/particles.hpp"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::solid::mpm {

struct FaceShares;  // solver_cracks.cpp

// The state of one crack tip (fracture.cpp).
struct TipResult {
  std::size_t crack = 0;
  bool at_end = true;              // the crack's last particle (false: its first)
  Vec2 position = Vec2::Zero();    // m
  Vec2 direction = Vec2::UnitX();  // unit, along the last segment, out of the crack
  double j = 0;                    // J/m^2: energy release rate (area integral plus face-load work)
  double j_faces = 0;              // J/m^2: the face-load part of j
  double k1 = 0, k2 = 0;           // Pa m^0.5, from the interaction integral (Williams auxiliary fields)
  double kink = 0;                 // rad, growth direction by maximum hoop stress, counter-clockwise from direction
  double toughness = 0;            // J/m^2, J_Ic of the material at the tip
  double modulus = 0;              // Pa, plane-strain E' there
  std::size_t material = 0;        // index of the material at the tip
  // rad: the largest angle between `direction` and a crack segment within the
  // J domain (0 on a straight crack), and whether the domain's particles are
  // all of the tip's material; they decide which energy drives growth
  // (growth_energy).
  double bend = 0;
  bool one_material = true;
};

// rad: where the crack bends by more than this within a one-material J
// domain, growth is driven by Irwin's (K_I^2 + K_II^2) / E' instead of J
// (growth_energy; docs/solid.md, "J after a kink").
inline constexpr double kIrwinBend = 0.5235987755982988;  // 30 deg

// J/m^2: the energy release rate that drives growth, G without the share of
// a negative K_I (a crack closed in compression): G (max(K_I, 0)^2 + K_II^2)
// / (K_I^2 + K_II^2); with mode_one_only (straight growth by symmetry) the
// K_II^2 term is left out of the numerator. G is J, or (K_I^2 + K_II^2) / E'
// where the crack bends by more than kIrwinBend within a one-material domain:
// J's domain form then misses the face term of the kink's corner, which sits
// within a fraction of a cell of the tip. A tip grows when it reaches the
// toughness.
double growth_energy(const TipResult& tip, bool mode_one_only = false);

// Whether a kinking tip's K's can set its direction: they carry J within a
// factor 10 either way, J / 10 <= (K_I^2 + K_II^2) / E' <= 10 J (growth.cpp;
// docs/solid.md, "Growth"). Otherwise the tip waits. Where growth_energy
// takes Irwin's form (a sharp kink in one material) the K's are the energy
// and there is nothing to check.
bool growth_direction_known(const TipResult& tip);

class Solver {
 public:
  explicit Solver(SolidConfig config);

  void step(double dt);
  // The step in two parts around an exchange with the fluid (the implicit
  // interface scheme, docs/architecture.md): begin_step() does P2G and every
  // load but the crack-face pressure (it needs no dt); step(dt) then finishes
  // the step begun (or does a whole one). Between them set_crack_pressure()
  // sets the pressure this step will carry, and face_response() says how the
  // faces will move under it.
  void begin_step();
  bool step_begun() const { return step_begun_; }
  // After begin_step(): per crack particle of crack c, the opening over the
  // coming step of dt under face pressures p_j is
  //   w_k + dt (rate_k + dt (acceleration_k + sum_j C_kj p_j)),
  // exactly (the explicit update is affine in its load) while no contact
  // acts and the normals turn little. rate: m/s, the faces' opening
  // velocity now; acceleration: m/s^2, from every load but the face
  // pressure; C: m/s^2 per Pa, banded, |k - j| <= band, row-major in
  // compliance[k * (2 band + 1) + (j - k + band)]. Tips: 0 (their faces
  // move together).
  // plane_rate / plane_acceleration: the crack plane's own motion (the mean
  // of its two surfaces; m/s, m/s^2 from every load but the face pressure),
  // so that the fluid can follow the crack as it moves along itself.
  struct FaceResponse {
    std::vector<double> rate, acceleration, compliance;
    std::size_t band = 0;
    std::vector<Vec2> plane_rate, plane_acceleration;
  };
  FaceResponse face_response(std::size_t c) const;
  // cfl * h / (fastest P-wave speed with the scaled densities)
  double stable_dt() const;

  double time() const { return t_; }
  std::uint64_t steps() const { return steps_; }
  std::uint64_t contacts() const { return contacts_; }  // node contacts applied so far
  double kinetic_energy() const;                        // J/m, with the scaled masses
  // J/m: elastic energy of the particles' stress, sum V sigma : C^-1 : sigma / 2
  // (of the change from the in-situ state with in_situ_reference).
  double strain_energy() const;
  // J/m: the work the in-situ shear traction has done on the faces' slip
  // since the start (in_situ_reference; 0 without): elastic energy of the
  // in-situ state that the crack's sliding released (solver_cracks.cpp).
  double in_situ_shear_work() const { return in_situ_shear_work_; }
  const SolidConfig& config() const { return config_; }
  const Grid& grid() const { return config_.grid; }
  Particles& particles() { return particles_; }
  const Particles& particles() const { return particles_; }
  const NodalFields& nodes() const { return field0_; }
  // Particle p's Cauchy stress (Pa): the stored stress, plus its region's
  // initial stress when the particles carry changes (in_situ_reference).
  Voigt total_stress(std::size_t p) const;
  std::vector<Voigt> total_stresses() const;
  // The in-situ stress at x: the initial stress of the region there (the
  // last region containing x), zero outside every region.
  Voigt in_situ_stress(const Vec2& x) const;
  // Bytes of the grid's arrays as allocated: reduced fields, velocities and
  // accelerations, P2G's per-thread accumulators (for memory reports).
  std::size_t grid_bytes() const;
  std::vector<Crack>& cracks() { return cracks_; }
  const std::vector<Crack>& cracks() const { return cracks_; }
  // The nodal fields of one side of a crack: field 1 holds the particles whose
  // line to the node crosses a crack (only near cracks).
  const NodalFields& nodes(int field) const { return field ? field1_ : field0_; }
  // Which field of `node` a point at `from` uses: 1 if the segment between
  // them crosses a crack an odd number of times, else 0.
  int field_of(const Vec2& from, const Vec2& node) const;
  // Crack-face pressure, Pa, per crack particle of crack c (a prefix of the
  // crack; the rest get 0). Optionally the fluid's stiffness -dp/dw (Pa/m)
  // and the widths (m) the pressure was computed from (both the pressure's
  // size, or empty): the faces then carry p - stiffness (w - width).
  // `offset`: the crack particle the first value belongs to (a fluid that
  // has not yet seen the particles a start tip's growth added); particles
  // without a value carry none.
  void set_crack_pressure(std::size_t c, const std::vector<double>& pressure, const std::vector<double>& stiffness = {},
                          const std::vector<double>& width = {}, std::size_t offset = 0);
  // The fluid on crack c: the arc lengths (m) from its first particle where
  // the wetted part begins (0 at a mouth) and where its front is.
  void set_crack_front(std::size_t c, double start, double end);

  // J, K_I, K_II and the kink angle at every tip, evaluated now (one pass
  // over the particles near the tips). Quasi-static J: no kinetic terms.
  std::vector<TipResult> tips() const;
  // Pa, the plane-strain modulus E' of the material at x (the region that
  // holds x, else the nearest particle's).
  double plane_strain_modulus_at(const Vec2& x) const {
    return config_.materials[material_at(x)].plane_strain_modulus();
  }
  // The tips as last evaluated by the propagation check (empty without one).
  const std::vector<TipResult>& last_tips() const { return last_tips_; }
  // Grows every tip whose J >= J_Ic by one crack particle in the maximum hoop
  // stress direction; returns the number of particles added. step() calls it
  // every check_interval steps when propagation is on.
  int propagate();
  // The end-state watches of growth (docs/stability.md, "When a run must not
  // pass silently"). A tip whose growth energy stays at or above kOverload x
  // its toughness (K at least twice K_Ic) without growing: the one that has
  // done so longest, with K / K_Ic (from the growth energy) now.
  static constexpr double kOverload = 4;
  struct Overload {
    std::size_t crack = 0;
    bool at_end = true;
    double duration = 0;  // s, since its energy first reached kOverload x toughness
    double k_ratio = 0;   // sqrt(growth energy / toughness)
  };
  std::optional<Overload> longest_overload() const;
  // A tip that could not grow because its next step would come within a
  // cell of the body's edge: the crack has run through the body.
  struct BoundaryHit {
    std::size_t crack = 0;
    bool at_end = true;
    Vec2 position = Vec2::Zero();
    double t = 0;
  };
  const std::optional<BoundaryHit>& boundary_reached() const { return boundary_reached_; }
  // Feedback damping coefficient now, 1/s.
  double feedback_alpha() const { return feedback_alpha_; }
  // The region (later wins) and so material and in-situ stress at x; -1 if none.
  int region_at(const Vec2& x) const;

  // Checkpoints (checkpoint.cpp): everything a later step reads, also between
  // begin_step() and step() (the grid's fields with it): particles, cracks,
  // nodal fields, time, step and contact counters, damping and growth state.
  // load() into a Solver built from the same config restores it bit for bit;
  // it throws std::runtime_error if the sizes do not fit that config.
  void save(StateWriter& out) const;
  void load(const StateReader& in);

 private:
  void generate_particles();
  void build_constraints();
  void find_edges();
  template <bool kCracks>
  void p2g();
  // P2G's steps, each run by every thread (transfer.cpp).
  std::array<std::size_t, 2> p2g_band(std::size_t begin, std::size_t end) const;
  template <bool kCracks>
  void p2g_scatter(std::size_t thread, std::size_t begin, std::size_t end);
  template <bool kCracks>
  void p2g_reduce(std::size_t thread);
  void edge_loads();
  void grid_update(double dt);
  template <bool kCracks>
  void g2p(double dt);
  // Cracks (solver_cracks.cpp)
  // Whether x is within 2.5 h of a crack's box (a particle-node segment is
  // at most about 2.2 h long, the uGIMP reach); inline: P2G asks it for
  // every particle.
  bool near_crack(const Vec2& x) const {
    const double margin = 2.5 * config_.grid.h;
    for (const auto& crack : cracks_) {
      if (crack.near(x, margin)) return true;
    }
    return false;
  }
  // Face loads: the in-situ traction the cut gives up (in_situ_reference) and
  // the fluid's pressure, each when asked.
  void crack_loads(bool in_situ, bool pressure);
  // Per crack particle, the part of its tributary length not yet loaded by
  // a release in progress (Fracture::release_transits): it takes that much
  // less of the face load. Set by update_releases at begin_step.
  void update_releases();
  double unloaded_length(std::size_t c, std::size_t k) const {
    return c < unloaded_.size() && k < unloaded_[c].size() ? unloaded_[c][k] : 0.0;
  }
  FaceShares face_shares(const Crack& crack, std::size_t k, int side) const;
  void spread_face_force(const Crack& crack, std::size_t k, int side, const Vec2& force);
  void implicit_face_stiffness(double dt);
  void keep_fixed(std::size_t u, int f);
  void affine_displacement();
  // After growth: the particles using a node that the new segments (each
  // from the old tip to the new) re-sort into fields take the displacement
  // gradient of their fields' nodal displacements; returns how many
  // (transfer.cpp).
  int reproject_strains(const std::vector<std::array<Vec2, 2>>& segments);
  void anchor_crack_surfaces();
  // One shear-wave transit of crack c: its length over the slowest
  // shear-wave speed (scaled density) of the materials at its tips.
  double crack_transit(std::size_t c) const;
  // Crack c's surface drift for the step begun, or nullptr if it has none
  // (no surfaces_from_material, or the crack changed since it was set).
  const std::vector<std::array<Vec2, 2>>* surface_drift(std::size_t c) const;
  void move_crack_surfaces(double dt);
  // Frictionless contact between the two fields of a node; dt = 0: on the
  // momenta after P2G; dt > 0: on the updated velocities (and accelerations).
  void contact(double dt);
  void record_faces();
  void account_in_situ_shear_work();

  // J and K at a tip, in named steps (fracture.cpp).
  struct TipFrame {
    Vec2 position, e1, e2;  // the tip, the frame's axes (x1 along the crack)
    Eigen::Matrix2d rot;    // rows e1, e2: global -> tip frame
    bool at_end = true;
    int up = 1;  // the crack surface on the frame's +x2 side
  };
  struct TipSums {
    double j = 0, m1 = 0, m2 = 0;  // J and the interaction integrals
    bool one_material = true;      // all particles in the domain are of the tip's material
  };
  static TipFrame tip_frame(const Crack& crack, bool at_end);
  std::size_t material_at(const Vec2& x) const;
  TipSums domain_integrals(const Crack& crack, const TipFrame& frame, double ri, double ro, std::size_t material) const;
  TipSums face_work(const Crack& crack, const TipFrame& frame, double ri, double ro, std::size_t material) const;
  TipResult evaluate_tip(std::size_t c, bool at_end) const;
  std::string runaway_report(std::size_t p, double dt) const;
  void update_feedback(double dt);

  SolidConfig config_;
  std::vector<TipResult> last_tips_;
  std::vector<std::array<double, 2>> grown_at_;  // s, last growth of each crack's (start, end) tip
  // The release of each crack's (start, end) tip's last growth step
  // (Fracture::release_transits): from t0 over tau (s), the part of the
  // crack within `length` (m) of the tip.
  struct Release {
    double t0 = 0, tau = 0, length = 0;
  };
  std::vector<std::array<Release, 2>> releases_;
  std::vector<std::vector<double>> unloaded_;  // m, per crack and crack particle (update_releases)
  // s, when the fluid front came within the end tip's allowed lag (-inf: not
  // since its last growth); Fracture::front_settle_transits.
  std::vector<std::array<double, 2>> front_arrived_at_;  // s, per crack (start, end) tip
  double anchored_at_ = -1;                              // s, when anchor_crack_surfaces last ran (-1: not yet)
  // Per crack and crack particle, the drift velocity (m/s) of its surface
  // above and below toward the material's opening over the step begun
  // (anchor_crack_surfaces; empty without surfaces_from_material).
  std::vector<std::vector<std::array<Vec2, 2>>> surface_drift_;
  double feedback_alpha_ = 0;
  double in_situ_shear_work_ = 0;
  std::vector<std::array<double, 2>> overloaded_since_;  // s, per crack (start, end) tip; inf: not overloaded
  std::optional<BoundaryHit> boundary_reached_;          // J/m (in_situ_shear_work)
  std::vector<std::vector<Vec2>> faces_before_;          // per crack particle, above - below at the step's start
  double total_mass_ = 0;
  Vec2 body_lo_ = Vec2::Zero(), body_hi_ = Vec2::Zero();  // bounding box of the particles' domains
  Particles particles_;
  // The grid's two velocity fields (CRAMP): field 0 holds every node's
  // material on one side of a crack (and everywhere away from cracks), field
  // 1 a node's material on the other side of a crack; sized only with cracks.
  NodalFields field0_;
  NodalFields field1_;
  std::vector<Crack> cracks_;
  // P2G's per-thread accumulators: one cache line per node and field
  // (index node * fields + field), over the span of nodes the thread's
  // particles reach this step; the spans are reduced into field0_ / field1_
  // and zeroed as they are (all zero between P2Gs).
  struct alignas(64) NodeAcc {
    Vec2 p = Vec2::Zero();  // momentum
    Vec2 f = Vec2::Zero();  // force
    Vec2 u = Vec2::Zero();  // mass-weighted displacement (cracks)
    double m = 0;           // mass
  };
  std::vector<std::vector<NodeAcc>> thread_acc_;
  std::vector<std::array<std::size_t, 2>> thread_span_;       // [first, last) node
  std::vector<std::array<std::size_t, 2>> thread_side_span_;  // [first, last) node with field-1 entries
  std::vector<std::vector<int>> thread_active_;
  // Per particle, cracks only, set by P2G for G2P: bit 15 = near a crack,
  // bit 3 b + a = node (a, b) of its 3 x 3 stencil is in field 1.
  std::vector<std::uint16_t> stencil_fields_;
  // Per field and node: sum of S m (u + grad u (x_i - x_p)) over the particles
  // near a crack (affine_displacement), and the nodes it wrote.
  std::array<std::vector<Vec2>, 2> affine_;
  std::vector<std::size_t> affine_touched_;
  // The P2G (its serial number, transfer_) that last gave each node mass: a
  // node whose touched_in_ differs from transfer_ is empty this step.
  std::vector<std::uint32_t> touched_in_;
  std::vector<int> active_;
  std::vector<Vec2> velocity_[2];      // new nodal velocity, per field and node
  std::vector<Vec2> acceleration_[2];  // nodal acceleration, per field and node
  std::vector<std::uint32_t> edges_[4];
  std::vector<double> lambda_, shear_, p_modulus_, density_;  // per material, density scaled
  std::uint32_t transfer_ = 0;                                // serial number of the current P2G (touched_in_)
  bool step_begun_ = false;                                   // begin_step() ran; step() finishes it
  double t_ = 0;
  std::uint64_t steps_ = 0;
  std::vector<int> face_slot_;  // scratch of implicit_face_stiffness: node -> entry, -1
  std::uint64_t contacts_ = 0;
  double min_mass_ = 0;     // nodes lighter than this get zero velocity
  double sliver_mass_ = 0;  // rho h^2 / 64 of the lightest material: lighter fields take less face load
};

}  // namespace hfmpm::solid::mpm
