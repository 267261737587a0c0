#include "hfmpm/coupling/scene_loader.hpp"

#include "scene_text.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cctype>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

namespace hfmpm::coupling {
namespace {

using scene_text::Collector;
using scene_text::join;

namespace pb = google::protobuf;

// Longest scene file read (a scene is a few kB).
constexpr std::size_t kMaxSceneBytes = std::size_t{16} << 20;

// Line (1-based) where the key path was written, or 0 if it was not written.
int line_of(const pb::TextFormat::ParseInfoTree* tree, const pb::Descriptor* type, const std::string& key) {
  std::stringstream parts(key);
  std::string part;
  int line = 0;
  while (tree && type && std::getline(parts, part, '.')) {
    int index = -1;
    const auto bracket = part.find('[');
    if (bracket != std::string::npos) {
      index = std::stoi(part.substr(bracket + 1));
      part = part.substr(0, bracket);
    }
    const auto* field = type->FindFieldByName(part);
    if (!field) break;
    const auto location = tree->GetLocation(field, field->is_repeated() ? std::max(index, 0) : -1);
    if (location.line < 0) break;
    line = location.line + 1;
    if (field->type() != pb::FieldDescriptor::TYPE_MESSAGE) break;
    tree = tree->GetTreeForNested(field, field->is_repeated() ? std::max(index, 0) : -1);
    type = field->message_type();
  }
  return line;
}

// An override: the key as validation names it (numeric indices) and as written.
struct Overridden {
  std::string key;
  std::string written;
};

std::string describe(const SceneProblem& p, const std::string& name, int line,
                     const std::vector<Overridden>& overridden) {
  std::string where = name;
  for (const auto& o : overridden) {  // in order: a later override wins
    const auto& key = o.key;
    if (p.key == key || p.key.rfind(key + ".", 0) == 0 || p.key.rfind(key + "[", 0) == 0) {
      where = "--set " + o.written;
      line = 0;
    }
  }
  if (line > 0) where += ":" + std::to_string(line);
  return where + ": " + proto::problem_text(p);
}

}  // namespace

SceneError::SceneError(const std::vector<std::string>& problems)
    : std::runtime_error(join(problems, "\n")), problems_(problems) {}

scene::Scene parse_scene(const std::string& file_text, const std::string& name, const SceneRules& rules,
                         const std::vector<std::string>& overrides, std::vector<method::Setting>* derived) {
  if (file_text.size() > kMaxSceneBytes) {
    throw SceneError({name + ": " + std::to_string(file_text.size()) + " bytes; a scene file may have at most " +
                      std::to_string(kMaxSceneBytes)});
  }
  // A UTF-8 byte order mark (some Windows editors write one) is skipped; a
  // UTF-16 file is refused by name rather than by the parser's first complaint.
  const std::string bom = "\xEF\xBB\xBF";
  const std::string text = file_text.compare(0, bom.size(), bom) == 0 ? file_text.substr(bom.size()) : file_text;
  if (text.size() >= 2 && ((text[0] == '\xFF' && text[1] == '\xFE') || (text[0] == '\xFE' && text[1] == '\xFF'))) {
    throw SceneError({name + ": the file is UTF-16 (it starts with a UTF-16 byte order mark); save it as UTF-8"});
  }
  scene::Scene scene;
  pb::TextFormat::Parser parser;
  Collector collector(name, text);
  pb::TextFormat::ParseInfoTree tree;
  parser.RecordErrorsTo(&collector);
  parser.WriteLocationsTo(&tree);
  if (!parser.ParseFromString(text, &scene)) {
    if (collector.errors_.empty()) collector.errors_.push_back(name + ": not a valid scene file");
    throw SceneError(collector.errors_);
  }
  std::vector<Overridden> overridden;
  for (const auto& assignment : overrides) {
    overridden.push_back(
        {scene_text::apply_override_indexed(scene, assignment), assignment.substr(0, assignment.find('='))});
  }
  // The method keys left unset, derived from the physics (the rules then
  // check the scene as it will run; a derived value they refuse is named so).
  std::vector<method::Setting> settings;
  scene = method::with_method(scene, &settings);
  const auto problems = validate(scene, rules);
  if (!problems.empty()) {
    std::vector<std::string> lines;
    for (const auto& p : problems) {
      std::string line = describe(p, name, line_of(&tree, scene.GetDescriptor(), p.key), overridden);
      for (const auto& s : settings) {
        if (p.key == s.key || p.key.rfind(s.key + ".", 0) == 0) {
          line += " (" + s.key + " was derived: " + s.rule + "; set it in the scene to choose another value)";
        }
      }
      lines.push_back(line);
    }
    throw SceneError(lines);
  }
  if (derived) *derived = settings;
  return scene;
}

scene::Scene load_scene(const std::string& path, const SceneRules& rules, const std::vector<std::string>& overrides,
                        std::vector<method::Setting>* derived) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw SceneError({path + ": is a directory, not a scene file"});
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError({path + ": cannot read the scene file (does it exist?)"});
  const auto size = std::filesystem::file_size(path, error);
  if (!error && size > kMaxSceneBytes) {
    throw SceneError({path + ": " + std::to_string(size) + " bytes; a scene file may have at most " +
                      std::to_string(kMaxSceneBytes)});
  }
  std::stringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path, rules, overrides, derived);
}

namespace {

void fill_defaults(google::protobuf::Message& message) {
  const auto* type = message.GetDescriptor();
  const auto* reflection = message.GetReflection();
  for (int i = 0; i < type->field_count(); ++i) {
    const auto* field = type->field(i);
    if (field->is_repeated() || field->real_containing_oneof()) {
      if (field->real_containing_oneof() && field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE &&
          reflection->HasField(message, field)) {
        fill_defaults(*reflection->MutableMessage(&message, field));
      }
      if (field->is_repeated() && field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE) {
        for (int k = 0; k < reflection->FieldSize(message, field); ++k) {
          fill_defaults(*reflection->MutableRepeatedMessage(&message, field, k));
        }
      }
      continue;
    }
    if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE) {
      if (reflection->HasField(message, field)) fill_defaults(*reflection->MutableMessage(&message, field));
    } else if (!reflection->HasField(message, field) && field->has_default_value()) {
      std::string text;
      google::protobuf::TextFormat::PrintFieldValueToString(message, field, -1, &text);
      google::protobuf::TextFormat::ParseFieldValueFromString(text, field, &message);
    }
  }
}

}  // namespace

scene::Scene with_defaults(const scene::Scene& scene) {
  scene::Scene filled = scene;
  filled.mutable_time();  // blocks whose every field has a default
  filled.mutable_output();
  filled.mutable_coupling();
  fill_defaults(filled);
  return filled;
}

}  // namespace hfmpm::coupling
