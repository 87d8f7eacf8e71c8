#pragma once
/// Walking a KBL document (pugixml), shared by the KBL reader and writer: element names
/// without their namespace prefix, children by name, and a depth-first visit that does not
/// recurse (the nesting is the file's to choose).

#include <pugixml.hpp>

#include <cstring>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace loom::kbl_dom {

/// How loom parses KBL text, reading and writing alike. The writer keeps declarations,
/// processing instructions and comments, so the reader parses them too: a text the reader
/// accepts must parse again when it is written back (a malformed comment, skipped unread
/// by pugixml's default flags, made the writer fail on a file the reader had taken).
constexpr unsigned kKblParseFlags =
    pugi::parse_default | pugi::parse_doctype | pugi::parse_declaration | pugi::parse_pi | pugi::parse_comments;

/// The element name without a namespace prefix ("kbl:Node" → "Node").
inline std::string_view local_name(const pugi::xml_node& n) {
  const char* name = n.name();
  const char* colon = std::strrchr(name, ':');
  return colon ? colon + 1 : name;
}

/// The first child element with this local name (empty if none).
inline pugi::xml_node child(const pugi::xml_node& n, std::string_view name) {
  for (auto c : n.children())
    if (c.type() == pugi::node_element && local_name(c) == name) return c;
  return {};
}

/// Every child element with this local name, in order.
inline std::vector<pugi::xml_node> children(const pugi::xml_node& n, std::string_view name) {
  std::vector<pugi::xml_node> out;
  for (auto c : n.children())
    if (c.type() == pugi::node_element && local_name(c) == name) out.push_back(c);
  return out;
}

/// An element as messages name it: `<kbl:Node id="N1">` (the id when it has one).
inline std::string describe(const pugi::xml_node& n) {
  std::string s = "<" + std::string(n.name());
  if (auto a = n.attribute("id")) s += " id=\"" + std::string(a.value()) + "\"";
  return s + ">";
}

/// The whitespace-separated words of an element's text (IDREFS, a list of ids).
inline std::vector<std::string> words(const pugi::xml_node& n) {
  std::istringstream in(n.child_value());
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

/// An element's text with its whitespace runs made single spaces and its ends trimmed.
inline std::string words_text(const pugi::xml_node& n) {
  std::string out;
  for (const auto& w : words(n)) out += (out.empty() ? "" : " ") + w;
  return out;
}

/// Calls visit(node) for `root` and every node below it, depth first, without recursion.
template <class Visit>
void for_each_node(const pugi::xml_node& root, const Visit& visit) {
  for (pugi::xml_node n = root; n;) {
    visit(n);
    if (n.first_child()) {
      n = n.first_child();
      continue;
    }
    while (n && n != root && !n.next_sibling()) n = n.parent();
    if (!n || n == root) break;
    n = n.next_sibling();
  }
}

}  // namespace loom::kbl_dom
