// The command line of every side program (hfmpm-solid, hfmpm-fluid and the
// stand-ins), parsed with CLI11: typed values, ranges, --help.
#include <CLI/CLI.hpp>
#include <iostream>

#include "hfmpm/runtime/side_runtime.hpp"

namespace hfmpm::coupling {

int side_main(int argc, char** argv, protocol::Role role, const std::string& implementation,
              const std::vector<std::string>& capabilities,
              const std::function<std::unique_ptr<SideModel>()>& make_model) {
  const std::string program = argc > 0 ? argv[0] : implementation;
  SideOptions options;
  options.role = role;
  options.implementation = implementation;
  options.capabilities = capabilities;

  CLI::App app("A " + std::string(proto::role_name(role)) + " side of hfmpm (protocol version " +
                   std::to_string(proto::kProtocolVersion) +
                   "). Normally started by the coupler; start it by hand to join a coupler started with\n"
                   "'hfmpm coupler SCENE --bind ENDPOINT', e.g. on another host.",
               program);
  std::string keys, fault;
  app.add_option("--connect", options.control_endpoint, "the coupler's control endpoint (tcp://HOST:PORT, ipc://PATH)")
      ->required()
      ->type_name("ENDPOINT");
  app.add_option("--out", options.output_dir, "where this side writes its files (default: the coupler's)")
      ->type_name("DIR");
  app.add_option("--advertise-host", options.advertise_host, "tcp: the host name the other side reaches this one at")
      ->type_name("HOST");
  app.add_option("--keys", keys,
                 "tcp: the sides' CURVE key file (side.keys from 'hfmpm keygen DIR'); a coupler on tcp admits no "
                 "side without it (unless --insecure-tcp)")
      ->type_name("FILE");
  app.add_option("--welcome-timeout", options.welcome_timeout_s,
                 "seconds to wait for the coupler's answer to Hello, 0.001 to 1e6 (default 60)")
      ->check(CLI::Range(1e-3, 1e6))
      ->type_name("S");
  app.add_option("--fault", fault, "test hook: exit|crash|hang|freeze|garbage|nan at STEP")->type_name("KIND@STEP");
  app.add_option("--protocol-version", options.protocol_version, "test hook: claim protocol version N in Hello")
      ->type_name("N");
  app.add_option("--extra-hellos", options.extra_hellos, "test hook: send Hello N more times at once")
      ->check(CLI::Range(0, 100))
      ->type_name("N");
  app.add_option("--scene-schema-version", options.scene_schema_version,
                 "test hook: claim scene schema version N in Hello (0: a side built before them)")
      ->type_name("N");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::ParseError& e) {
    std::cerr << program << ": " << e.what() << "; see --help\n";
    return kSideInput;
  }
  try {
    if (!keys.empty()) options.curve = read_side_key_file(keys);
    if (!fault.empty()) options.fault = Fault::parse(fault);
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
