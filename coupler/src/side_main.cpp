#include <iostream>

#include "hfmpm/coupling/side_runtime.hpp"

namespace hfmpm::coupling {
namespace {

void usage(std::ostream& out, const std::string& program, protocol::Role role) {
  out << "usage: " << program << " --connect ENDPOINT [options]\n"
      << "A " << proto::role_name(role) << " side of hfmpm (protocol version " << proto::kProtocolVersion
      << "). Normally started by the coupler; start it by hand to join a coupler\n"
      << "started with 'hfmpm coupler SCENE --bind ENDPOINT', e.g. on another host.\n\n"
      << "  --connect ENDPOINT       the coupler's control endpoint (tcp://HOST:PORT, ipc://PATH)\n"
      << "  --out DIR                where this side writes its files (default: the coupler's)\n"
      << "  --advertise-host HOST    tcp: the host name the other side reaches this one at\n"
      << "  --keys FILE              tcp: the sides' CURVE key file (side.keys from 'hfmpm keygen DIR');\n"
      << "                           a coupler on tcp admits no side without it (unless --insecure-tcp)\n"
      << "  --welcome-timeout S      seconds to wait for the coupler's answer (default 60)\n"
      << "  --fault KIND@STEP        test hook: exit|crash|hang|freeze|garbage|nan at STEP\n"
      << "  --protocol-version N     test hook: claim protocol version N\n"
      << "  --scene-schema-version N test hook: claim scene schema version N (0: an older side)\n"
      << "  --help                   this text\n";
}

}  // namespace

int side_main(int argc, char** argv, protocol::Role role, const std::string& implementation,
              const std::vector<std::string>& capabilities,
              const std::function<std::unique_ptr<SideModel>()>& make_model) {
  const std::string program = argc > 0 ? argv[0] : implementation;
  SideOptions options;
  options.role = role;
  options.implementation = implementation;
  options.capabilities = capabilities;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw InputError("option " + arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--help" || arg == "-h") {
        usage(std::cout, program, role);
        return 0;
      } else if (arg == "--connect") {
        options.control_endpoint = value();
      } else if (arg == "--out") {
        options.output_dir = value();
      } else if (arg == "--keys") {
        try {
          options.curve = read_side_key_file(value());
        } catch (const std::runtime_error& e) {
          throw InputError(e.what());
        }
      } else if (arg == "--advertise-host") {
        options.advertise_host = value();
      } else if (arg == "--welcome-timeout") {
        options.welcome_timeout_s = std::stod(value());
      } else if (arg == "--fault") {
        options.fault = Fault::parse(value());
      } else if (arg == "--protocol-version") {
        options.protocol_version = static_cast<std::uint32_t>(std::stoul(value()));
      } else if (arg == "--scene-schema-version") {
        options.scene_schema_version = static_cast<std::uint32_t>(std::stoul(value()));
      } else {
        throw InputError("unknown option '" + arg + "'; see --help");
      }
    }
    if (options.control_endpoint.empty()) throw InputError("--connect ENDPOINT is required; see --help");
    if (options.control_endpoint.rfind("tcp://", 0) == 0 && !options.curve) {
      std::cerr << program << ": note: no --keys: joining over plain tcp; a coupler that requires CURVE (the "
                << "default on tcp) will not hear this side\n";
    }
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return kSideInput;
  }
  auto model = make_model();
  return run_side(*model, options);
}

}  // namespace hfmpm::coupling
