#include "messages.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace hfmpm::reliability {
namespace {

double weird_double(Rng& rng) {
  static const std::vector<double> special{0.0,
                                           -0.0,
                                           1e-300,
                                           -1.0,
                                           1e300,
                                           std::numeric_limits<double>::infinity(),
                                           -std::numeric_limits<double>::infinity(),
                                           std::numeric_limits<double>::quiet_NaN(),
                                           std::numeric_limits<double>::denorm_min(),
                                           std::numeric_limits<double>::max()};
  return rng.chance(0.7) ? rng.uniform(-1e3, 1e3) * std::pow(10.0, rng.uniform(-8, 8)) : rng.pick(special);
}

std::string some_text(Rng& rng) {
  static const std::vector<std::string> texts{"",
                                              "x",
                                              "solid",
                                              "fluid",
                                              "protocol",
                                              "\x01\x02\xff",
                                              "step 3",
                                              std::string(300, 'a'),
                                              "ipc:///nonexistent/x",
                                              "tcp://127.0.0.1:1"};
  if (rng.chance(0.8)) return rng.pick(texts);
  // Random ASCII, control characters included (invalid UTF-8 comes from the byte mutations).
  std::string text = rng.bytes(rng.between(0, 64));
  for (auto& c : text) c = static_cast<char>(c & 0x7f);
  return text;
}

protocol::Role some_role(Rng& rng) { return static_cast<protocol::Role>(rng.between(0, 4)); }

void fill_diagnostics(Rng& rng, protocol::Diagnostics* d) {
  d->set_kinetic_energy(weird_double(rng));
  d->set_crack_length(weird_double(rng));
  d->set_mouth_opening(weird_double(rng));
  d->set_inlet_pressure(weird_double(rng));
  d->set_fluid_volume(weird_double(rng));
  d->set_crack_particles(static_cast<std::uint32_t>(rng.between(0, 200)));
}

}  // namespace

protocol::Envelope next_command(Rng& rng, const MessageContext& context) {
  protocol::Envelope envelope;
  auto* command = envelope.mutable_step_command();
  command->set_first_step(context.step);
  command->set_num_steps(static_cast<std::uint32_t>(rng.between(1, 20)));
  command->set_t(context.t);
  command->set_dt(5e-5);
  const bool output = rng.chance(0.3);
  command->set_write_output(output);
  command->set_output_frame(output ? rng.between(1, 5) : 0);
  return envelope;
}

