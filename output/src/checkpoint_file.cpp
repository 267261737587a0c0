// Side checkpoints in HDF5 (see checkpoint_file.hpp).
#include "hfmpm/output/checkpoint_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "h5.hpp"
#include "hfmpm/checksum.hpp"

namespace hfmpm::output {
namespace {

// The checksums are of the bytes the file holds (little-endian types); a writer hashes its values as
// they are in memory, which are those bytes only on a little-endian machine.
static_assert(std::endian::native == std::endian::little, "checkpoint checksums assume a little-endian machine");

constexpr const char* kChecksum = "checksum_fnv1a64";  // on each dataset, and on the root (the stamp's)

// A dataset's checksum covers its name and its type ("f64", "u64" or "u8"), each followed by a zero
// byte, then its elements' bytes: a name or a type damaged in the file no longer matches either.
std::string dataset_checksum(const std::string& name, const std::string& type, const void* data, std::size_t size) {
  const std::string head = name + '\0' + type + '\0';
  return checksum_text(fnv1a64(data, size, fnv1a64(head)));
}

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
    seal(name, "f64", values.data(), values.size() * sizeof(double));
  }
  void u64(const std::string& name, const std::vector<std::uint64_t>& values) override {
    check(name);
    file_.write_u64(name, {values.size()}, values.data());
    seal(name, "u64", values.data(), values.size() * sizeof(std::uint64_t));
  }
  void text(const std::string& name, const std::string& bytes) override {
    check(name);
    file_.write_u8(name, {bytes.size()}, reinterpret_cast<const std::uint8_t*>(bytes.data()));
    seal(name, "u8", bytes.data(), bytes.size());
  }
  std::size_t datasets() const { return names_.size(); }

 private:
  void seal(const std::string& name, const std::string& type, const void* data, std::size_t size) {
    file_.set_attribute(name, kChecksum, dataset_checksum(name, type, data, size));
  }
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

// The root attributes the stamp's checksum covers, in its order, after the fields above.
std::vector<std::pair<std::string, std::string>> sealed_stamp(const CheckpointStamp& s, std::size_t datasets) {
  auto pairs = fields(s);
  pairs.emplace_back("t_s", text(s.t));
  pairs.emplace_back("datasets", std::to_string(datasets));
  return pairs;
}

std::string stamp_checksum(const std::vector<std::pair<std::string, std::string>>& pairs) {
  std::string bytes;
  for (const auto& [key, value] : pairs) bytes += key + "=" + value + "\n";
  return checksum_text(fnv1a64(bytes));
}

// A name read from a file that may be damaged: printable, and not too long.
std::string shown(const std::string& name) {
  std::string out;
  for (char c : name.substr(0, 200)) {
    if (c >= 0x20 && c < 0x7f) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += hex;
    }
  }
  return name.size() > 200 ? out + "..." : out;
}

// A file of another format, refused as such (not as damaged).
class OtherFormat : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Refuses a file of another format that has no stamp checksum (format 1 had none); a format
// attribute that differs under a stamp checksum is judged by the checksum first.
void check_format(const h5::ReadFile& file) {
  const std::string found = file.root_attribute("format");
  const std::string here = std::to_string(kCheckpointFormat);
  if (found == here || !file.root_attribute(kChecksum).empty()) return;
  throw OtherFormat("checkpoint " + file.path() + " has format = '" + found + "', this run needs '" + here +
                    "': it was written by another version of the program (a checkpoint without checksums, format "
                    "1, cannot be checked and is not used)");
}

// Every checksum of an open checkpoint (see checkpoint_file.hpp).
void verify(const h5::ReadFile& file) {
  auto damaged = [&](const std::string& what) {
    throw DamagedCheckpoint("checkpoint " + file.path() + " is damaged: " + what +
                            "; a checkpoint is used only if its stamp and every dataset match the checksums written "
                            "with them");
  };
  std::vector<std::pair<std::string, std::string>> pairs;  // the stamp's keys, with the file's values
  for (const auto& [key, value] : sealed_stamp(CheckpointStamp{}, 0)) pairs.emplace_back(key, file.root_attribute(key));
  const std::string stored = file.root_attribute(kChecksum);
  if (stored.empty()) damaged("its stamp has no checksum (root attribute " + std::string(kChecksum) + ")");
  if (stamp_checksum(pairs) != stored) {
    damaged(
        "its stamp (the root attributes format, role, implementation, versions, scene_hash, step, t_bits, t_s "
        "and datasets) does not match its checksum");
  }
  const auto names = file.root_names();
  const std::string count = file.root_attribute("datasets");
  if (std::to_string(names.size()) != count) {
    damaged("it holds " + std::to_string(names.size()) + " datasets, its stamp says " + shown(count));
  }
  for (const auto& name : names) {
    if (!file.is_dataset(name)) damaged("'" + shown(name) + "' is not a dataset");
    // The type is checked as well as the bytes: the same bytes read as another type (big-endian,
    // another size or sign) are other numbers.
    const std::string type = file.array_type(name);
    if (type.empty()) {
      damaged("dataset " + shown(name) +
              " is not a one-dimensional array of little-endian float64, uint64 or uint8, the types a checkpoint "
              "holds");
    }
    const std::string sum = file.attribute(name, kChecksum);
    if (sum.empty()) damaged("dataset " + shown(name) + " has no checksum (attribute " + std::string(kChecksum) + ")");
    const std::string bytes = file.raw_bytes(name);
    const std::string computed = dataset_checksum(name, type, bytes.data(), bytes.size());
    if (computed != sum) {
      damaged("dataset " + shown(name) + " does not match its checksum (FNV-1a of its name, type and " +
              std::to_string(bytes.size()) + " bytes is " + computed + ", written as " + shown(sum) + ")");
    }
  }
}

// Opens the file and checks its format and checksums; a file HDF5 cannot read is damaged.
std::unique_ptr<h5::ReadFile> open_verified(const std::string& path) {
  if (!std::filesystem::exists(path)) throw std::runtime_error("checkpoint file " + path + " does not exist");
  try {
    auto file = std::make_unique<h5::ReadFile>(path);
    check_format(*file);
    verify(*file);
    return file;
  } catch (const DamagedCheckpoint&) {
    throw;
  } catch (const OtherFormat&) {
    throw;
  } catch (const std::exception& e) {  // HDF5's errors, and a size no allocation can hold
    throw DamagedCheckpoint("checkpoint " + path + " is damaged: it cannot be read (" + e.what() +
                            "); a checkpoint is used only if it reads whole and matches its checksums");
  }
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
    H5StateWriter writer(file);
    fill(writer);
    const auto pairs = sealed_stamp(stamp, writer.datasets());
    for (const auto& [key, value] : pairs) file.set_attribute("/", key, value);
    file.set_attribute("/", kChecksum, stamp_checksum(pairs));
    file.flush();
  }
  sync_file(tmp);
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) throw std::runtime_error("checkpoint: cannot rename " + tmp + " to " + path + ": " + error.message());
}

void verify_checkpoint(const std::string& path) { open_verified(path); }

void read_checkpoint(const std::string& path, const CheckpointStamp& expected,
                     const std::function<void(const StateReader&)>& read) {
  const auto opened = open_verified(path);
  const h5::ReadFile& file = *opened;
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
