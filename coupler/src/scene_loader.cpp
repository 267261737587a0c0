#include "hfmpm/coupling/scene_loader.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cctype>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace hfmpm::coupling {
namespace {

namespace pb = google::protobuf;

// Longest scene file and longest --set assignment read (a scene is a few kB).
constexpr std::size_t kMaxSceneBytes = std::size_t{16} << 20;
constexpr std::size_t kMaxAssignmentBytes = std::size_t{64} << 10;

// The text between `prefix` (which ends with an opening quote) and the next
// '"', at the first place `prefix` occurs in `message` and is followed by a
// closing quote. `from` is where the search starts; `end` gets the position
// after the closing quote.
bool quoted_after(const std::string& message, const std::string& prefix, std::string& out, std::size_t from = 0,
                  std::size_t* end = nullptr) {
  const auto start = message.find(prefix, from);
  if (start == std::string::npos) return false;
  const auto first = start + prefix.size();
  const auto close = message.find('"', first);
  if (close == std::string::npos) return false;
  out = message.substr(first, close - first);
  if (end) *end = close + 1;
  return true;
}

// Parses protobuf's 'Message type "T" has no field named "K"' (T of
// [A-Za-z0-9_.]+), wherever it is in `message`.
bool unknown_field(const std::string& message, std::string& type, std::string& key) {
  const std::string prefix = "Message type \"";
  const std::string middle = " has no field named \"";
  for (std::size_t from = 0; from < message.size();) {
    std::size_t after = 0;
    if (!quoted_after(message, prefix, type, from, &after)) return false;
    from = message.find(prefix, from) + 1;
    const bool type_ok = !type.empty() && std::all_of(type.begin(), type.end(), [](char ch) {
      return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.';
    });
    if (!type_ok || message.compare(after, middle.size(), middle) != 0) continue;
    if (quoted_after(message, middle, key, after)) return true;
  }
  return false;
}

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

std::string field_names(const pb::Descriptor* type) {
  std::vector<std::string> names;
  for (int i = 0; i < type->field_count(); ++i) names.push_back(type->field(i)->name());
  return join(names, ", ");
}

// Collects text-format errors as "file:line:column: message", naming the
// allowed keys when a key is unknown.
class Collector : public pb::io::ErrorCollector {
 public:
  explicit Collector(std::string name, std::string source = "") : name_(std::move(name)), source_(std::move(source)) {}
  void AddError(int line, pb::io::ColumnNumber column, const std::string& message) override {
    // Protobuf places an unknown enum value at the token after it, which may
    // be on the next line: point at the last line up to there that holds it.
    // (Plain string scanning: the message quotes user text, of any length.)
    std::string token;
    if (quoted_after(message, "Unknown enumeration value of \"", token)) line = line_of_token_before(token, line);
    std::string text = name_ + ":" + std::to_string(line + 1) + ":" + std::to_string(column + 1) + ": " + message;
    std::string type_name, key;
    if (unknown_field(message, type_name, key)) {
      if (const auto* type = pb::DescriptorPool::generated_pool()->FindMessageTypeByName(type_name)) {
        text = name_ + ":" + std::to_string(line + 1) + ": unknown key '" + key + "' in " + type->name() +
               "; allowed: " + field_names(type);
      }
    }
    errors_.push_back(text);
  }
  void AddWarning(int, pb::io::ColumnNumber, const std::string&) override {}
  std::vector<std::string> errors_;