protocol::Envelope random_envelope(Rng& rng, const MessageContext& context) {
  protocol::Envelope envelope;
  switch (rng.between(1, 11)) {
    case 1: {
      auto* hello = envelope.mutable_hello();
      hello->set_role(some_role(rng));
      hello->set_protocol_version(rng.chance(0.8) ? 1 : static_cast<std::uint32_t>(rng.next()));
      hello->set_implementation(some_text(rng));
      hello->set_implementation_version("0.1.0");
      hello->add_capabilities(some_text(rng));
      hello->set_host(some_text(rng));
      hello->set_pid(static_cast<std::int64_t>(rng.next()));
      hello->set_scene_schema_version(protocol::SCENE_SCHEMA_CURRENT);
      break;
    }
    case 2: {
      auto* welcome = envelope.mutable_welcome();
      welcome->set_protocol_version(rng.chance(0.9) ? 1 : static_cast<std::uint32_t>(rng.next()));
      welcome->set_run_id("0123456789ab");
      *welcome->mutable_scene() = rng.chance(0.5) ? context.coupled_scene : context.dry_scene;
      welcome->mutable_data_plane()->set_mode(static_cast<protocol::DataPlane::Mode>(rng.between(0, 4)));
      welcome->mutable_data_plane()->set_endpoint(context.data_endpoint);
      welcome->set_output_dir(context.output_dir);
      welcome->set_scene_schema_version(rng.chance(0.9) ? protocol::SCENE_SCHEMA_CURRENT : 0);
      break;
    }
    case 3:
      envelope.mutable_reject()->set_reason(some_text(rng));
      envelope.mutable_reject()->set_coupler_protocol_version(1);
      break;
    case 4:
      envelope.mutable_listening()->set_data_endpoint(rng.chance(0.5) ? context.data_endpoint : some_text(rng));
      break;
    case 5:
      envelope.mutable_ready()->set_stable_dt(weird_double(rng));
      envelope.mutable_ready()->set_stable_dt_limit(some_text(rng));
      fill_diagnostics(rng, envelope.mutable_ready()->mutable_diagnostics());
      break;
    case 6: {
      envelope = next_command(rng, context);
      auto* command = envelope.mutable_step_command();
      if (rng.chance(0.3)) command->set_first_step(rng.between(0, 1000));
      if (rng.chance(0.3)) command->set_t(weird_double(rng));
      if (rng.chance(0.3)) command->set_dt(weird_double(rng));
      if (rng.chance(0.2)) command->set_num_steps(0);
      break;
    }
    case 7: {
      auto* report = envelope.mutable_step_report();
      report->set_step(rng.between(0, 100000));
      report->set_t(weird_double(rng));
      report->set_stable_dt(weird_double(rng));
      report->set_status(static_cast<protocol::StepReport::Status>(rng.between(0, 3)));
      fill_diagnostics(rng, report->mutable_diagnostics());
      break;
    }
    case 8: {
      auto* frame = envelope.mutable_data();
      frame->set_step(rng.between(0, 100));
      frame->set_t(weird_double(rng));
      const auto n = rng.between(0, 8);
      if (rng.chance(0.5)) {
        auto* crack = frame->mutable_crack()->add_cracks();
        for (std::uint64_t i = 0; i < n; ++i) {
          crack->add_ids(i);
          crack->add_x(0.01 * static_cast<double>(i));
          crack->add_y(0);
          crack->add_nx(0);
          crack->add_ny(1);
          crack->add_width(rng.chance(0.9) ? 1e-4 : weird_double(rng));
          crack->add_tip(i + 1 == n);
        }
      } else {
        auto* crack = frame->mutable_fluid()->add_cracks();
        for (std::uint64_t i = 0; i < n; ++i) {
          crack->add_ids(i);
          crack->add_pressure(rng.chance(0.9) ? 1e5 : weird_double(rng));
        }
        crack->set_front_position(weird_double(rng));
      }
      break;
    }
    case 9: {
      auto* beat = envelope.mutable_heartbeat();
      beat->set_role(some_role(rng));
      beat->set_sequence(rng.next());
      beat->set_step(rng.between(0, 1000));
      beat->set_waiting_for_peer(rng.chance(0.5));
      break;
    }
    case 10:
      envelope.mutable_shutdown()->set_reason(some_text(rng));
      envelope.mutable_shutdown()->set_error(rng.chance(0.5));
      break;
    default: {
      auto* error = envelope.mutable_error();
      error->set_who(some_role(rng));
      error->set_what(some_text(rng));
      error->set_where(some_text(rng));
      error->set_message(some_text(rng));
      error->set_step(rng.between(0, 1000));
      break;
    }
  }
  return envelope;
}

std::string mutate(std::string bytes, Rng& rng) {
  static const std::vector<char> interesting{'\x00', '\x01', '\x7f', '\x80', '\xff', '\x08', '\x0a', '\x12', '\x1a'};
  const auto edits = rng.between(1, 4);
  for (std::uint64_t e = 0; e < edits; ++e) {
    const std::size_t size = bytes.size();
    const std::size_t at = size ? rng.between(0, size - 1) : 0;
    switch (rng.between(0, 6)) {
      case 0:  // flip a bit
        if (size) bytes[at] = static_cast<char>(bytes[at] ^ (1 << rng.between(0, 7)));
        break;
      case 1:  // an interesting byte
        if (size) bytes[at] = rng.pick(interesting);
        break;
      case 2:  // insert random bytes
        bytes.insert(at, rng.bytes(rng.between(1, 16)));
        break;
      case 3:  // delete a range
        if (size) bytes.erase(at, rng.between(1, std::max<std::size_t>(1, std::min<std::size_t>(16, size - at))));
        break;
      case 4:  // truncate
        bytes.resize(at);
        break;
      case 5:  // repeat a range
        if (size) bytes.insert(at, bytes.substr(at, rng.between(1, 32)));
        break;
      default: {  // append a field: random tag and wire type, random payload
        const auto field = rng.between(1, 40);
        const auto wire = rng.between(0, 5);
        bytes += static_cast<char>((field << 3 | wire) & 0x7f);
        bytes += rng.bytes(rng.between(1, 12));
        break;
      }
    }
  }
  return bytes;
}

}  // namespace hfmpm::reliability
