// The coupler and both sides in one process, through the in-memory transport
// (runtime/include/hfmpm/runtime/memory_transport.hpp): no sockets, no
// ZeroMQ. A small KGD with the MPM solid and the MPM fluid, and the stand-ins
// under each scheme, give the same history as the same runs through ZeroMQ
// (inproc: the same threads, over sockets).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "coupled_support.hpp"
#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/runtime/memory_transport.hpp"
#include "mpm_fluid_side.hpp"
#include "mpm_solid_side.hpp"
#include "prescribed_fluid_side.hpp"
#include "prescribed_solid_side.hpp"
#include "solid_scene_rules.hpp"
#include "test_support.hpp"

namespace {

using namespace hfmpm;
using namespace hfmpm::test;

std::unique_ptr<coupling::SideModel> make_side(protocol::Role role, const scene::Scene& scene) {
  if (role == protocol::SOLID) {
    return scene.solid().has_mpm() ? solid::make_mpm_solid_side() : solid::make_prescribed_solid_side();
  }
  return scene.fluid().has_mpm() ? fluid::make_mpm_fluid_side() : fluid::make_prescribed_fluid_side();
}

// Runs `scene` with its sides as threads; `transport` null: ZeroMQ.
coupling::RunSummary run_in_process(const scene::Scene& scene, const std::string& out,
                                    std::shared_ptr<coupling::Transport> transport) {
  coupling::RunOptions options;
  options.output_dir = out;
  options.progress = false;
  options.inproc_factory = make_side;
  options.transport = std::move(transport);
  return coupling::run_coupled(scene, options);
}

const coupling::SceneRules& rules() {
  static const coupling::SceneRules both{solid::scene_rules(), fluid::scene_rules()};
  return both;
}

// scenarios/kgd-viscosity-ci.scene cut to its first 0.8 s (a history row
// every 0.16 s) at the 5-s run's step (kKgdViscosityCiMethod), as threads:
// long enough for the crack to grow (the 5-s run's is 0.1544 m at 0.25 and
// 0.5 s, one growth step past the notch, and 0.1718 m at 0.75 s).
scene::Scene small_kgd() {
  std::vector<std::string> overrides{"time.end_s=0.8", "output.interval_s=0.16", "output.hdf5=false",
                                     "coupling.transport=INPROC"};
  overrides.insert(overrides.end(), kKgdViscosityCiMethod.begin(), kKgdViscosityCiMethod.end());
  return coupling::load_scene(source("scenarios/kgd-viscosity-ci.scene"), rules(), overrides);
}

// The keys the tests that cut kgd-viscosity-ci short set
// (kKgdViscosityCiMethod) are those its 5-s run derives, with their values.
TEST(MemoryTransport, ShortKgdRunsSetThe5sRunsDerivedMethod) {
  std::vector<method::Setting> derived;
  coupling::load_scene(source("scenarios/kgd-viscosity-ci.scene"), rules(), {}, &derived);
  for (const auto& assignment : kKgdViscosityCiMethod) {
    const auto key = assignment.substr(0, assignment.find('='));
    const auto found = std::find_if(derived.begin(), derived.end(), [&](const auto& s) { return s.key == key; });
    ASSERT_NE(found, derived.end()) << key << " is not derived";
    EXPECT_EQ(found->key + "=" + found->value, assignment);
  }
}

TEST(MemoryTransport, KgdOfTheMpmSolidAndFluidRunsInOneProcessAsOverZeroMq) {
  const auto scene = small_kgd();
  const auto memory_out = scratch_dir("memory-kgd");
  const auto memory = std::make_shared<coupling::MemoryTransport>();
  const auto in_memory = run_in_process(scene, memory_out, memory);
  ASSERT_TRUE(in_memory.ok) << in_memory.error << "\n" << read_file(memory_out + "/coupler.log");
  EXPECT_NEAR(in_memory.t, 0.8, 0.01);
  // Every message went through the queues: Hello, Welcome, frames, reports, heartbeats.
  EXPECT_GT(memory->messages(), 2 * in_memory.steps);
  const auto zmq_out = scratch_dir("memory-kgd-zmq");
  const auto over_zmq = run_in_process(scene, zmq_out, nullptr);
  ASSERT_TRUE(over_zmq.ok) << over_zmq.error;
  EXPECT_EQ(in_memory.steps, over_zmq.steps);
  EXPECT_EQ(in_memory.t, over_zmq.t);
  const Csv a = read_csv(memory_out + "/history.csv"), b = read_csv(zmq_out + "/history.csv");
  ASSERT_GE(a.rows.size(), 5u);
  expect_same_history(a, b);
  // The crack grew and the fluid followed it: a coupled run, not a dry one.
  EXPECT_GT(a.values("crack_length_m").back(), a.values("crack_length_m").front());
  EXPECT_GT(a.values("fluid_volume_m2").back(), a.values("fluid_volume_m2").front());
  EXPECT_EQ(json_string(read_file(memory_out + "/run.json"), "status"), "completed");
}

TEST(MemoryTransport, StandInsUnderEachSchemeAndIntervalAsOverZeroMq) {
  for (const std::string scheme : {"JACOBI", "GAUSS_SEIDEL"}) {
    for (const std::string interval : {"1", "3"}) {
      SCOPED_TRACE(scheme + ", exchange_interval " + interval);
      const auto scene = coupling::parse_scene(
          prescribed_scene(0.05), "prescribed", rules(),
          {"coupling.transport=INPROC", "coupling.scheme=" + scheme, "coupling.exchange_interval=" + interval});
      const auto memory_out = scratch_dir("memory-standins-" + scheme + interval);
      const auto zmq_out = scratch_dir("memory-standins-zmq-" + scheme + interval);
      const auto in_memory = run_in_process(scene, memory_out, std::make_shared<coupling::MemoryTransport>());
      ASSERT_TRUE(in_memory.ok) << in_memory.error;
      const auto over_zmq = run_in_process(scene, zmq_out, nullptr);
      ASSERT_TRUE(over_zmq.ok) << over_zmq.error;
      EXPECT_EQ(in_memory.steps, over_zmq.steps);
      expect_same_history(read_csv(memory_out + "/history.csv"), read_csv(zmq_out + "/history.csv"));
    }
  }
}

TEST(MemoryTransport, IsOnlyForSidesAsThreads) {
  const auto scene = coupling::parse_scene(prescribed_scene(0.05), "prescribed", rules(), {"coupling.transport=IPC"});
  const auto out = scratch_dir("memory-not-inproc");
  const auto summary = run_in_process(scene, out, std::make_shared<coupling::MemoryTransport>());
  EXPECT_FALSE(summary.ok);
  EXPECT_NE(summary.error.find("coupling.transport: INPROC"), std::string::npos) << summary.error;
}

}  // namespace
