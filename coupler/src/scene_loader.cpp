#include "hfmpm/coupling/scene_loader.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace hfmpm::coupling {
namespace {

namespace pb = google::protobuf;

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
    static const std::regex bad_enum(R"re(Unknown enumeration value of "([^"]*)")re");
    std::smatch e;
    if (std::regex_search(message, e, bad_enum)) line = line_of_token_before(e[1].str(), line);
    std::string text = name_ + ":" + std::to_string(line + 1) + ":" + std::to_string(column + 1) + ": " + message;
    static const std::regex unknown(R"re(Message type "([A-Za-z0-9_.]+)" has no field named "([^"]*)")re");
    std::smatch m;
    if (std::regex_search(message, m, unknown)) {
      if (const auto* type = pb::DescriptorPool::generated_pool()->FindMessageTypeByName(m[1].str())) {
        text = name_ + ":" + std::to_string(line + 1) + ": unknown key '" + m[2].str() + "' in " + type->name() +
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

std::string describe(const SceneProblem& p, const std::string& name, int line, const std::set<std::string>& overridden) {
  std::string where = name;
  for (const auto& key : overridden) {
    if (p.key == key || p.key.rfind(key + ".", 0) == 0 || p.key.rfind(key + "[", 0) == 0) {
      where = "--set " + key;
      line = 0;
    }
  }
  if (line > 0) where += ":" + std::to_string(line);
  if (p.value.empty()) return where + ": " + p.key + " is missing; expected " + p.allowed;
  return where + ": " + p.key + " = " + p.value + " is not allowed; expected " + p.allowed;
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
    const std::string separator = field->type() == pb::FieldDescriptor::TYPE_MESSAGE && value.front() == '{' ? " " : ": ";
    if (!parser.MergeFromString(field->name() + separator + value, message)) {
      throw SceneError({"--set " + key + "=" + assignment.substr(equals + 1) + ": not a valid " +
                        (field->type() == pb::FieldDescriptor::TYPE_MESSAGE ? field->message_type()->name()
                                                                            : std::string(field->type_name())) +
                        " value for " + key});
    }
  }
}

scene::Scene parse_scene(const std::string& text, const std::string& name, const std::vector<std::string>& overrides) {
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
  const auto problems = validate(scene);
  if (!problems.empty()) {
    std::vector<std::string> lines;
    for (const auto& p : problems) lines.push_back(describe(p, name, line_of(&tree, scene.GetDescriptor(), p.key), overridden));
    throw SceneError(lines);
  }
  return scene;
}

scene::Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) throw SceneError({path + ": cannot read the scene file (does it exist?)"});
  std::stringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path, overrides);
}

}  // namespace hfmpm::coupling
