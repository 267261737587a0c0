// Test helper: a small, strict XML parser, enough to check the XDMF files FrameWriter writes. Accepts an
// optional <?xml ...?> declaration, comments, elements with quoted attributes, text and the five predefined
// entities; rejects anything else (unbalanced or mismatched tags, duplicate attributes, stray '<' or '&',
// content after the root element, DOCTYPE) with std::runtime_error giving the offset.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace hfmpm::test::xml {

struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;  // character data directly inside, entities resolved, concatenated
  std::vector<Element> children;

  const std::string& attribute(const std::string& key) const;  // throws if missing
  std::vector<const Element*> all(const std::string& child_name) const;
};

Element parse(const std::string& text);

}  // namespace hfmpm::test::xml
