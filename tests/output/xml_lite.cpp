// Test helper: strict little XML parser (see xml_lite.hpp).
#include "xml_lite.hpp"

#include <stdexcept>

namespace hfmpm::test::xml {
namespace {

class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  Element document() {
    skip_space();
    if (starts("<?xml")) {
      const auto end = s_.find("?>", i_);
      if (end == std::string::npos) error("unterminated XML declaration");
      i_ = end + 2;
    }
    skip_misc();
    if (!starts("<") || starts("</")) error("expected the root element");
    Element root = element();
    skip_misc();
    if (i_ != s_.size()) error("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void error(const std::string& what) const {
    throw std::runtime_error("XML error at offset " + std::to_string(i_) + ": " + what);
  }
  bool starts(const char* prefix) const { return s_.compare(i_, std::char_traits<char>::length(prefix), prefix) == 0; }
  static bool space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  static bool name_char(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == ':' ||
           c == '-' || c == '.';
  }
  void skip_space() {
    while (i_ < s_.size() && space(s_[i_])) ++i_;
  }
  void skip_misc() {  // whitespace and comments
    for (;;) {
      skip_space();
      if (!starts("<!--")) return;
      comment();
    }
  }
  void comment() {
    const auto end = s_.find("-->", i_ + 4);
    if (end == std::string::npos) error("unterminated comment");
    i_ = end + 3;
  }
  std::string name() {
    const std::size_t begin = i_;
    while (i_ < s_.size() && name_char(s_[i_])) ++i_;
    if (i_ == begin) error("expected a name");
    return s_.substr(begin, i_ - begin);
  }
  std::string characters(char stop) {  // up to (not including) stop, resolving entities
    std::string out;
    while (i_ < s_.size() && s_[i_] != stop) {
      const char c = s_[i_];
      if (c == '<') error("'<' in character data");
      if (c == '&') {
        const auto semi = s_.find(';', i_);
        if (semi == std::string::npos) error("unterminated entity");
        const std::string entity = s_.substr(i_ + 1, semi - i_ - 1);
        if (entity == "amp")
          out += '&';
        else if (entity == "lt")
          out += '<';
        else if (entity == "gt")
          out += '>';
        else if (entity == "quot")
          out += '"';
        else if (entity == "apos")
          out += '\'';
        else
          error("unknown entity &" + entity + ";");
        i_ = semi + 1;
      } else {
        out += c;
        ++i_;
      }
    }
    return out;
  }
  Element element() {
    ++i_;  // '<'
    Element e;
    e.name = name();
    for (;;) {
      const std::size_t before = i_;
      skip_space();
      if (starts("/>")) {
        i_ += 2;
        return e;
      }
      if (starts(">")) {
        ++i_;
        break;
      }
      if (i_ == before) error("expected whitespace before an attribute of <" + e.name + ">");
      const std::string key = name();
      skip_space();
      if (!starts("=")) error("expected '=' after attribute " + key);
      ++i_;
      skip_space();
      if (i_ >= s_.size() || (s_[i_] != '"' && s_[i_] != '\'')) error("expected a quoted value for " + key);
      const char quote = s_[i_++];
      std::string value = characters(quote);
      if (i_ >= s_.size()) error("unterminated attribute value");
      ++i_;
      if (!e.attributes.emplace(key, value).second) error("duplicate attribute " + key + " in <" + e.name + ">");
    }
    for (;;) {  // content
      if (i_ >= s_.size()) error("missing </" + e.name + ">");
      if (starts("</")) {
        i_ += 2;
        const std::string closing = name();
        if (closing != e.name) error("</" + closing + "> closes <" + e.name + ">");
        skip_space();
        if (!starts(">")) error("expected '>'");
        ++i_;
        return e;
      }
      if (starts("<!--")) {
        comment();
      } else if (starts("<![CDATA[") || starts("<!") || starts("<?")) {
        error("unsupported markup");
      } else if (starts("<")) {
        e.children.push_back(element());
      } else {
        e.text += characters('<');
      }
    }
  }

  const std::string& s_;
  std::size_t i_ = 0;
};

}  // namespace

const std::string& Element::attribute(const std::string& key) const {
  const auto it = attributes.find(key);
  if (it == attributes.end()) throw std::runtime_error("<" + name + "> has no attribute " + key);
  return it->second;
}

std::vector<const Element*> Element::all(const std::string& child_name) const {
  std::vector<const Element*> out;
  for (const Element& c : children) {
    if (c.name == child_name) out.push_back(&c);
  }
  return out;
}

Element parse(const std::string& text) { return Parser(text).document(); }

}  // namespace hfmpm::test::xml
