// Optional CSV log of every data frame a side receives (scene:
// output.exchange_log). For debugging and for tests that check the values
// that crossed the data plane.
#pragma once

#include <fstream>
#include <string>

#include "hfmpm/protocol.pb.h"

namespace hfmpm::coupling {

class ExchangeLog {
 public:
  ExchangeLog(const std::string& directory, const std::string& role);
  void write(const protocol::DataFrame& frame);

 private:
  std::ofstream out_;
};

}  // namespace hfmpm::coupling
