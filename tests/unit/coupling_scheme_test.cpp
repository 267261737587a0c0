// The coupling scheme (runtime/include/hfmpm/runtime/coupling_scheme.hpp)
// without sockets: the order of one side's steps, sends and waits under
// Jacobi, Gauss-Seidel and the implicit interface scheme, with an exchange
// interval; and two sides run against each other through plain queues, step
// by step, to show which frame each side has when it steps (and that no
// order deadlocks).
#include "hfmpm/runtime/coupling_scheme.hpp"

#include <gtest/gtest.h>

#include <deque>
#include <string>
#include <vector>

namespace {

using hfmpm::coupling::CouplingScheme;
using Action = CouplingScheme::Action;
namespace scene = hfmpm::scene;
namespace protocol = hfmpm::protocol;

constexpr auto kAdvance = Action::Advance;
constexpr auto kPublish = Action::Publish;
constexpr auto kConsume = Action::Consume;

TEST(CouplingScheme, JacobiBothSidesStepThenExchange) {
  const CouplingScheme jacobi(scene::Coupling::JACOBI, 1, true);
  const std::vector<Action> expected{{kAdvance, 1}, {kPublish, 1}, {kConsume, 1},
                                     {kAdvance, 2}, {kPublish, 2}, {kConsume, 2}};
  EXPECT_EQ(jacobi.block(protocol::SOLID, 0, 2), expected);
  EXPECT_EQ(jacobi.block(protocol::FLUID, 0, 2), expected);
  EXPECT_FALSE(jacobi.sides_in_sequence());
}

TEST(CouplingScheme, GaussSeidelFluidWaitsForTheCrackOfTheStepItTakes) {
  const CouplingScheme gs(scene::Coupling::GAUSS_SEIDEL, 1, true);
  EXPECT_EQ(
      gs.block(protocol::SOLID, 4, 2),
      (std::vector<Action>{{kAdvance, 5}, {kPublish, 5}, {kConsume, 5}, {kAdvance, 6}, {kPublish, 6}, {kConsume, 6}}));
  EXPECT_EQ(
      gs.block(protocol::FLUID, 4, 2),
      (std::vector<Action>{{kConsume, 5}, {kAdvance, 5}, {kPublish, 5}, {kConsume, 6}, {kAdvance, 6}, {kPublish, 6}}));
  EXPECT_TRUE(gs.waits_first(protocol::FLUID));
  EXPECT_FALSE(gs.waits_first(protocol::SOLID));
  EXPECT_TRUE(gs.sides_in_sequence());
}

TEST(CouplingScheme, ImplicitSolidWaitsForThePressureOfTheStepItFinishes) {
  const CouplingScheme implicit(scene::Coupling::IMPLICIT, 1, true);
  EXPECT_EQ(implicit.block(protocol::SOLID, 0, 1), (std::vector<Action>{{kConsume, 1}, {kAdvance, 1}, {kPublish, 1}}));
  EXPECT_EQ(implicit.block(protocol::FLUID, 0, 1), (std::vector<Action>{{kAdvance, 1}, {kPublish, 1}, {kConsume, 1}}));
  EXPECT_TRUE(implicit.sides_in_sequence());
}

TEST(CouplingScheme, AnIntervalExchangesAtTheWindowsEnds) {
  const CouplingScheme gs(scene::Coupling::GAUSS_SEIDEL, 3, true);
  EXPECT_EQ(gs.exchange_interval(), 3u);
  EXPECT_EQ(gs.block(protocol::SOLID, 3, 6), (std::vector<Action>{{kAdvance, 4},
                                                                  {kAdvance, 5},
                                                                  {kAdvance, 6},
                                                                  {kPublish, 6},
                                                                  {kConsume, 6},
                                                                  {kAdvance, 7},
                                                                  {kAdvance, 8},
                                                                  {kAdvance, 9},
                                                                  {kPublish, 9},
                                                                  {kConsume, 9}}));
  EXPECT_EQ(gs.block(protocol::FLUID, 3, 6), (std::vector<Action>{{kConsume, 6},
                                                                  {kAdvance, 4},
                                                                  {kAdvance, 5},
                                                                  {kAdvance, 6},
                                                                  {kPublish, 6},
                                                                  {kConsume, 9},
                                                                  {kAdvance, 7},
                                                                  {kAdvance, 8},
                                                                  {kAdvance, 9},
                                                                  {kPublish, 9}}));
}

TEST(CouplingScheme, WithoutAPeerTheSideOnlySteps) {
  const CouplingScheme dry(scene::Coupling::GAUSS_SEIDEL, 5, false);
  EXPECT_EQ(dry.exchange_interval(), 1u);
  EXPECT_TRUE(dry.initial_exchange(protocol::SOLID).empty());
  EXPECT_EQ(dry.block(protocol::SOLID, 0, 2), (std::vector<Action>{{kAdvance, 1}, {kAdvance, 2}}));
}

TEST(CouplingScheme, TheSolidGoesFirstAtStepZero) {
  const CouplingScheme gs(scene::Coupling::GAUSS_SEIDEL, 1, true);
  EXPECT_EQ(gs.initial_exchange(protocol::SOLID), (std::vector<Action>{{kPublish, 0}, {kConsume, 0}}));
  EXPECT_EQ(gs.initial_exchange(protocol::FLUID), (std::vector<Action>{{kConsume, 0}, {kPublish, 0}}));
}

TEST(CouplingScheme, OfASceneHasAPeerOnlyWithAFluid) {
  scene::Scene s;
  s.mutable_coupling()->set_scheme(scene::Coupling::JACOBI);
  s.mutable_coupling()->set_exchange_interval(4);
  EXPECT_FALSE(CouplingScheme::of(s).has_peer());
  EXPECT_EQ(CouplingScheme::of(s).exchange_interval(), 1u);
  s.mutable_fluid();
  EXPECT_TRUE(CouplingScheme::of(s).has_peer());
  EXPECT_EQ(CouplingScheme::of(s).exchange_interval(), 4u);
}

// Two sides run their actions against each other: a side may take its next
// action unless it is a Consume whose frame has not been sent. Each Advance
// records the step of the peer's newest frame the side has received.
struct Trace {
  std::vector<std::uint64_t> solid_saw, fluid_saw;  // per step taken
};

Trace run_both(const CouplingScheme& scheme, std::uint64_t blocks, std::uint64_t steps_per_block) {
  struct Side {
    protocol::Role role = protocol::ROLE_UNSPECIFIED;
    std::vector<Action> actions;
    std::size_t next = 0;
    std::deque<std::uint64_t> inbox;  // frames sent by the peer, by step
    std::uint64_t seen = 0;           // the newest frame consumed
    std::vector<std::uint64_t> saw;
  };
  Side solid, fluid;
  solid.role = protocol::SOLID;
  solid.actions = scheme.initial_exchange(protocol::SOLID);
  fluid.role = protocol::FLUID;
  fluid.actions = scheme.initial_exchange(protocol::FLUID);
  for (std::uint64_t b = 0; b < blocks; ++b) {
    for (Side* side : {&solid, &fluid}) {
      const auto block = scheme.block(side->role, b * steps_per_block, steps_per_block);
      side->actions.insert(side->actions.end(), block.begin(), block.end());
    }
  }
  auto take = [](Side& side, Side& peer) {
    if (side.next == side.actions.size()) return false;
    const Action action = side.actions[side.next];
    switch (action.kind) {
      case Action::Consume:
        if (side.inbox.empty()) return false;  // waits
        EXPECT_EQ(side.inbox.front(), action.step) << "frames arrive in order, one per exchange";
        side.seen = side.inbox.front();
        side.inbox.pop_front();
        break;
      case Action::Publish:
        peer.inbox.push_back(action.step);
        break;
      case Action::Advance:
        side.saw.push_back(side.seen);
        break;
    }
    ++side.next;
    return true;
  };
  while (take(solid, fluid) || take(fluid, solid)) {
  }
  EXPECT_EQ(solid.next, solid.actions.size()) << "the solid is stuck: the scheme deadlocks";
  EXPECT_EQ(fluid.next, fluid.actions.size()) << "the fluid is stuck: the scheme deadlocks";
  return {solid.saw, fluid.saw};
}

TEST(CouplingScheme, GaussSeidelFluidStepsOnTheNewCrackTheSolidOnTheOldPressure) {
  const auto trace = run_both(CouplingScheme(scene::Coupling::GAUSS_SEIDEL, 1, true), 3, 4);
  ASSERT_EQ(trace.solid_saw.size(), 12u);
  ASSERT_EQ(trace.fluid_saw.size(), 12u);
  for (std::uint64_t k = 0; k < 12; ++k) {
    EXPECT_EQ(trace.solid_saw[k], k) << "solid step " << k + 1 << " under the pressure of step " << k;
    EXPECT_EQ(trace.fluid_saw[k], k + 1) << "fluid step " << k + 1 << " on the crack of step " << k + 1;
  }
}

TEST(CouplingScheme, JacobiBothSidesStepOnTheOldState) {
  const auto trace = run_both(CouplingScheme(scene::Coupling::JACOBI, 2, true), 2, 4);
  // Windows of 2 steps: steps 1-2 on the frames of step 0, steps 3-4 on step 2, ...
  for (std::uint64_t k = 0; k < 8; ++k) {
    EXPECT_EQ(trace.solid_saw[k], k / 2 * 2);
    EXPECT_EQ(trace.fluid_saw[k], k / 2 * 2);
  }
}

TEST(CouplingScheme, ImplicitSolidFinishesItsStepUnderTheFluidsNewPressure) {
  const auto trace = run_both(CouplingScheme(scene::Coupling::IMPLICIT, 1, true), 2, 5);
  for (std::uint64_t k = 0; k < 10; ++k) {
    EXPECT_EQ(trace.solid_saw[k], k + 1);
    EXPECT_EQ(trace.fluid_saw[k], k);
  }
}

}  // namespace
