#include "hfmpm/coupling/scene_loader.hpp"

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

std::string quote(const std::string& value) {
  std::string out = "\"";
  for (char ch : value) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

// One component of a --set key: a field's name and, in brackets, one element
// of a repeated field: an index (cracks[1]) or, where the elements are
// messages with a string field `name`, a name (materials[rock],
// materials["rock"]; quotes for a name that starts with a digit or a sign or
// holds ']', with \" and \\ inside them).
struct KeyPart {
  std::string field;
  bool bracket = false;
  bool quoted = false;
  std::string selector;  // between the brackets, without the quotes
  std::string written;   // the brackets as written
};

constexpr const char* kKeyForm =
    "a key is NAME.NAME..., with [INDEX] or [NAME] after the name of a list, e.g. solid.mpm.cracks[0].x_m or "
    "solid.mpm.materials[rock].youngs_modulus_pa";

std::vector<KeyPart> split_key(const std::string& key) {
  const auto refuse = [&](const std::string& why) {
    return SceneError({"--set " + key + ": " + why + "; " + kKeyForm});
  };
  std::vector<KeyPart> parts;
  std::size_t i = 0;
  while (true) {
    KeyPart part;
    const auto stop = std::min(key.find_first_of(".[", i), key.size());
    part.field = key.substr(i, stop - i);
    i = stop;
    if (i < key.size() && key[i] == '[') {
      const auto open = i++;
      part.bracket = true;
      if (i < key.size() && (key[i] == '"' || key[i] == '\'')) {
        const char mark = key[i++];
        part.quoted = true;
        bool closed = false;
        while (i < key.size() && !closed) {
          char ch = key[i++];
          if (ch == mark) {
            closed = true;
          } else {
            if (ch == '\\' && i < key.size()) ch = key[i++];
            part.selector += ch;
          }
        }
        if (!closed) throw refuse("the quote after '" + part.field + "[' is not closed");
        if (i >= key.size() || key[i] != ']')
          throw refuse("']' expected after the quoted name in '" + part.field + "['");
      } else {
        const auto close = key.find(']', i);
        if (close == std::string::npos) throw refuse("'[' after '" + part.field + "' is not closed");
        part.selector = key.substr(i, close - i);
        if (part.selector.empty()) throw refuse("nothing between the brackets of '" + part.field + "[]'");
        i = close;
      }
      ++i;  // past ']'
      part.written = key.substr(open, i - open);
      if (i < key.size() && key[i] != '.') {
        throw refuse("'.' or the end expected after '" + part.field + part.written + "', not '" + key.substr(i, 1) +
                     "'");
      }
    }
    parts.push_back(part);
    if (i >= key.size()) return parts;
    ++i;  // past '.'
  }
}

// The string field `name` of a repeated message field's elements, if they have one.
const pb::FieldDescriptor* name_field(const pb::FieldDescriptor* field) {
  if (field->cpp_type() != pb::FieldDescriptor::CPPTYPE_MESSAGE) return nullptr;
  const auto* name = field->message_type()->FindFieldByName("name");
  return name && !name->is_repeated() && name->type() == pb::FieldDescriptor::TYPE_STRING ? name : nullptr;
}

// A name as it is selected: [rock], or ["1a"] where it needs quotes.
std::string bracketed(const std::string& name) {
  const bool plain = !name.empty() && std::string("0123456789+-\"'").find(name.front()) == std::string::npos &&
                     name.find(']') == std::string::npos;
  return "[" + (plain ? name : quote(name)) + "]";
}

// "solid.mpm.cracks has 1 element; allowed: [0]", with the names where the elements have them.
std::string elements_allowed(const pb::Message& message, const pb::FieldDescriptor* field, const std::string& path) {
  const auto* reflection = message.GetReflection();
  const int size = reflection->FieldSize(message, field);
  std::string text = path + " has " +
                     (size == 0   ? std::string("no elements")
                      : size == 1 ? std::string("1 element")
                                  : std::to_string(size) + " elements") +
                     "; allowed: " +
                     (size == 0   ? std::string("none")
                      : size == 1 ? std::string("[0]")
                                  : "[0] to [" + std::to_string(size - 1) + "]");
  if (const auto* name = name_field(field); name && size > 0) {
    constexpr int kMaxNames = 20;
    std::vector<std::string> names;
    for (int k = 0; k < size && k < kMaxNames; ++k) {
      const auto& element = reflection->GetRepeatedMessage(message, field, k);
      names.push_back(bracketed(element.GetReflection()->GetString(element, name)));
    }
    if (size > kMaxNames) names.push_back("...");
    text += " or by name " + join(names, ", ");
  }
  return text;
}

// The element that `part`'s brackets select in `field` of `message` (`path`
// is the field's key as written); throws SceneError naming what is allowed.
int element_index(const pb::Message& message, const pb::FieldDescriptor* field, const KeyPart& part,
                  const std::string& key, const std::string& path) {
  const auto refuse = [&](const std::string& why) { return SceneError({"--set " + key + ": " + why}); };
  if (!field->is_repeated()) {
    throw refuse("'" + path + "' is not a list; brackets select one element of a repeated key");
  }
  const auto* reflection = message.GetReflection();
  const int size = reflection->FieldSize(message, field);
  const std::string& s = part.selector;
  if (!part.quoted && std::isdigit(static_cast<unsigned char>(s.front())) == 0 && s.front() != '-' &&
      s.front() != '+') {
    // A name.
  } else if (!part.quoted) {
    const bool digits =
        std::all_of(s.begin(), s.end(), [](char ch) { return std::isdigit(static_cast<unsigned char>(ch)) != 0; });
    if (!digits) {
      throw refuse("'" + s + "' is not an index (a whole number from 0)" +
                   (name_field(field) ? "; a name that starts with a digit or a sign is written in quotes, " +
                                            part.field + bracketed(s)
                                      : std::string()) +
                   "; " + elements_allowed(message, field, path));
    }
    const auto first = s.find_first_not_of('0');
    const std::string number = first == std::string::npos ? "0" : s.substr(first);
    const long long index = number.size() > 10 ? -1 : std::stoll(number);
    if (index < 0 || index >= size) {
      const std::string example =
          field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE ? "[{...}, {...}]" : "[a, b]";
      throw refuse(elements_allowed(message, field, path) + " (--set does not add elements: to add one, set the " +
                   "whole list, --set '" + path + "=" + example + "')");
    }
    return static_cast<int>(index);
  }
  const auto* name = name_field(field);
  if (!name) {
    throw refuse((field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE
                      ? "the elements of " + path + " (" + field->message_type()->name() + ") have no name"
                      : path + " holds values, not named elements") +
                 ": select one by index, not by " + quote(s) + "; " + elements_allowed(message, field, path));
  }
  std::vector<int> found;
  for (int k = 0; k < size; ++k) {
    const auto& element = reflection->GetRepeatedMessage(message, field, k);
    if (element.GetReflection()->GetString(element, name) == s) found.push_back(k);
  }
  if (found.empty()) {
    throw refuse(path + " has no element named " + quote(s) + "; " + elements_allowed(message, field, path));
  }
  if (found.size() > 1) {
    std::vector<std::string> indices;
    for (int k : found) indices.push_back("[" + std::to_string(k) + "]");
    throw refuse(path + " has " + std::to_string(found.size()) + " elements named " + quote(s) + " (" +
                 join(indices, ", ") + "); select one by index");
  }
  return found.front();
}

// Replaces element `index` of repeated `field` of `message` by `value`
// (one value, or one message in braces), written as in a scene file.
void set_element(pb::Message& message, const pb::FieldDescriptor* field, int index, std::string value,
                 const std::string& key, const std::string& written_value) {
  if (field->type() == pb::FieldDescriptor::TYPE_STRING && value.front() != '"') value = quote(value);
  const bool is_message = field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE;
  std::unique_ptr<pb::Message> scratch(message.New());
  pb::TextFormat::Parser parser;
  Collector collector("--set " + key);
  parser.RecordErrorsTo(&collector);
  const std::string separator = is_message && value.front() == '{' ? " " : ": ";
  const auto* reflection = message.GetReflection();
  std::vector<const pb::FieldDescriptor*> set;
  const bool parsed = parser.MergeFromString(field->name() + separator + value, scratch.get());
  if (parsed) reflection->ListFields(*scratch, &set);
  if (!parsed || set.size() != 1 || set.front() != field) {
    throw SceneError({"--set " + key + "=" + written_value + ": not a valid " +
                      (is_message ? field->message_type()->name() : std::string(field->type_name())) + " value for " +
                      key});
  }
  const int count = reflection->FieldSize(*scratch, field);
  if (count != 1) {
    throw SceneError({"--set " + key + "=" + written_value + ": " + std::to_string(count) +
                      " values for one element (" + key + "); give one" +
                      (is_message ? " message in braces, {...}" : "")});
  }
  // Appended (scratch holds this field alone), then swapped into place.
  message.MergeFrom(*scratch);
  const int last = reflection->FieldSize(message, field) - 1;
  reflection->SwapElements(&message, field, index, last);
  reflection->RemoveLast(&message, field);
}

// apply_override; returns the key as validation names it (indices, not names).
std::string apply_one(scene::Scene& scene, const std::string& assignment) {
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
  const auto components = split_key(key);
  scene::Scene result = scene;  // the scene is left as it was if the override is refused
  pb::Message* message = &result;
  std::string path;     // the key up to here, as written
  std::string indexed;  // the same with indices for names
  for (std::size_t i = 0; i < components.size(); ++i) {
    const auto& part = components[i];
    const auto* type = message->GetDescriptor();
    const auto* reflection = message->GetReflection();
    const auto* field = type->FindFieldByName(part.field);
    path += (i ? "." : "") + part.field;
    indexed += (i ? "." : "") + part.field;
    if (!field) {
      throw SceneError({"--set " + key + ": '" + part.field + "' is not a key of " +
                        (i ? type->name() : std::string("the scene")) + "; allowed: " + field_names(type)});
    }
    const bool last = i + 1 == components.size();
    int index = -1;
    if (part.bracket) {
      index = element_index(*message, field, part, key, path);
      path += part.written;
      indexed += "[" + std::to_string(index) + "]";
    } else if (!last && field->is_repeated() && field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE) {
      throw SceneError({"--set " + key + ": '" + path + "' is a list; select one element, " + path + "[0]." +
                        components[i + 1].field + "; " + elements_allowed(*message, field, path)});
    }
    if (!last) {
      if (field->cpp_type() != pb::FieldDescriptor::CPPTYPE_MESSAGE) {
        throw SceneError({"--set " + key + ": '" + path + "' holds a value, not further keys"});
      }
      message = index >= 0 ? reflection->MutableRepeatedMessage(message, field, index)
                           : reflection->MutableMessage(message, field);
      continue;
    }
    if (index >= 0) {
      set_element(*message, field, index, value, key, assignment.substr(equals + 1));
      break;
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
    reflection->ClearField(message, field);
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
  scene = std::move(result);
  return indexed;
}

}  // namespace

SceneError::SceneError(const std::vector<std::string>& problems)
    : std::runtime_error(join(problems, "\n")), problems_(problems) {}

void apply_override(scene::Scene& scene, const std::string& assignment) { apply_one(scene, assignment); }

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
    overridden.push_back({apply_one(scene, assignment), assignment.substr(0, assignment.find('='))});
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
