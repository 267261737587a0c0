// Text helpers of the scene loader and of --set (internal to coupler/src):
// parser errors with the allowed keys named, quoting, joining.
#pragma once

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>

#include <algorithm>
#include <cctype>
#include <sstream>
#include <string>
#include <vector>

#include "hfmpm/scene.pb.h"

namespace hfmpm::coupling::scene_text {

namespace pb = google::protobuf;

// The text between `prefix` (which ends with an opening quote) and the next
// '"', at the first place `prefix` occurs in `message` and is followed by a
// closing quote. `from` is where the search starts; `end` gets the position
// after the closing quote.
inline bool quoted_after(const std::string& message, const std::string& prefix, std::string& out, std::size_t from = 0,
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
inline bool unknown_field(const std::string& message, std::string& type, std::string& key) {
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

inline std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

inline std::string field_names(const pb::Descriptor* type) {
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

inline std::string quote(const std::string& value) {
  std::string out = "\"";
  for (char ch : value) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

// --set KEY=VALUE applied to `scene` (scene_override.cpp); returns the key
// as validation names it (indices for names). Throws SceneError, leaving the
// scene as it was.
std::string apply_override_indexed(scene::Scene& scene, const std::string& assignment);

}  // namespace hfmpm::coupling::scene_text
