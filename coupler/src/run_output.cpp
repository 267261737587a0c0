#include "run_output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
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

int Manifest::write() const {
  // Write then rename, so a reader never sees half a file; every byte checked
  // before the rename, so a full disk never replaces the last good file.
  const std::string tmp = path_ + ".tmp";
  std::string text = "{\n";
  std::size_t i = 0;
  for (const auto& [key, value] : fields_) {
    text += "  \"" + key + "\": " + value + (++i < fields_.size() ? ",\n" : "\n");
  }
  text += "}\n";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return errno;
  int error = 0;
  std::size_t done = 0;
  while (done < text.size() && error == 0) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else {
      error = n < 0 ? errno : ENOSPC;
    }
  }
  if (error == 0 && ::fsync(fd) != 0) error = errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error == 0 && std::rename(tmp.c_str(), path_.c_str()) != 0) error = errno;
  if (error != 0) std::remove(tmp.c_str());
  return error;
}

void Manifest::save() {
  int error = write();
  if (error == 0) return;
  if (!reserve_.empty()) {
    release_reserve();
    error = write();
    if (error == 0) return;
  }
  // The last good run.json stays; say why it is not newer.
  std::cerr << "hfmpm: cannot write " << path_ << ": " << std::strerror(error) << " (the last complete one is kept)\n";
}

void Manifest::keep_reserve(std::size_t bytes) {
  const std::string path = path_ + ".reserve";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return;
  const std::string zeros(bytes, '\0');
  const bool kept = ::write(fd, zeros.data(), zeros.size()) == static_cast<ssize_t>(zeros.size());
  ::close(fd);
  if (kept) {
    reserve_ = path;
  } else {
    std::remove(path.c_str());
  }
}

void Manifest::release_reserve() {
  if (!reserve_.empty()) std::remove(reserve_.c_str());
  reserve_.clear();
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
