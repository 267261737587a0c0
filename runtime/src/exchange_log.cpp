#include "exchange_log.hpp"

#include <iomanip>
#include <stdexcept>
#include <string>

namespace hfmpm::coupling {

namespace {

// The log's header and its rows of steps up to `step` (the rest, and a row cut short, go).
std::string kept_rows(const std::string& path, std::uint64_t step) {
  std::ifstream in(path);
  std::string line, kept;
  if (std::getline(in, line)) kept = line + "\n";
  while (std::getline(in, line)) {
    const auto comma = line.find(',');
    if (comma == 0 || comma == std::string::npos || line.find_first_not_of("0123456789") != comma) break;
    if (std::stoull(line.substr(0, comma)) > step) break;
    kept += line + "\n";
  }
  return kept;
}

}  // namespace

ExchangeLog::ExchangeLog(const std::string& directory, const std::string& role, std::int64_t continue_after) {
  const std::string path = directory + "/" + role + "_received.csv";
  if (continue_after >= 0) {
    const std::string kept = kept_rows(path, static_cast<std::uint64_t>(continue_after));
    out_.open(path, std::ios::out | std::ios::trunc);
    out_ << kept;
  } else {
    out_.open(path, std::ios::out | std::ios::trunc);
  }
  if (!out_) throw std::runtime_error("cannot write " + path);
  out_ << std::setprecision(17);
  if (continue_after >= 0 && out_.tellp() > 0) return;  // the header is there
  if (role == "fluid") {
    out_ << "step,t_s,crack_id,id,x_m,y_m,nx,ny,width_m,tip,grew\n";
  } else {
    out_ << "step,t_s,crack_id,id,pressure_pa,front_position_m,inlet_flux_m2_s,fluid_volume_m2\n";
  }
}

void ExchangeLog::write(const protocol::DataFrame& frame) {
  if (frame.has_crack()) {
    for (const auto& c : frame.crack().cracks()) {
      for (int i = 0; i < c.ids_size(); ++i) {
        out_ << frame.step() << ',' << frame.t() << ',' << c.crack_id() << ',' << c.ids(i) << ',' << c.x(i) << ','
             << c.y(i) << ',' << c.nx(i) << ',' << c.ny(i) << ',' << c.width(i) << ',' << (c.tip(i) ? 1 : 0) << ','
             << (c.grew() ? 1 : 0) << '\n';
      }
    }
  } else if (frame.has_fluid()) {
    for (const auto& c : frame.fluid().cracks()) {
      for (int i = 0; i < c.ids_size(); ++i) {
        out_ << frame.step() << ',' << frame.t() << ',' << c.crack_id() << ',' << c.ids(i) << ',' << c.pressure(i)
             << ',' << c.front_position() << ',' << c.inlet_flux() << ',' << c.fluid_volume() << '\n';
      }
    }
  }
  out_.flush();
}

}  // namespace hfmpm::coupling
