// The coupler: the control plane of a run. It launches (or waits for) the
// sides, handshakes, owns the clock and dt, schedules steps, collects reports
// and heartbeats, writes history.csv and the run manifest, and stops
// everything on any failure. It has no physics.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hfmpm/coupling/checkpoint.hpp"
#include "hfmpm/runtime/side_runtime.hpp"
#include "hfmpm/runtime/transport.hpp"
#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling {

// Builds a side model for the in-process transport.
using ModelFactory = std::function<std::unique_ptr<SideModel>(protocol::Role role, const scene::Scene& scene)>;

struct RunOptions {
  std::string output_dir = "hfmpm-out";
  // true: start the sides (processes, or threads with INPROC). false: bind
  // `bind_endpoint` and wait for sides started by hand (--connect).
  bool launch = true;
  std::string bind_endpoint;   // join mode: e.g. tcp://0.0.0.0:5555 or ipc:///tmp/x
  std::string executable_dir;  // where the side programs are; default: beside this program
  std::string solid_program;   // override the solid program (another implementation)
  std::string fluid_program;
  ModelFactory inproc_factory;  // required for INPROC
  // What the coupler and in-process sides talk through: null for ZeroMQ (a
  // context of the run's own), or another Transport shared with the side
  // threads, e.g. a MemoryTransport (only with coupling.transport INPROC).
  std::shared_ptr<Transport> transport;
  bool progress = true;    // progress line on stderr
  std::string scene_path;  // for the manifest
  std::vector<std::string> overrides;
  std::function<void(const std::string&)> on_bound;  // told the bound control endpoint
  // A stop request (install_stop_signals): 0, or the signal that asked the
  // run to stop. Read before each control round and while waiting for the
  // sides to join; the run then ends "interrupted".
  const std::atomic<int>* stop_request = nullptr;
  // tcp security (docs/reliability.md, "Who may join"). By default a tcp
  // control endpoint is CURVE-authenticated: 'run' makes keys for the run and
  // hands them to the sides it starts; join mode needs the coupler's key file
  // (hfmpm keygen). insecure_tcp: plain tcp, for sides that cannot do CURVE.
  std::string keys_file;
  bool insecure_tcp = false;
  // Continue from this checkpoint (hfmpm run --restart): output_dir must be its
  // run directory, and the scene its scene (check_restart_scene).
  std::shared_ptr<const RestartPoint> restart;
  // The continued run's status as the restart found it (run.json's
  // "previous_status"), e.g. "stopped without finishing (coupler killed?)".
  std::string previous_status;
};

struct RunSummary {
  bool ok = false;
  std::string error;       // names the failed side and step
  int interrupted_by = 0;  // the signal that stopped the run (error says so), or 0
  std::uint64_t steps = 0;
  std::uint64_t commands = 0;
  double t = 0;
  double wall_s = 0;           // whole run
  double stepping_wall_s = 0;  // from the first StepCommand to the last report
  double solid_compute_s = 0, fluid_compute_s = 0;
  double solid_exchange_s = 0, fluid_exchange_s = 0;
  bool sides_in_sequence = false;  // Gauss-Seidel: the fluid steps after the solid, not beside it
  // ok and non-empty: a side had nothing more to do and the run stopped
  // before its end time, e.g. "the crack reached the boundary: ..." (run.json "stopped").
  std::string stopped;
  // The end states the run passed through (run.json "warnings"), one per code.
  std::vector<std::string> warnings;
  // stepping_wall_s minus the sides' compute time, per step: minus the slower
  // side's when they step side by side (Jacobi), minus both when in sequence.
  double overhead_per_step_us() const;
};

// Runs a validated scene. Never throws for run failures: they are in the summary.
RunSummary run_coupled(const scene::Scene& scene, const RunOptions& options);

// Every number a side reports (a StepReport or a Ready: t, stable_dt,
// compute_s, exchange_s and every diagnostic) must be finite; stable_dt may
// also be +inf ("no limit", protocol.proto). Returns the fields that break
// it with their values ("diagnostics.inlet_pressure = nan, compute_s =
// inf"), or "" if none does. The coupler fails the run with them, naming the
// side and the step, before the report reaches a history row (the rows so far
// are kept).
std::string non_finite_report_fields(const google::protobuf::Message& report);

}  // namespace hfmpm::coupling
