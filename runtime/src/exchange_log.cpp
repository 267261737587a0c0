#include "exchange_log.hpp"

#include <iomanip>
#include <stdexcept>

namespace hfmpm::coupling {

ExchangeLog::ExchangeLog(const std::string& directory, const std::string& role)
    : out_(directory + "/" + role + "_received.csv") {
  if (!out_) throw std::runtime_error("cannot write " + directory + "/" + role + "_received.csv");
  out_ << std::setprecision(17);
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
