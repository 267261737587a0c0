// Checkpoints, the coupler's part (see checkpoint.hpp).
#include "hfmpm/coupling/checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "hfmpm/checksum.hpp"
#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::coupling {
namespace fs = std::filesystem;
namespace {

constexpr const char* kPrefix = "step-";

// Writes `bytes` to path.tmp, fsyncs it, renames it to path.
void write_atomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write " + tmp);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) {
      ::close(fd);
      throw std::runtime_error("cannot write " + tmp);
    }
    done += static_cast<std::size_t>(n);
  }
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!synced) throw std::runtime_error("cannot sync " + tmp);
  fs::rename(tmp, path);
}

// Steps of the complete checkpoints in run_dir, ascending.
std::vector<std::uint64_t> complete_steps(const std::string& run_dir) {
  std::vector<std::uint64_t> steps;
  const fs::path root = fs::path(run_dir) / "checkpoints";
  std::error_code error;
  if (!fs::is_directory(root, error)) return steps;
  for (const auto& entry : fs::directory_iterator(root, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kPrefix, 0) != 0 || !fs::exists(entry.path() / "coupler.pb", error)) continue;
    const std::string digits = name.substr(std::char_traits<char>::length(kPrefix));
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 19) continue;
    steps.push_back(std::stoull(digits));
  }
  std::sort(steps.begin(), steps.end());
  return steps;
}

// coupler.pb ends with its field `checksum` (34, fixed64): the tag, (34 << 3) | 1 = 273 as a
// varint, then the 8 bytes little-endian.
static_assert(checkpoint::CouplerState::kChecksumFieldNumber == 34);
constexpr char kChecksumTag[2] = {'\x91', '\x02'};
constexpr std::size_t kTrailer = 10;

// What reading a coupler.pb found: intact, of an older format (without a checksum), or the problem.
struct CouplerFile {
  bool intact = false;
  bool other_format = false;
  std::string problem;
};

CouplerFile read_coupler_file(const std::string& path, checkpoint::CouplerState& state) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (!in) return {false, false, "checkpoint " + path + " cannot be read"};
  const std::string bytes = buffer.str();
  const std::size_t n = bytes.size();
  if (n >= kTrailer && bytes[n - kTrailer] == kChecksumTag[0] && bytes[n - kTrailer + 1] == kChecksumTag[1]) {
    std::uint64_t stored = 0;
    for (std::size_t i = 0; i < 8; ++i) {
      stored |= std::uint64_t{static_cast<unsigned char>(bytes[n - 8 + i])} << (8 * i);
    }
    const std::uint64_t computed = fnv1a64(bytes.data(), n - kTrailer);
    if (stored != computed) {
      return {false, false,
              "checkpoint " + path + " is damaged: it does not match its checksum (FNV-1a of its first " +
                  std::to_string(n - kTrailer) + " bytes is " + checksum_text(computed) + ", written as " +
                  checksum_text(stored) +
                  "); a checkpoint is used only if its coupler.pb matches the checksum written "
                  "with it"};
    }
    if (!state.ParseFromString(bytes)) {
      return {false, false,
              "checkpoint " + path + " matches its checksum but does not parse as a coupler checkpoint (CouplerState)"};
    }
    return {true, false, {}};
  }
  // No checksum at the end: a file of format 1 (before checksums), or one damaged there.
  if (state.ParseFromString(bytes) && state.format() != 0 && state.format() < kCouplerCheckpointFormat) {
    return {false, true, {}};
  }
  return {false, false,
          "checkpoint " + path +
              " is damaged: it does not end with its checksum (field 34, written last since "
              "checkpoint format 2); a checkpoint is used only if its coupler.pb matches the checksum written with it"};
}

// Refuses a checkpoint written by another format or version of the program.
void check_versions(const RestartPoint& point) {
  const auto& s = point.state;
  auto refuse = [&](const std::string& what, const std::string& found, const std::string& here) {
    throw RestartError("--restart " + point.run_dir + ": the checkpoint " + point.directory + " was written by " +
                       what + " " + found + "; this is " + what + " " + here +
                       ": it cannot continue that run (start the scene afresh)");
  };
  if (s.format() != kCouplerCheckpointFormat) {
    refuse("checkpoint format", std::to_string(s.format()), std::to_string(kCouplerCheckpointFormat));
  }
  if (s.program_version() != proto::kProgramVersion) refuse("hfmpm", s.program_version(), proto::kProgramVersion);
  if (s.protocol_version() != proto::kProtocolVersion) {
    refuse("protocol version", std::to_string(s.protocol_version()), std::to_string(proto::kProtocolVersion));
  }
  if (s.scene_schema_version() != proto::kSceneSchemaVersion) {
    refuse("scene schema version", std::to_string(s.scene_schema_version()),
           std::to_string(proto::kSceneSchemaVersion));
  }
}

}  // namespace

std::string coupler_checkpoint_bytes(checkpoint::CouplerState state) {
  state.clear_checksum();
  std::string bytes;
  if (!state.SerializeToString(&bytes)) throw std::runtime_error("cannot serialize the coupler's checkpoint");
  const std::uint64_t sum = fnv1a64(bytes);
  bytes.append(kChecksumTag, sizeof(kChecksumTag));
  for (std::size_t i = 0; i < 8; ++i) bytes.push_back(static_cast<char>((sum >> (8 * i)) & 0xffu));
  return bytes;
}

