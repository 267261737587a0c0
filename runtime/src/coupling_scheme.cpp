#include "hfmpm/runtime/coupling_scheme.hpp"

#include <algorithm>

namespace hfmpm::coupling {

CouplingScheme::CouplingScheme(scene::Coupling::Scheme scheme, std::uint32_t exchange_interval, bool has_peer)
    : scheme_(scheme), interval_(std::max(1u, exchange_interval)), has_peer_(has_peer) {}

CouplingScheme CouplingScheme::of(const scene::Scene& scene) {
  return CouplingScheme(scene.coupling().scheme(), scene.coupling().exchange_interval(), scene.has_fluid());
}

bool CouplingScheme::waits_first(protocol::Role role) const {
  // Sequential schemes: one side waits for the other's frame of the same
  // step before it steps. Gauss-Seidel: the fluid waits for the solid's new
  // crack. Implicit: the solid waits for the pressure the fluid solved over
  // the step it is about to finish.
  return (scheme_ == scene::Coupling::GAUSS_SEIDEL && role == protocol::FLUID) ||
         (scheme_ == scene::Coupling::IMPLICIT && role == protocol::SOLID);
}

std::vector<CouplingScheme::Action> CouplingScheme::initial_exchange(protocol::Role role) const {
  if (!has_peer_) return {};
  // The solid goes first; the fluid builds its grid from the crack before it can answer.
  if (role == protocol::SOLID) return {{Action::Publish, 0}, {Action::Consume, 0}};
  return {{Action::Consume, 0}, {Action::Publish, 0}};
}

std::vector<CouplingScheme::Action> CouplingScheme::block(protocol::Role role, std::uint64_t first_step,
                                                          std::uint64_t num_steps) const {
  std::vector<Action> actions;
  actions.reserve(num_steps * 3 / std::max(1u, exchange_interval()) + num_steps);
  const bool first = has_peer_ && waits_first(role);
  for (std::uint64_t step = first_step; step < first_step + num_steps; ++step) {
    if (first && step % interval_ == 0) actions.push_back({Action::Consume, step + interval_});
    actions.push_back({Action::Advance, step + 1});
    if (has_peer_ && (step + 1) % interval_ == 0) {
      actions.push_back({Action::Publish, step + 1});
      if (!first) actions.push_back({Action::Consume, step + 1});
    }
  }
  return actions;
}

}  // namespace hfmpm::coupling
