// Optional CSV log of every data frame a side receives (scene:
// output.exchange_log). For debugging and for tests that check the values
// that crossed the data plane.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

#include "hfmpm/protocol.pb.h"

namespace hfmpm::coupling {

class ExchangeLog {
 public:
  // continue_after: a restart from the checkpoint of that step keeps the log's rows up to
  // it and appends (rows a killed run wrote after the checkpoint go); -1: a new log.
  ExchangeLog(const std::string& directory, const std::string& role, std::int64_t continue_after = -1);
  void write(const protocol::DataFrame& frame);

 private:
  std::ofstream out_;
};

}  // namespace hfmpm::coupling
