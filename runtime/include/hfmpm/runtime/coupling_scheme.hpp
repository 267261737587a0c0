// The coupling scheme: in which order a side steps and exchanges frames with
// its peer (docs/architecture.md, section 5). One object answers it for the
// side runtime (the order of its steps, sends and waits) and the coupler
// (the exchange window a command must be a multiple of, whether the sides
// step in sequence). No sockets, no physics: unit-tested on its own.
//
// Per exchange window from step k to k+I (I = the exchange interval):
//   Jacobi:       both: advance I steps -> send own frame of k+I -> wait for the peer's of k+I
//   Gauss-Seidel: solid as Jacobi; fluid: wait for C(k+I) -> advance I steps -> send F(k+I)
//   Implicit:     fluid as Jacobi; solid: wait for F(k+I) -> advance -> send C(k+I)   (I = 1)
// and before the first step (step 0): the solid sends, then waits; the fluid
// waits (it builds its grid from the crack), then sends.
#pragma once

#include <cstdint>
#include <vector>

#include "hfmpm/protocol.pb.h"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

class CouplingScheme {
 public:
  struct Action {
    enum Kind { Advance, Publish, Consume };
    Kind kind;
    // Advance: the step it reaches; Publish: the step of the frame sent;
    // Consume: the step of the peer's frame waited for.
    std::uint64_t step;
    bool operator==(const Action&) const = default;
  };

  // `has_peer`: a data plane to exchange on (false in a dry run: the solid alone).
  CouplingScheme(scene::Coupling::Scheme scheme, std::uint32_t exchange_interval, bool has_peer);
  // The scheme of a validated scene, as the coupler sees it (a peer if the scene has a fluid).
  static CouplingScheme of(const scene::Scene& scene);

  scene::Coupling::Scheme scheme() const { return scheme_; }
  bool has_peer() const { return has_peer_; }
  // Steps between exchanges (1 without a peer): every command is a multiple of it.
  std::uint32_t exchange_interval() const { return has_peer_ ? interval_ : 1; }
  // Does `role` wait for the peer's frame of a window before it steps it?
  bool waits_first(protocol::Role role) const;
  // One side steps after the other (Gauss-Seidel, implicit), not beside it (Jacobi).
  bool sides_in_sequence() const { return scheme_ != scene::Coupling::JACOBI; }

  // What `role` does at the step-0 exchange (nothing without a peer).
  std::vector<Action> initial_exchange(protocol::Role role) const;
  // What `role` does for a command of `num_steps` steps from `first_step`.
  std::vector<Action> block(protocol::Role role, std::uint64_t first_step, std::uint64_t num_steps) const;

 private:
  scene::Coupling::Scheme scheme_;
  std::uint32_t interval_;
  bool has_peer_;
};

}  // namespace hfmpm::coupling
