#include "core/io/dae_geometry.hpp"

#include <cstring>
#include <iterator>
#include <sstream>
#include <vector>

namespace loom {

namespace {

/// Whether `name` is one of the `count` names `kept`.
bool any_of(const char* name, const char* const* kept, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i)
    if (std::strcmp(name, kept[i]) == 0) return true;
  return false;
}

/// Removes the element children of `parent` that `drop` says go.
template <class Drop>
void remove_children(pugi::xml_node parent, Drop drop) {
  std::vector<pugi::xml_node> gone;
  for (pugi::xml_node c = parent.first_child(); c; c = c.next_sibling())
    if (c.type() == pugi::node_element && drop(c)) gone.push_back(c);
  for (const pugi::xml_node& c : gone) parent.remove_child(c);
}

}  // namespace

void keep_dae_geometry(pugi::xml_document& doc) {
  static const char* const kTop[] = {"asset", "library_geometries", "library_nodes", "library_visual_scenes", "scene"};
  static const char* const kInNode[] = {"instance_controller", "instance_camera", "instance_light"};
  const pugi::xml_node root = doc.document_element();
  remove_children(root, [](const pugi::xml_node& c) { return !any_of(c.name(), kTop, std::size(kTop)); });
  for (pugi::xml_node scene = root.child("scene"); scene; scene = scene.next_sibling("scene"))
    remove_children(scene, [](const pugi::xml_node& c) { return std::strcmp(c.name(), "instance_visual_scene") != 0; });
  // Nodes nest in nodes and in the node and visual-scene libraries: one walk without
  // recursion over every element left.
  std::vector<pugi::xml_node> stack{root};
  while (!stack.empty()) {
    const pugi::xml_node n = stack.back();
    stack.pop_back();
    if (std::strcmp(n.name(), "node") == 0)
      remove_children(n, [](const pugi::xml_node& c) { return any_of(c.name(), kInNode, std::size(kInNode)); });
    else if (std::strcmp(n.name(), "instance_geometry") == 0)
      remove_children(n, [](const pugi::xml_node& c) { return std::strcmp(c.name(), "bind_material") == 0; });
    for (pugi::xml_node c = n.first_child(); c; c = c.next_sibling())
      if (c.type() == pugi::node_element) stack.push_back(c);
  }
}

std::string dae_geometry_for_assimp(const std::string& text) {
  pugi::xml_document doc;
  doc.load_buffer(text.data(), text.size(), kDaeParseOptions);
  keep_dae_geometry(doc);
  std::ostringstream out;
  doc.save(out, "", pugi::format_raw);
  return out.str();
}

}  // namespace loom
