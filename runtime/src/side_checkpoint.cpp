#include "side_checkpoint.hpp"

#include <filesystem>
#include <iostream>
#include <system_error>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/runtime/transport.hpp"

namespace hfmpm::coupling {

std::string checkpoint_path(const std::string& output_dir, const std::string& directory, const std::string& role) {
  if (directory.empty() || directory.front() == '/' || directory.find("..") != std::string::npos) {
    throw proto::ProtocolError("checkpoint directory '" + printable(directory) +
                               "' must be a relative path inside the output directory");
  }
  const std::filesystem::path dir = std::filesystem::path(output_dir) / directory;
  std::filesystem::create_directories(dir);
  return (dir / (role + ".h5")).string();
}

CheckpointStamp checkpoint_stamp(const SideOptions& options, const std::string& role, const scene::Scene& scene,
                                 std::uint64_t step, double t) {
  CheckpointStamp s;
  s.role = role;
  s.implementation = options.implementation;
  s.program_version = options.implementation_version;
  s.protocol_version = options.protocol_version;
  s.scene_schema_version = options.scene_schema_version;
  s.scene_hash = proto::scene_hash(scene);
  s.step = step;
  s.t = t;
  return s;
}

double write_side_checkpoint(SideModel& model, const std::string& path, const CheckpointStamp& stamp,
                             const std::string& role) {
  const auto start = Clock::now();
  model.save_checkpoint(path, stamp);
  const double took = seconds_since(start);
  std::error_code size_error;
  const auto bytes = std::filesystem::file_size(path, size_error);
  std::cerr << role << ": checkpoint " << path << " written in " << took << " s ("
            << (size_error ? 0.0 : static_cast<double>(bytes) / 1e6) << " MB)\n";
  return took;
}

}  // namespace hfmpm::coupling