 private:
  int line_of_token_before(const std::string& token, int line) const {
    std::stringstream lines(source_);
    std::string text;
    int found = line;
    for (int i = 0; i <= line && std::getline(lines, text); ++i) {
      if (text.find(token) != std::string::npos) found = i;
    }
    return found;
  }
  std::string name_;
  std::string source_;
};

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

std::string describe(const SceneProblem& p, const std::string& name, int line,
                     const std::set<std::string>& overridden) {
  std::string where = name;
  for (const auto& key : overridden) {
    if (p.key == key || p.key.rfind(key + ".", 0) == 0 || p.key.rfind(key + "[", 0) == 0) {
      where = "--set " + key;
      line = 0;
    }
  }
  if (line > 0) where += ":" + std::to_string(line);
  return where + ": " + proto::problem_text(p);
}

std::string quote(const std::string& value) {
  std::string out = "\"";
  for (char ch : value) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

}  // namespace

SceneError::SceneError(const std::vector<std::string>& problems)
    : std::runtime_error(join(problems, "\n")), problems_(problems) {}

void apply_override(scene::Scene& scene, const std::string& assignment) {
  if (assignment.size() > kMaxAssignmentBytes) {
    throw SceneError({"--set " + assignment.substr(0, std::min<std::size_t>(assignment.find('='), 100)) + ": " +
                      std::to_string(assignment.size()) + " characters; an override may have at most " +
                      std::to_string(kMaxAssignmentBytes)});
  }
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw SceneError({"--set " + assignment + ": expected KEY=VALUE, e.g. --set time.end_s=2"});
  }
  const std::string key = assignment.substr(0, equals);
  std::string value = assignment.substr(equals + 1);
  if (value.empty()) throw SceneError({"--set " + key + "=: no value given; write --set " + key + "=VALUE"});
  pb::Message* message = &scene;
  std::stringstream parts(key);
  std::string part, path;
  std::vector<std::string> components;
  while (std::getline(parts, part, '.')) components.push_back(part);
  for (std::size_t i = 0; i < components.size(); ++i) {
    const auto* type = message->GetDescriptor();
    const auto* field = type->FindFieldByName(components[i]);
    path += (i ? "." : "") + components[i];
    if (!field) {
      throw SceneError({"--set " + key + ": '" + components[i] + "' is not a key of " +
                        (i ? type->name() : std::string("the scene")) + "; allowed: " + field_names(type)});
    }
    if (i + 1 < components.size()) {
      if (field->type() != pb::FieldDescriptor::TYPE_MESSAGE || field->is_repeated()) {
        throw SceneError({"--set " + key + ": '" + path + "' holds a value, not further keys"});
      }
      message = message->GetReflection()->MutableMessage(message, field);
      continue;
    }
    if (field->type() == pb::FieldDescriptor::TYPE_STRING) {
      if (field->is_repeated()) {
        if (value.empty() || value.front() != '[') value = "[" + quote(value) + "]";
      } else if (value.empty() || value.front() != '"') {
        value = quote(value);
      }
    } else if (field->is_repeated() && (value.empty() || value.front() != '[')) {
      value = "[" + value + "]";
    }
    message->GetReflection()->ClearField(message, field);
    pb::TextFormat::Parser parser;
    Collector collector("--set " + key);
    parser.RecordErrorsTo(&collector);
    const std::string separator =
        field->type() == pb::FieldDescriptor::TYPE_MESSAGE && value.front() == '{' ? " " : ": ";
    if (!parser.MergeFromString(field->name() + separator + value, message)) {
      throw SceneError({"--set " + key + "=" + assignment.substr(equals + 1) + ": not a valid " +
                        (field->type() == pb::FieldDescriptor::TYPE_MESSAGE ? field->message_type()->name()
                                                                            : std::string(field->type_name())) +
                        " value for " + key});
    }
  }
}

scene::Scene parse_scene(const std::string& file_text, const std::string& name, const SceneRules& rules,
                         const std::vector<std::string>& overrides) {
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
  std::set<std::string> overridden;
  for (const auto& assignment : overrides) {
    apply_override(scene, assignment);
    overridden.insert(assignment.substr(0, assignment.find('=')));
  }
  const auto problems = validate(scene, rules);
  if (!problems.empty()) {
    std::vector<std::string> lines;
    for (const auto& p : problems)
      lines.push_back(describe(p, name, line_of(&tree, scene.GetDescriptor(), p.key), overridden));
    throw SceneError(lines);
  }
  return scene;
}

scene::Scene load_scene(const std::string& path, const SceneRules& rules, const std::vector<std::string>& overrides) {
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
  return parse_scene(text.str(), path, rules, overrides);
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
