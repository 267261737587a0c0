#include "run_output.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace hfmpm::coupling {

History::History(const std::string& path, bool append, std::optional<std::uint64_t> last_step)
    : out_(path, std::ios::out | (append ? std::ios::app : std::ios::trunc)), last_step_(last_step) {
  if (!out_) throw std::runtime_error("cannot write " + path);
  out_ << std::setprecision(10);
  if (append) return;
  // The first nine columns are the ones every hfmpm history has (docs/architecture.md, "history.csv").
  out_ << "time_s,step,crack_length_m,mouth_opening_m,inlet_pressure_pa,injected_volume_m2,fluid_volume_m2,"
          "kinetic_energy_j,wall_s,dt_s,crack_face_load_n_per_m,front_position_m,crack_particles,fluid_particles,"
          "coupling_lag_pa\n";
  out_.flush();
}

void History::write(double t, std::uint64_t step, double dt, const SideDiagnostics& solid, const SideDiagnostics& fluid,
                    double wall_s) {
  out_ << t << ',' << step << ',' << solid.crack_length << ',' << solid.mouth_opening << ',' << fluid.inlet_pressure
       << ',' << fluid.injected_volume << ',' << fluid.fluid_volume << ',' << solid.kinetic_energy << ',' << wall_s
       << ',' << dt << ',' << solid.crack_face_load << ',' << fluid.front_position << ',' << solid.crack_particles
       << ',' << fluid.fluid_particles << ',' << fluid.coupling_lag << '\n';
  out_.flush();
  last_step_ = step;
}

void Manifest::set_number(const std::string& key, double value) {
  std::ostringstream out;
  out << std::setprecision(12) << (std::isfinite(value) ? value : 0.0);
  fields_[key] = out.str();
}

std::string Manifest::quoted(const std::string& value) {
  std::string out = "\"";
  for (char ch : value) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof(buffer), "\\u%04x", ch);
      out += buffer;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

void Manifest::append(const std::string& key, const std::string& value) {
  auto& list = lists_[key];
  list.push_back(quoted(value));
  std::string json = "[";
  for (std::size_t i = 0; i < list.size(); ++i) json += (i ? ",\n    " : "\n    ") + list[i];
  fields_[key] = json + "\n  ]";
}

void Manifest::save() const {
  // Write then rename, so a reader never sees half a file.
  const std::string tmp = path_ + ".tmp";
  {
    std::ofstream out(tmp);
    out << "{\n";
    std::size_t i = 0;
    for (const auto& [key, value] : fields_) {
      out << "  \"" << key << "\": " << value << (++i < fields_.size() ? ",\n" : "\n");
    }
    out << "}\n";
  }
  std::rename(tmp.c_str(), path_.c_str());
}

void Log::open_file(const std::string& path, bool append) {
  file_.open(path, std::ios::out | (append ? std::ios::app : std::ios::trunc));
}

void Log::operator()(const std::string& line) {
  if (echo_) std::cerr << "hfmpm: " << line << "\n";
  if (file_) file_ << line << std::endl;
}

void Log::file_only(const std::string& line) {
  if (file_) file_ << line << std::endl;
}

Progress::Progress(bool enabled, double end_time)
    : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0), end_time_(end_time) {}

void Progress::update(double t, std::uint64_t step, double wall_s) {
  if (!enabled_ || wall_s - last_print_ < (tty_ ? 0.2 : 10.0)) return;
  last_print_ = wall_s;
  const double fraction = std::min(1.0, t / end_time_);
  const double rate = wall_s > 0 ? static_cast<double>(step) / wall_s : 0.0;
  const double left = fraction > 0 ? wall_s * (1 - fraction) / fraction : 0.0;
  std::ostringstream line;
  line << "t = " << std::setprecision(4) << t << " s (" << std::fixed << std::setprecision(1) << 100 * fraction
       << "%)  step " << step << "  " << std::setprecision(0) << rate << " steps/s  about " << std::setprecision(1)
       << left << " s left";
  std::cerr << (tty_ ? "\r" : "") << line.str() << (tty_ ? "\x1b[K" : "\n") << std::flush;
  printed_ = true;
}

void Progress::finish() {
  if (enabled_ && tty_ && printed_) std::cerr << "\n";
}

}  // namespace hfmpm::coupling
