// Side checkpoints in HDF5 (see checkpoint_file.hpp).
#include "hfmpm/output/checkpoint_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

#include "h5.hpp"

namespace hfmpm::output {
namespace {

bool valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.';
    if (!ok) return false;
  }
  return name != "." && name != "..";
}

class H5StateWriter final : public StateWriter {
 public:
  explicit H5StateWriter(h5::File& file) : file_(file) {}
  void f64(const std::string& name, const std::vector<double>& values) override {
    check(name);
    file_.write_f64(name, {values.size()}, values.data());
  }
  void u64(const std::string& name, const std::vector<std::uint64_t>& values) override {
    check(name);
    file_.write_u64(name, {values.size()}, values.data());
  }
  void text(const std::string& name, const std::string& bytes) override {
    check(name);
    file_.write_u8(name, {bytes.size()}, reinterpret_cast<const std::uint8_t*>(bytes.data()));
  }

 private:
  void check(const std::string& name) {
    if (!valid_name(name)) throw std::invalid_argument("checkpoint array name '" + name + "' is not allowed");
    if (!names_.insert(name).second) throw std::logic_error("checkpoint array " + name + " written twice");
  }
  h5::File& file_;
  std::set<std::string> names_;
};

class H5StateReader final : public StateReader {
 public:
  explicit H5StateReader(const h5::ReadFile& file) : file_(file) {}
  std::vector<double> f64(const std::string& name) const override { return file_.read_f64(name); }
  std::vector<std::uint64_t> u64(const std::string& name) const override { return file_.read_u64(name); }
  std::string text(const std::string& name) const override { return file_.read_text(name); }

 private:
  const h5::ReadFile& file_;
};

std::string text(double t) {
  std::ostringstream out;
  out.precision(17);
  out << t;
  return out.str();
}

std::string hex_bits(double t) {
  std::ostringstream out;
  out << std::hex << std::bit_cast<std::uint64_t>(t);
  return out.str();
}

std::vector<std::pair<std::string, std::string>> fields(const CheckpointStamp& s) {
  return {{"format", std::to_string(kCheckpointFormat)},
          {"role", s.role},
          {"implementation", s.implementation},
          {"program_version", s.program_version},
          {"protocol_version", std::to_string(s.protocol_version)},
          {"scene_schema_version", std::to_string(s.scene_schema_version)},
          {"scene_hash", s.scene_hash},
          {"step", std::to_string(s.step)},
          {"t_bits", hex_bits(s.t)}};
}

void sync_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw std::runtime_error("checkpoint: cannot open " + path + " to sync it");
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) throw std::runtime_error("checkpoint: fsync of " + path + " failed");
}

}  // namespace

void write_checkpoint(const std::string& path, const CheckpointStamp& stamp,
                      const std::function<void(StateWriter&)>& fill) {
  const std::string tmp = path + ".tmp";
  {
    h5::File file(tmp);
    for (const auto& [key, value] : fields(stamp)) file.set_attribute("/", key, value);
    file.set_attribute("/", "t_s", text(stamp.t));
    H5StateWriter writer(file);
    fill(writer);
    file.flush();
  }
  sync_file(tmp);
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) throw std::runtime_error("checkpoint: cannot rename " + tmp + " to " + path + ": " + error.message());
}

void read_checkpoint(const std::string& path, const CheckpointStamp& expected,
                     const std::function<void(const StateReader&)>& read) {
  if (!std::filesystem::exists(path)) throw std::runtime_error("checkpoint file " + path + " does not exist");
  h5::ReadFile file(path);
  for (const auto& [key, value] : fields(expected)) {
    const std::string found = file.root_attribute(key);
    if (found != value) {
      std::string what = key;
      if (key == "t_bits")
        what = "t (as bits; " + file.root_attribute("t_s") + " s against " + text(expected.t) + " s)";
      throw std::runtime_error(
          "checkpoint " + path + " has " + what + " = '" + found + "', this run needs '" + value + "'" +
          (key == "scene_hash" ? ": it was written for another scene"
           : key == "program_version" || key == "protocol_version" || key == "scene_schema_version" || key == "format"
               ? ": it was written by another version of the program"
               : ""));
    }
  }
  H5StateReader reader(file);
  read(reader);
}

}  // namespace hfmpm::output