std::string checkpoint_directory(std::uint64_t step) {
  char text[48] = {};
  std::snprintf(text, sizeof(text), "checkpoints/%s%012llu", kPrefix, static_cast<unsigned long long>(step));
  return text;
}

RestartPoint find_restart(const std::string& run_dir, const SideFileCheck& check_side_file) {
  std::error_code error;
  if (!fs::is_directory(run_dir, error)) throw RestartError("--restart " + run_dir + ": no such run directory");
  const auto steps = complete_steps(run_dir);
  if (steps.empty()) {
    throw RestartError("--restart " + run_dir + ": no complete checkpoint in " + run_dir +
                       "/checkpoints (the scene needs output.checkpoint_interval_s > 0, and a checkpoint is "
                       "complete only once both sides and the coupler have written it)");
  }
  RestartPoint point;
  point.run_dir = run_dir;
  // The newest first; a damaged one is passed over for the one before it.
  for (auto step = steps.rbegin(); step != steps.rend(); ++step) {
    point.directory = checkpoint_directory(*step);
    const fs::path dir = fs::path(run_dir) / point.directory;
    point.state.Clear();
    const CouplerFile file = read_coupler_file((dir / "coupler.pb").string(), point.state);
    std::string problem = file.problem;
    if (file.intact || file.other_format) {
      check_versions(point);  // another format or version is refused, not passed over
      const std::pair<const char*, bool> sides[] = {{"solid", point.state.solid().expected()},
                                                    {"fluid", point.state.fluid().expected()}};
      for (const auto& [role, expected] : sides) {
        const fs::path side_file = dir / (std::string(role) + ".h5");
        if (!expected || !check_side_file || !fs::exists(side_file, error)) continue;
        try {
          check_side_file(side_file.string());
        } catch (const std::exception& e) {
          problem = e.what();
          break;
        }
      }
      if (problem.empty()) break;
    }
    point.damaged.push_back(point.directory + ": " + problem);
  }
  if (point.damaged.size() == steps.size()) {
    std::string each;
    for (const auto& d : point.damaged) each += (each.empty() ? "" : "; ") + d;
    throw RestartError("--restart " + run_dir + ": every complete checkpoint in " + run_dir +
                       "/checkpoints is damaged (" + each +
                       "); a checkpoint is used only if coupler.pb and each side's file match their checksums: "
                       "none can continue the run (start the scene afresh)");
  }
  if (proto::scene_hash(point.state.scene()) != point.state.scene_hash()) {
    throw RestartError("--restart " + run_dir + ": the checkpoint " + point.directory +
                       " is damaged (its scene does not match its scene hash)");
  }
  return point;
}

void check_restart_scene(const RestartPoint& point, const scene::Scene& scene) {
  const std::string hash = proto::scene_hash(scene);
  if (hash != point.state.scene_hash()) {
    throw RestartError("--restart " + point.run_dir + ": the checkpoint " + point.directory +
                       " was written for another scene (scene hash " + point.state.scene_hash() +
                       "; the scene given, with its --set overrides, hashes to " + hash +
                       "); give the run's own scene and overrides, or none to use the checkpoint's");
  }
}

void write_coupler_checkpoint(const std::string& run_dir, const std::string& directory,
                              const checkpoint::CouplerState& state) {
  const fs::path dir = fs::path(run_dir) / directory;
  fs::create_directories(dir);
  write_atomically((dir / "coupler.pb").string(), coupler_checkpoint_bytes(state));
  // Keep this one and the complete one before it; older ones (and directories
  // of cut-short checkpoints before those) go.
  const auto steps = complete_steps(run_dir);
  if (steps.size() < 2) return;
  const std::uint64_t keep_from = steps[steps.size() - 2];
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(fs::path(run_dir) / "checkpoints", error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kPrefix, 0) != 0) continue;
    const std::string digits = name.substr(std::char_traits<char>::length(kPrefix));
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 19) continue;
    if (std::stoull(digits) < keep_from) fs::remove_all(entry.path(), error);
  }
}

std::optional<std::uint64_t> truncate_history(const std::string& path, std::uint64_t step) {
  std::ifstream in(path);
  if (!in) throw RestartError("cannot read " + path + " to continue it");
  std::string line, kept;
  std::optional<std::uint64_t> last;
  bool header = true;
  while (std::getline(in, line)) {
    if (header) {
      kept += line + "\n";
      header = false;
      continue;
    }
    const auto first = line.find(',');
    if (first == std::string::npos) break;  // a row cut short by the kill
    const auto second = line.find(',', first + 1);
    if (second == std::string::npos) break;
    const std::string digits = line.substr(first + 1, second - first - 1);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) break;
    const std::uint64_t row_step = std::stoull(digits);
    if (row_step > step) break;
    if (last == row_step) continue;  // the same step again: one row per step
    kept += line + "\n";
    last = row_step;
  }
  in.close();
  write_atomically(path, kept);
  return last;
}

}  // namespace hfmpm::coupling
