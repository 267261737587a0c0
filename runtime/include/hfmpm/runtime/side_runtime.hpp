// The generic side of the protocol: handshake, data plane, step loop,
// heartbeat, errors and shutdown. A side (stand-in or real physics) supplies a
// SideModel; everything about sockets and messages lives here, so any model
// speaks exactly the same protocol (docs/protocol.md).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hfmpm/exchange.hpp"
#include "hfmpm/proto/envelope.hpp"
#include "hfmpm/runtime/curve.hpp"
#include "hfmpm/runtime/transport.hpp"
#include "hfmpm/scene.pb.h"
#include "hfmpm/state_archive.hpp"

namespace hfmpm::coupling {

// A bad value in the scene or on the command line, found by a side.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Listed in Hello by a side that writes checkpoints and restarts from them.
inline constexpr const char* kCheckpointCapability = "checkpoint";

// What a side's physics must provide. Called from one thread only.
class SideModel {
 public:
  virtual ~SideModel() = default;
  // Once, with the validated scene; throws InputError for anything it cannot run.
  virtual void setup(const scene::Scene& scene, const std::string& output_dir) = 0;
  virtual double stable_dt() const = 0;  // s; +inf if unlimited
  // What sets stable_dt() now, in a few words (run.json names the term that limited the step).
  virtual std::string stable_dt_limit() const { return {}; }
  virtual void advance(double dt) = 0;  // one explicit step
  // Fill the payload of the frame this side sends (crack for a solid, fluid for a fluid).
  virtual void publish(protocol::DataFrame& frame) = 0;
  // Apply a frame from the peer; throws proto::ProtocolError if it is inconsistent.
  virtual void receive(const protocol::DataFrame& frame) = 0;
  virtual SideDiagnostics diagnostics() const = 0;
  // Every notice raised so far (a state the physics forbids or a run must not
  // pass silently, docs/protocol.md "Notices"); the runtime sends each code
  // once, in the report of the command that first returns it.
  virtual std::vector<Notice> notices() const { return {}; }
  // Non-empty once the side has nothing more to do (a crack reached the
  // body's edge): its reports then say DONE with this reason. The side still
  // answers further commands.
  virtual std::string done_reason() const { return {}; }
  virtual void write_output(std::uint64_t /*frame*/, double /*t*/) {}
  virtual void finish() {}
  // Checkpoints (docs/reliability.md, "Checkpoint and restart"). A model that
  // can write its whole state returns true here; the runtime then lists the
  // capability "checkpoint" in Hello, and the coupler asks only such sides for
  // checkpoints or a restart. save_checkpoint writes the state after the
  // block just done to `path` atomically (write, fsync, rename), stamped with
  // `stamp`; load_checkpoint, called after setup() instead of the step-0
  // exchange, restores it and refuses a file whose stamp differs.
  virtual bool can_checkpoint() const { return false; }
  // Called before setup() when the run continues from a checkpoint (load_checkpoint
  // follows setup): setup() must then leave the files a restart continues alone.
  virtual void will_restart() {}
  virtual void save_checkpoint(const std::string& /*path*/, const CheckpointStamp& /*stamp*/) {
    throw InputError("this side cannot write checkpoints");
  }
  virtual void load_checkpoint(const std::string& /*path*/, const CheckpointStamp& /*stamp*/) {
    throw InputError("this side cannot restart from a checkpoint");
  }
};

// Test hook: make a side fail on purpose at a step ("KIND@STEP").
struct Fault {
  enum class Kind { None, Exit, Crash, Hang, Freeze, Garbage, NaN };
  Kind kind = Kind::None;
  std::uint64_t step = 0;
  static Fault parse(const std::string& text);  // throws InputError
};

struct SideOptions {
  protocol::Role role = protocol::ROLE_UNSPECIFIED;
  std::string control_endpoint;  // the coupler's control socket
  std::string implementation;    // e.g. "hfmpm-prescribed-solid"
  std::string implementation_version = proto::kProgramVersion;
  std::vector<std::string> capabilities;
  std::string advertise_host;     // tcp: host the peer can reach this side at
  std::string output_dir;         // overrides the coupler's output_dir
  double welcome_timeout_s = 60;  // the coupler must answer Hello within this
  // Hello is sent again every hello_repeat_s until the coupler answers: a
  // ZeroMQ ROUTER refuses a connection whose routing id a peer it has not yet
  // seen leave still holds, and the Hello sent on it is lost (the coupler
  // ignores a repeated Hello from a side that has joined).
  double hello_repeat_s = 1;
  int extra_hellos = 0;                                      // test hook: send Hello this many more times at once
  std::shared_ptr<Transport> transport;                      // shared (in-process sides); ZeroMQ's if null
  std::uint32_t protocol_version = proto::kProtocolVersion;  // tests claim others
  std::uint32_t scene_schema_version = proto::kSceneSchemaVersion;  // tests claim others
  Fault fault;
  // tcp with CURVE (--keys FILE, the sides' key file): the control and
  // heartbeat sockets authenticate to the coupler, and the data plane between
  // the sides is a CURVE server/client pair admitting only this key.
  std::optional<CurveKeys> curve;
};

// Exit codes of a side.
// kSideStoppedOnError: told to stop by a Shutdown with error = true (the run
// failed elsewhere); this side itself did nothing wrong.
enum SideExit : int {
  kSideOk = 0,
  kSideFailed = 1,
  kSideInput = 2,
  kSideProtocol = 3,
  kSideCouplerLost = 4,
  kSideStoppedOnError = 5
};

// Runs the side until Shutdown or failure; never throws. Returns a SideExit.
int run_side(SideModel& model, const SideOptions& options);

// A thin main: parses --connect, --out, --advertise-host, --fault,
// --protocol-version, --welcome-timeout, --help; runs the model.
int side_main(int argc, char** argv, protocol::Role role, const std::string& implementation,
              const std::vector<std::string>& capabilities,
              const std::function<std::unique_ptr<SideModel>()>& make_model);

}  // namespace hfmpm::coupling
