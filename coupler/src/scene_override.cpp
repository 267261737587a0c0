// --set KEY=VALUE: a key path through the scene, into one element of a list
// by index or by name (docs/scenes.md, section 3).
#include <google/protobuf/text_format.h>

#include <memory>

#include "hfmpm/coupling/scene_loader.hpp"
#include "scene_text.hpp"

namespace hfmpm::coupling {
namespace scene_text {
namespace {

// Longest --set assignment read.
constexpr std::size_t kMaxAssignmentBytes = std::size_t{64} << 10;

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

}  // namespace

std::string apply_override_indexed(scene::Scene& scene, const std::string& assignment) {
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

}  // namespace scene_text

void apply_override(scene::Scene& scene, const std::string& assignment) {
  scene_text::apply_override_indexed(scene, assignment);
}

}  // namespace hfmpm::coupling
