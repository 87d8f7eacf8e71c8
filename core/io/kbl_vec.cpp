// VEC files: the topology counted, the missing geometry named (kbl_vec.hpp).
#include "core/io/kbl_vec.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"
#include "core/io/kbl_dom.hpp"
#include "core/io/line_map.hpp"

#include <pugixml.hpp>

#include <fstream>
#include <iterator>
#include <map>
#include <string>

namespace loom {

Harness parse_harness_vec(const std::string& text, const std::string& name_for_errors) {
  const LineMap lines(text);
  pugi::xml_document doc;
  const auto res = doc.load_buffer(text.data(), text.size());
  if (!res) throw InputError({name_for_errors, lines.line(res.offset), ""}, std::string("malformed XML: ") + res.description());
  const pugi::xml_node root = doc.document_element();
  const SourceLocation where{name_for_errors, lines.line(root.offset_debug()), "<" + std::string(root.name()) + ">"};
  if (kbl_dom::local_name(root) != "VecContent")
    throw InputError(where, "not a VEC file: the root element is <" + std::string(root.name()) +
                                ">, a VEC file's is <vec:VecContent>");
  std::map<std::string, int> count;
  int geometry_3d = 0;
  kbl_dom::for_each_node(root, [&](const pugi::xml_node& n) {
    if (n.type() != pugi::node_element) return;
    const std::string name(kbl_dom::local_name(n));
    ++count[name];
    // VEC keeps 3D geometry in GeometryNode3D, GeometrySegment3D, CartesianPoint3D, ...
    if (name.find("3D") != std::string::npos) ++geometry_3d;
  });
  const std::string version = kbl_dom::child(root, "VecVersion").child_value();
  auto n = [&](const char* what) { return std::to_string(count[what]) + " " + what; };
  const std::string holds = "VEC " + (version.empty() ? std::string("(no VecVersion)") : version) + " with " +
                            n("TopologyNode") + ", " + n("TopologySegment") + ", " + n("Routing") + ", " +
                            n("WireElement") + ", " + n("ContactPoint");
  if (geometry_3d == 0)
    throw InputError(where, holds + ", and no 3D geometry (no GeometryNode3D, GeometrySegment3D or other *3D element): "
                                    "there are no node positions or segment curves to route or audit. loom reads "
                                    "the 3D geometry of KBL 2.3/2.4 files (.kbl)");
  throw InputError(where, holds + ", and " + std::to_string(geometry_3d) +
                              " elements of 3D geometry, which loom does not read from VEC: give the harness as "
                              "KBL 2.3/2.4 (.kbl)");
}

Harness read_harness_vec(const std::filesystem::path& path) {
  require_input_file(path, "harness file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0, ""}, "cannot read harness file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_harness_vec(text, path.string());
}

}  // namespace loom
