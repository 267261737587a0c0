// The --fault test hook's parser (KIND@STEP).
#include <string>

#include "hfmpm/coupling/side_runtime.hpp"

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

}  // namespace hfmpm::coupling
