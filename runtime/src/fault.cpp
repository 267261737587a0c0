// The --fault test hook: its parser (KIND@STEP) and its action.
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>

#include "hfmpm/runtime/side_runtime.hpp"
#include "side_checks.hpp"

namespace hfmpm::coupling {

Fault Fault::parse(const std::string& text) {
  const auto at = text.find('@');
  const std::string kind = text.substr(0, at);
  Fault fault;
  if (kind == "exit")
    fault.kind = Kind::Exit;
  else if (kind == "crash")
    fault.kind = Kind::Crash;
  else if (kind == "hang")
    fault.kind = Kind::Hang;
  else if (kind == "freeze")
    fault.kind = Kind::Freeze;
  else if (kind == "garbage")
    fault.kind = Kind::Garbage;
  else if (kind == "nan")
    fault.kind = Kind::NaN;
  else {
    throw InputError("--fault '" + text + "': unknown kind '" + kind +
                     "'; allowed: exit, crash, hang, freeze, garbage, nan, as KIND@STEP");
  }
  try {
    if (at == std::string::npos) throw std::invalid_argument("no step");
    std::size_t used = 0;
    fault.step = std::stoull(text.substr(at + 1), &used);
    if (used != text.size() - at - 1 || fault.step == 0) throw std::invalid_argument("bad step");
  } catch (const std::exception&) {
    throw InputError("--fault '" + text + "': expected KIND@STEP with STEP a positive integer");
  }
  return fault;
}

bool act_on_fault(const Fault& fault, std::uint64_t step, const std::string& role, Link& control, Link* data) {
  if (fault.kind == Fault::Kind::None || fault.step != step) return false;
  std::cerr << role << ": injecting fault at step " << step << "\n";
  switch (fault.kind) {
    case Fault::Kind::Exit:
      std::_Exit(7);
    case Fault::Kind::Crash:
      std::abort();
    case Fault::Kind::Hang:
      while (true) std::this_thread::sleep_for(std::chrono::seconds(1));
    case Fault::Kind::Freeze:
      std::raise(SIGSTOP);
      return false;
    case Fault::Kind::Garbage: {
      static constexpr char kGarbage[] = "\xff\x01garbage\x00\x7f not an envelope";
      const std::string garbage(kGarbage, sizeof(kGarbage) - 1);
      (void)control.send_bytes(garbage, true);
      if (data) (void)data->send_bytes(garbage, true);
      return false;
    }
    case Fault::Kind::NaN:
      return true;
    case Fault::Kind::None:
      break;
  }
  return false;
}

}  // namespace hfmpm::coupling
