#include "core/io/mesh_node_checks.hpp"

#include "core/error.hpp"
#include "core/io/dae_geometry.hpp"
#include "core/io/glb_container.hpp"
#include "core/io/gltf_primitive_checks.hpp"
#include "core/io/input_file.hpp"
#include "core/io/line_map.hpp"
#include "core/io/mesh_file_checks.hpp"

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace loom {

namespace {

/// A graph of nodes, each instancing its children (a child may repeat) and some geometry of
/// its own, measured by its triangle corners.
struct NodeGraph {
  std::vector<std::vector<std::size_t>> children;
  std::vector<double> own_corners;
  std::vector<std::string> names;  ///< for messages
  std::vector<int> lines;          ///< for messages (0: unknown)

  std::size_t add(std::string name, int line) {
    children.emplace_back();
    own_corners.push_back(0.0);
    names.push_back(std::move(name));
    lines.push_back(line);
    return children.size() - 1;
  }
};

/// What instancing the roots of a NodeGraph builds.
struct Expansion {
  double nodes = 0.0;    ///< node instances
  double corners = 0.0;  ///< triangle corners of the geometry instanced
};

[[noreturn]] void too_deep(const std::filesystem::path& path, int line, const std::string& what) {
  throw InputError({path.string(), line, what},
                   "nested more than " + std::to_string(kMaxMeshNesting) +
                       " levels deep (Assimp reads the hierarchy recursively and would overflow the stack)");
}

/// Instances and corners below each root, each node's subtree measured once (post-order,
/// without recursion: the graph is the file's to choose). Throws InputError for a cycle
/// (Assimp would recurse through it until the stack overflows) and for a hierarchy deeper
/// than kMaxMeshNesting. `what` names the kind of link ("instance_node", "child").
Expansion expand(const NodeGraph& g, const std::vector<std::size_t>& roots, const std::filesystem::path& path,
                 const std::string& what) {
  const std::size_t n = g.children.size();
  enum : unsigned char { kNew, kOpen, kDone };
  std::vector<unsigned char> state(n, kNew);
  std::vector<double> nodes(n, 0.0), corners(n, 0.0);
  std::vector<std::size_t> height(n, 0);
  Expansion total;
  for (const std::size_t root : roots) {
    if (state[root] == kNew) {
      std::vector<std::pair<std::size_t, std::size_t>> stack{{root, 0}};  // node, next child
      state[root] = kOpen;
      while (!stack.empty()) {
        auto& [v, next] = stack.back();
        if (next < g.children[v].size()) {
          const std::size_t c = g.children[v][next++];
          if (state[c] == kOpen)
            throw InputError({path.string(), g.lines[v], "node '" + g.names[v] + "'"},
                             what + " cycle through node '" + g.names[c] +
                                 "' (Assimp would follow it until the stack overflows)");
          if (state[c] == kNew) {
            state[c] = kOpen;
            stack.push_back({c, 0});
            if (stack.size() > kMaxMeshNesting) too_deep(path, g.lines[c], "node '" + g.names[c] + "'");
          }
          continue;
        }
        // Doubles: a fan-out of 2 per level passes 2^64 instances at 64 levels; the sums
        // only need to tell "beyond the cap" apart (inf compares as such).
        nodes[v] = 1.0;
        corners[v] = g.own_corners[v];
        for (const std::size_t c : g.children[v]) {
          nodes[v] += nodes[c];
          corners[v] += corners[c];
          height[v] = std::max(height[v], height[c] + 1);
        }
        if (height[v] > kMaxMeshNesting) too_deep(path, g.lines[v], "node '" + g.names[v] + "'");
        state[v] = kDone;
        stack.pop_back();
      }
    }
    total.nodes += nodes[root];
    total.corners += corners[root];
  }
  return total;
}

std::string count_text(double v) {
  std::ostringstream os;
  if (v < 1e15) os << static_cast<std::uint64_t>(v);
  else os << v;
  return os.str();
}

/// Throws InputError when `e` exceeds the caps and the file's own nodes and corners (a file
/// holding that much geometry itself is not amplified by instancing). `where` names the roots.
void check_expansion(const Expansion& e, double own_nodes, double own_corners, const std::filesystem::path& path,
                     int line, const std::string& where) {
  if (e.nodes > std::max(kMaxMeshNodeInstances, own_nodes))
    throw InputError({path.string(), line, where},
                     "shared nodes expand to " + count_text(e.nodes) + " node instances, more than the " +
                         count_text(kMaxMeshNodeInstances) + " accepted from a file of " + count_text(own_nodes) +
                         " nodes (Assimp would build every instance)");
  if (e.corners > std::max(kMaxMeshInstancedCorners, own_corners))
    throw InputError({path.string(), line, where},
                     "shared nodes expand to " + count_text(e.corners / 3.0) + " triangles, more than the " +
                         count_text(kMaxMeshInstancedCorners / 3.0) + " accepted from a file of " +
                         count_text(own_corners / 3.0) + " (Assimp would build every instance)");
}

// --- DAE ----------------------------------------------------------------------------------

/// The DAE document with what its checks need: element ids and line numbers.
class Dae {
 public:
  Dae(const std::filesystem::path& path, const std::string& text) : path_(path), lines_(text) {}

  int line(const pugi::xml_node& n) const { return lines_.line(n.offset_debug()); }

  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& reason) const {
    throw InputError({path_.string(), line(n), "<" + std::string(n.name()) + ">"}, reason);
  }

  /// The element a "#id" URL names, or null (external and unresolved URLs: Assimp's concern).
  pugi::xml_node target(const pugi::xml_node& n, const char* attr) const {
    const std::string url = n.attribute(attr).value();
    if (url.size() < 2 || url[0] != '#') return {};
    const auto it = ids_.find(url.substr(1));
    return it == ids_.end() ? pugi::xml_node() : it->second;
  }

  /// Every element once, depth-first without recursion: XML nesting within kMaxMeshNesting,
  /// ids indexed, index lists and accessors checked, nodes collected.
  void scan(const pugi::xml_document& doc) {
    std::vector<std::pair<pugi::xml_node, std::size_t>> stack{{doc, 0}};
    std::vector<pugi::xml_node> accessors;
    while (!stack.empty()) {
      const auto [node, depth] = stack.back();
      stack.pop_back();
      if (depth > kMaxMeshNesting) too_deep(path_, line(node), "<" + std::string(node.name()) + ">");
      const std::string name = node.name();
      if (const char* id = node.attribute("id").value(); *id) {
        const auto [other, fresh] = ids_.emplace(id, node);
        if (!fresh) {
          // The walk is not in file order: name the later of the two. Why: Assimp keeps one
          // array, node, geometry per id (a second array under a source's id made it
          // dereference null), and the instancing check would follow another element than
          // Assimp does (a node instancing itself behind a camera of its id: a stack overflow).
          const bool later = node.offset_debug() > other->second.offset_debug();
          const pugi::xml_node first = later ? other->second : node;
          fail(later ? node : other->second, "id '" + printable(id) + "' is given again (first at line " +
                                                 std::to_string(line(first)) + ", <" + first.name() +
                                                 ">): each element needs an id of its own");
        }
      }
      if (name == "p" || name == "vcount") check_indices(node);
      else if (is_primitive(node)) check_primitive(node);
      else if (name == "accessor") accessors.push_back(node);
      else if (name == "node") node_of(node);
      else if (name == "visual_scene") visual_scenes_.push_back(node);
      else if (name == "geometry") geometries_.push_back(node);
      else if (name == "mesh") check_mesh_layout(node);
      if (name == "vertices" || is_primitive_name(name)) check_in_its_mesh(node);
      if (std::string(node.parent().name()) == "node") check_transform(node, name);
      if (is_data_array(name)) check_array_count(node);
      for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling())
        if (c.type() == pugi::node_element) stack.push_back({c, depth + 1});
    }
    for (const auto& a : accessors) check_accessor(a);
    const auto in_file_order = [](const pugi::xml_node& a, const pugi::xml_node& b) {
      return a.offset_debug() < b.offset_debug();
    };
    std::sort(visual_scenes_.begin(), visual_scenes_.end(), in_file_order);
  }

  /// Expands the instantiated visual scene (or all of them) and checks the caps.
  void check_instancing(const pugi::xml_document& doc) {
    NodeGraph g;
    for (const pugi::xml_node& xml : nodes_) {
      const char* id = xml.attribute("id").value();
      const std::size_t v = g.add(*id ? id : xml.attribute("name").value(), line(xml));
      for (pugi::xml_node c = xml.first_child(); c; c = c.next_sibling()) {
        const std::string cn = c.name();
        if (cn == "node") {
          g.children[v].push_back(node_index_.at(c));
        } else if (cn == "instance_node") {
          // Assimp looks a URL that names no node id up among the node names, where the
          // instancing check does not follow it (a node instancing its own name recursed
          // without end).
          const pugi::xml_node t = target(c, "url");
          if (!t || !node_index_.count(t))
            fail(c, "url '" + printable(c.attribute("url").value()) + "' names no <node> id of the file");
          g.children[v].push_back(node_index_.at(t));
        } else if (cn == "instance_geometry") {
          g.own_corners[v] += geometry_corners(target(c, "url"));
        }
      }
    }
    // The scene Assimp builds: the one <scene> instantiates, else every visual scene.
    std::vector<pugi::xml_node> scenes;
    const pugi::xml_node instance = doc.document_element().child("scene").child("instance_visual_scene");
    const pugi::xml_node chosen = target(instance, "url");
    // An instance naming no visual scene of the file: Assimp threw after building the
    // scene's nodes and leaked them.
    if (instance && (!chosen || std::string(chosen.name()) != "visual_scene"))
      fail(instance, "url '" + printable(instance.attribute("url").value()) + "' names no <visual_scene> of the file");
    if (chosen) scenes.push_back(chosen);
    else scenes = visual_scenes_;
    std::vector<std::size_t> roots;
    for (const auto& s : scenes)
      for (pugi::xml_node c = s.child("node"); c; c = c.next_sibling("node")) roots.push_back(node_index_.at(c));
    const Expansion e = expand(g, roots, path_, "instance_node");
    double own_corners = 0.0;
    for (const auto& geometry : geometries_) own_corners += geometry_corners(geometry);
    const int at = scenes.empty() ? 0 : line(scenes.front());
    check_expansion(e, static_cast<double>(nodes_.size()), own_corners, path_, at, "<visual_scene>");
  }

 private:
  void node_of(const pugi::xml_node& n) {
    node_index_.emplace(n, nodes_.size());
    nodes_.push_back(n);
  }

  /// Whether an element named `name` is a COLLADA data array (<float_array>, <int_array>,
  /// ...), whose count check_array_count holds to its values.
  static bool is_data_array(const std::string& name) {
    return name == "float_array" || name == "int_array" || name == "bool_array" || name == "Name_array" ||
           name == "IDREF_array" || name == "SIDREF_array" || name == "token_array";
  }

  /// A node's transform (<matrix>, <translate>, <rotate>, <scale>, <lookat>, <skew>) holds
  /// its number of values, each a finite number. Why: Assimp read a <matrix> of 14 values
  /// past its end, or a rotate of "? 1 90", threw ("Cannot parse string ... as a real
  /// number") and leaked the nodes it had built (a kilobyte per file, which grew the
  /// fuzzer past its memory limit).
  void check_transform(const pugi::xml_node& n, const std::string& name) const {
    static const std::pair<const char*, int> kValues[] = {{"matrix", 16}, {"translate", 3}, {"rotate", 4},
                                                          {"scale", 3},   {"lookat", 9},    {"skew", 7}};
    for (const auto& [kind, values] : kValues) {
      if (name != kind) continue;
      int words = 0;
      for_each_word(n.child_value(), [&](const char* from, const char* to) {
        const std::string word(from, to);
        char* end = nullptr;
        const double v = std::strtod(word.c_str(), &end);
        if (end != word.c_str() + word.size() || !std::isfinite(v))
          fail(n, "'" + printable(word.substr(0, 20)) + "' (value " + std::to_string(words) + ") is not a number");
        ++words;
      });
      if (words != values)
        fail(n, "holds " + std::to_string(words) + " values; a <" + name + "> takes " + std::to_string(values));
      // Valid COLLADA that Assimp 5.2 cannot apply: it asserts (an abort in Debian's build).
      if (name == "skew") fail(n, "a <skew> transform is not read (Assimp cannot apply one)");
    }
  }

  /// A <mesh> holds one <vertices>, before its primitives (COLLADA 1.4 §5, <mesh>). Why:
  /// Assimp 5.2 reads a primitive before the <vertices> without positions but with its
  /// faces, so the faces of the next primitive named vertices past the mesh's (a
  /// heap-buffer overflow in its sub-mesh copy).
  void check_mesh_layout(const pugi::xml_node& mesh) const {
    pugi::xml_node vertices;
    for (pugi::xml_node c = mesh.first_child(); c; c = c.next_sibling()) {
      if (std::string(c.name()) == "vertices") {
        if (vertices)
          fail(c, "a second <vertices> in the mesh (the first at line " + std::to_string(line(vertices)) +
                      "): a mesh has one");
        vertices = c;
      } else if (is_primitive(c) && !vertices) {
        fail(c, "comes before the mesh's <vertices>" +
                    (mesh.child("vertices") ? " (line " + std::to_string(line(mesh.child("vertices"))) + ")"
                                            : std::string(" (the mesh has none)")) +
                    ": a mesh's primitives follow its <vertices>");
      }
    }
  }

  /// Whether `name` names a COLLADA primitive (<triangles>, <polylist>, ...).
  static bool is_primitive_name(const std::string& name) {
    static const char* const kPrimitives[] = {"triangles", "polylist", "polygons", "lines",
                                              "linestrips", "trifans", "tristrips"};
    return std::any_of(std::begin(kPrimitives), std::end(kPrimitives), [&](const char* k) { return name == k; });
  }

  /// Whether `n` is a primitive of a <mesh>: Assimp reads those (and nothing of a
  /// <convex_mesh> or other holder).
  static bool is_primitive(const pugi::xml_node& n) {
    return std::string(n.parent().name()) == "mesh" && is_primitive_name(n.name());
  }

  /// A <vertices> or primitive within a <mesh> is a child of it. Why: Assimp 5.2 walks all
  /// of a mesh's descendants for them, so a <triangles> a mutation had put inside an
  /// <accessor> was read as the mesh's — unchecked, with a count of 4.7·10⁵⁵ (103 GB).
  void check_in_its_mesh(const pugi::xml_node& n) const {
    if (std::string(n.parent().name()) == "mesh") return;
    for (pugi::xml_node a = n.parent(); a; a = a.parent())
      if (std::string(a.name()) == "mesh")
        fail(n, "inside <" + std::string(n.parent().name()) + ">, not a child of the <mesh> on line " +
                    std::to_string(line(a)) + " (Assimp would read it as one of that mesh's)");
  }

  /// A primitive with a count above 0 holds a <p>; a <polylist> holds its <vcount> before
  /// the first <p>. Every input offset names a value the <p> lists hold, and the count
  /// and <vcount> ask for no more indices than they hold: triangles 3 and lines 2 per
  /// primitive, a polylist's polygons the <vcount> values' sum, each vertex one index per
  /// offset; polygons, strips and fans one <p> per primitive. Why: Assimp 5.2's COLLADA
  /// reader aborted on a primitive with a count but no index list, dereferenced null for
  /// a polylist whose <vcount> was missing or came after its <p> (SIGSEGV), and allocated
  /// by the count, the <vcount> values and the highest offset before it read the indices
  /// (34 GB for one polygon of 34·10⁹ vertices, 412 GB for an offset of 10³⁴). Values
  /// that are not numbers are check_indices' to name.
  void check_primitive(const pugi::xml_node& n) {
    const long long count = n.attribute("count").as_llong(0);
    if (count <= 0) return;
    const pugi::xml_node p = n.child("p");
    if (!p) fail(n, "declares " + std::to_string(count) + " primitive(s) but holds no <p> index list");
    const std::string kind = n.name();
    pugi::xml_node vcount;
    for (pugi::xml_node c = n.first_child(); c && c != p && !vcount; c = c.next_sibling())
      if (std::string(c.name()) == "vcount") vcount = c;
    if (kind == "polylist" && !vcount)
      fail(n, "a <polylist> needs its <vcount> (the vertices of each polygon) before its <p>");
    double indices = 0.0, lists = 0.0, corners = 0.0, polygons = 0.0;
    bool numbers = true;
    for (pugi::xml_node c = p; c; c = c.next_sibling("p")) {
      lists += 1.0;
      for_each_word(c.child_value(), [&](const char* from, const char* to) {
        indices += 1.0;
        numbers = numbers && whole_word(from, to);
      });
    }
    if (vcount)
      for_each_word(vcount.child_value(), [&](const char* from, const char* to) {
        polygons += 1.0;
        corners += word_value(from, to);
        numbers = numbers && whole_word(from, to);
      });
    if (!numbers || indices == 0.0) return;  // check_indices names the word or the empty list
    check_offsets(n, indices);
    const double stride = static_cast<double>(values_per_vertex(n)), c = static_cast<double>(count);
    const auto too_many = [&](const pugi::xml_node& at, double need, const std::string& what) {
      fail(at, what + " take " + full_precision(need) + " indices at " + full_precision(stride) +
                   " per vertex, but the <p> holds " + full_precision(indices));
    };
    if (kind == "triangles" && 3.0 * c * stride > indices) too_many(n, 3.0 * c * stride, "count " + std::to_string(count) + " triangles");
    if (kind == "lines" && 2.0 * c * stride > indices) too_many(n, 2.0 * c * stride, "count " + std::to_string(count) + " lines");
    if (kind == "polylist" && corners * stride > indices)
      too_many(vcount, corners * stride, "the polygons' " + full_precision(corners) + " vertices");
    if (kind == "polylist" && c > polygons)
      fail(n, "count " + std::to_string(count) + " polygons, but the <vcount> lists " + full_precision(polygons));
    if ((kind == "polygons" || kind == "tristrips" || kind == "trifans" || kind == "linestrips") && c > lists)
      fail(n, "count " + std::to_string(count) + " primitives, but it holds " + full_precision(lists) + " <p> lists");
  }

  /// Every <input> offset of primitive `n` is a whole number below `indices`, the values
  /// its <p> lists hold (no vertex could use a larger one).
  void check_offsets(const pugi::xml_node& n, double indices) const {
    for (pugi::xml_node in = n.child("input"); in; in = in.next_sibling("input")) {
      const pugi::xml_attribute a = in.attribute("offset");
      if (!a) continue;
      const std::string o = a.value();
      std::uint64_t offset = 0;
      const auto [end, ec] = std::from_chars(o.data(), o.data() + o.size(), offset);
      if (ec != std::errc() || end != o.data() + o.size() || static_cast<double>(offset) >= indices)
        fail(in, "offset '" + printable(o.substr(0, 40)) + "' is not an index into the " + full_precision(indices) +
                     " values of the <p>");
    }
  }

  /// Whether [from, to) is all decimal digits.
  static bool whole_word(const char* from, const char* to) {
    return std::all_of(from, to, [](char ch) { return std::isdigit(static_cast<unsigned char>(ch)) != 0; });
  }

  /// The decimal value of the leading digits of [from, to), as a double (no overflow).
  static double word_value(const char* from, const char* to) {
    double v = 0.0;
    for (const char* c = from; c != to && std::isdigit(static_cast<unsigned char>(*c)); ++c) v = 10.0 * v + (*c - '0');
    return v;
  }

  /// Calls f(first, last) for each word of `s`: runs of bytes other than the separators
  /// Assimp skips between numbers (space, tab, CR, LF).
  template <class F>
  static void for_each_word(const char* s, F f) {
    const auto separator = [](char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n'; };
    for (const char* c = s; *c;) {
      while (*c && separator(*c)) ++c;
      if (!*c) break;
      const char* from = c;
      while (*c && !separator(*c)) ++c;
      f(from, c);
    }
  }

  /// Index values per vertex of a primitive: its highest input offset + 1.
  static std::uint64_t values_per_vertex(const pugi::xml_node& prim) {
    std::uint64_t stride = 1;
    for (pugi::xml_node in = prim.child("input"); in; in = in.next_sibling("input")) {
      std::uint64_t offset = 0;
      const std::string o = in.attribute("offset").value();
      if (std::from_chars(o.data(), o.data() + o.size(), offset).ec == std::errc())
        stride = std::max(stride, offset + 1);
    }
    return stride;
  }

  /// A <p> or <vcount> list: unsigned decimal integers separated by spaces, tabs and line ends,
  /// at least one. Why: Assimp's reader does not move past a byte it cannot read as part of
  /// one and appended indices until memory ran out — a word that is not a number, and also a
  /// form feed or vertical tab between two numbers (3 GB for "1\f2").
  void check_indices(const pugi::xml_node& n) {
    std::size_t values = 0;
    for_each_word(n.child_value(), [&](const char* from, const char* to) {
      if (!whole_word(from, to)) {
        constexpr std::ptrdiff_t kShown = 20;
        const std::string word(from, std::min(to - from, kShown));
        const bool odd_blank = word.find_first_of("\f\v") != std::string::npos;
        fail(n, "'" + printable(word) + "' is not an index (value " + std::to_string(values) + " of the list)" +
                    (odd_blank ? ": only spaces, tabs and line ends separate indices" : ""));
      }
      ++values;
    });
    // An empty list (<p/>, <p> </p>) in a primitive made Assimp 5.2's COLLADA reader
    // dereference null (SIGSEGV).
    if (values == 0) fail(n, "holds no values (an empty index list)");
    if (std::string(n.name()) == "p") p_values_[n.parent()] += static_cast<double>(values);
  }

  /// The corners a geometry (or a controller's source geometry) holds: per primitive, the
  /// values of its <p> lists over the values per vertex (its highest input offset + 1).
  double geometry_corners(pugi::xml_node g) {
    for (int hops = 0; g && std::string(g.name()) == "controller" && hops < 4; ++hops) {
      pugi::xml_node source = g.child("skin");
      if (!source) source = g.child("morph");
      g = target(source, "source");
    }
    if (!g || std::string(g.name()) != "geometry") return 0.0;
    if (const auto it = corners_.find(g); it != corners_.end()) return it->second;
    double corners = 0.0;
    for (pugi::xml_node m = g.first_child(); m; m = m.next_sibling())
      for (pugi::xml_node prim = m.first_child(); prim; prim = prim.next_sibling()) {
        const auto it = p_values_.find(prim);
        if (it == p_values_.end()) continue;
        corners += it->second / static_cast<double>(values_per_vertex(prim));
      }
    corners_[g] = corners;
    return corners;
  }

  /// An unsigned decimal attribute, `fallback` if absent; fails for anything else.
  std::uint64_t count_attribute(const pugi::xml_node& n, const char* attr, std::uint64_t fallback) const {
    const pugi::xml_attribute a = n.attribute(attr);
    if (!a) return fallback;
    const std::string v = a.value();
    std::uint64_t out = 0;
    const auto r = std::from_chars(v.data(), v.data() + v.size(), out);
    if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size())
      fail(n, std::string("attribute '") + attr + "' = '" + v + "' is not a count");
    return out;
  }

  /// A data array's count is no more than the values it holds. Why: Assimp reserved the
  /// declared count before it read the values (a count of 3·10⁸⁵, wrapped, grew the fuzzer
  /// past its memory limit) and then reported the missing values.
  void check_array_count(const pugi::xml_node& n) const {
    const std::uint64_t count = count_attribute(n, "count", 0);
    std::uint64_t values = 0;
    for_each_word(n.child_value(), [&](const char*, const char*) { ++values; });
    if (count > values)
      fail(n, "count " + std::to_string(count) + " but it holds " + std::to_string(values) + " values");
  }

  /// An accessor's last element within its array. Why: Assimp reads element k at offset +
  /// k·stride unchecked; stride 2^31 on a 9-value array read far outside it (SIGSEGV).
  void check_accessor(const pugi::xml_node& a) const {
    const std::uint64_t count = count_attribute(a, "count", 0);
    const std::uint64_t stride = count_attribute(a, "stride", 1);
    const std::uint64_t offset = count_attribute(a, "offset", 0);
    const pugi::xml_node array = target(a, "source");
    if (!array || count == 0) return;
    std::uint64_t params = 0;
    for (pugi::xml_node p = a.child("param"); p; p = p.next_sibling("param")) ++params;
    // A stride of 0 read every element at the offset, past an empty array (SIGSEGV).
    if (stride == 0 || stride < params)
      fail(a, "stride " + std::to_string(stride) + " for " + std::to_string(params) +
                  " params: an element takes at least one value and its params' values");
    const std::uint64_t size = count_attribute(array, "count", 0);
    // offset + (count − 1)·stride + params ≤ size, without overflow.
    const bool fits = offset <= size && params <= size - offset &&
                      count - 1 <= (size - offset - params) / stride;
    if (!fits)
      fail(a, "count " + std::to_string(count) + " x stride " + std::to_string(stride) + " from offset " +
                  std::to_string(offset) + " reaches beyond the " + std::to_string(size) + " values of <" +
                  array.name() + " id=\"" + array.attribute("id").value() + "\">");
  }

  struct NodeHash {
    std::size_t operator()(const pugi::xml_node& n) const { return std::hash<const void*>()(n.internal_object()); }
  };

  const std::filesystem::path& path_;
  LineMap lines_;
  std::unordered_map<std::string, pugi::xml_node> ids_;
  std::vector<pugi::xml_node> nodes_;
  std::vector<pugi::xml_node> visual_scenes_, geometries_;
  std::unordered_map<pugi::xml_node, std::size_t, NodeHash> node_index_;
  std::unordered_map<pugi::xml_node, double, NodeHash> p_values_;  ///< per primitive: values of its <p>
  std::unordered_map<pugi::xml_node, double, NodeHash> corners_;   ///< per geometry
};

// --- glTF ---------------------------------------------------------------------------------

/// Every buffer's byteLength against the bytes that can back it: a GLB's body buffer (no
/// uri) against its BIN chunk, a file buffer against that file, a data URI against its
/// decoded size. Why: Assimp allocates a buffer by its declared byteLength before reading it.
void check_gltf_buffers(const nlohmann::json& doc, const std::filesystem::path& path, bool binary) {
  if (!doc.contains("buffers")) return;
  const nlohmann::json& buffers = doc["buffers"];
  if (!buffers.is_array() && !buffers.is_object()) return;
  const std::uint64_t bin = binary ? read_glb_layout(path).bin_length : 0;
  for (const auto& [id, b] : buffers.items()) {
    if (!b.is_object() || !b.contains("byteLength")) continue;
    const std::string what = "buffer " + id;
    const nlohmann::json& n = b["byteLength"];
    if (!n.is_number_unsigned())
      throw InputError({path.string(), 0, what}, "byteLength " + n.dump() + " is not a whole number of bytes");
    const std::uint64_t length = n.get<std::uint64_t>();
    std::uint64_t room = 0;
    std::string backing;
    const std::string uri = b.contains("uri") && b["uri"].is_string() ? b["uri"].get<std::string>() : std::string();
    if (uri.empty()) {
      room = bin;
      backing = binary ? "the BIN chunk's " : "no data: ";
    } else if (uri.rfind("data:", 0) == 0) {
      room = uri.size() - std::min(uri.size(), uri.find(',') + 1);  // ≥ the decoded bytes
      backing = "its data URI's ";
    } else {
      std::error_code ec;
      const auto file = path.parent_path() / uri;
      room = static_cast<std::uint64_t>(std::filesystem::file_size(file, ec));
      if (ec) continue;  // a missing buffer file: Assimp reports it
      backing = "file " + file.string() + "'s ";
    }
    if (length > room)
      throw InputError({path.string(), 0, what}, "byteLength " + std::to_string(length) + " is more than " + backing +
                                                     std::to_string(room) + " bytes");
  }
}

/// The corners of a glTF mesh: per primitive, its index accessor's count, else its POSITION
/// accessor's (2.0: accessors an array and ids indices; 1.0: objects and ids names).
double gltf_mesh_corners(const nlohmann::json& doc, const nlohmann::json& mesh) {
  const nlohmann::json* accessors = doc.contains("accessors") ? &doc["accessors"] : nullptr;
  auto count_of = [&](const nlohmann::json& id) -> double {
    if (!accessors) return 0.0;
    const nlohmann::json* a = nullptr;
    if (id.is_number_unsigned() && accessors->is_array() && id.get<std::uint64_t>() < accessors->size())
      a = &(*accessors)[id.get<std::size_t>()];
    else if (id.is_string() && accessors->is_object() && accessors->contains(id.get<std::string>()))
      a = &(*accessors)[id.get<std::string>()];
    if (!a || !a->is_object() || !a->contains("count") || !(*a)["count"].is_number()) return 0.0;
    return (*a)["count"].get<double>();
  };
  double corners = 0.0;
  if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) return 0.0;
  for (const auto& prim : mesh["primitives"]) {
    if (!prim.is_object()) continue;
    if (prim.contains("indices")) corners += count_of(prim["indices"]);
    else if (prim.contains("attributes") && prim["attributes"].is_object() && prim["attributes"].contains("POSITION"))
      corners += count_of(prim["attributes"]["POSITION"]);
  }
  return corners;
}

/// The meshes a glTF node instances: 2.0 "mesh" (an index), 1.0 "meshes" (names).
double gltf_node_corners(const nlohmann::json& doc, const nlohmann::json& node) {
  if (!node.is_object() || !doc.contains("meshes")) return 0.0;
  const nlohmann::json& meshes = doc["meshes"];
  double corners = 0.0;
  if (node.contains("mesh") && node["mesh"].is_number_unsigned() && meshes.is_array() &&
      node["mesh"].get<std::uint64_t>() < meshes.size())
    corners += gltf_mesh_corners(doc, meshes[node["mesh"].get<std::size_t>()]);
  if (node.contains("meshes") && node["meshes"].is_array() && meshes.is_object())
    for (const auto& m : node["meshes"])
      if (m.is_string() && meshes.contains(m.get<std::string>())) corners += gltf_mesh_corners(doc, meshes[m.get<std::string>()]);
  return corners;
}

}  // namespace

void check_dae_file(const std::filesystem::path& path) {
  const std::string text = file_bytes(path);
  pugi::xml_document doc;
  // Not left to Assimp: it reads the part of a malformed document parsed before the error,
  // and a primitive cut off there was read over vertices that are not there.
  if (const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size(), kDaeParseOptions); !parsed)
    throw InputError({path.string(), LineMap(text).line(parsed.offset), "XML"},
                     std::string("the XML does not parse: ") + parsed.description());
  keep_dae_geometry(doc);  // what Assimp will read
  Dae dae(path, text);
  dae.scan(doc);
  dae.check_instancing(doc);
}

void check_gltf_file(const std::filesystem::path& path, bool binary) {
  const nlohmann::json doc = nlohmann::json::parse(gltf_json(path, binary), nullptr, false);
  // Not left to Assimp: when both of its glTF importers decline a file, it offers the file
  // to every other importer by content, and a text "indexarray{..." went to one (OpenGEX)
  // that read past its buffer.
  if (doc.is_discarded() || !doc.is_object())
    throw InputError({path.string(), 0, binary ? "GLB JSON chunk" : "glTF"},
                     std::string(doc.is_discarded() ? "the JSON does not parse" : "the JSON is not an object") +
                         " (not a glTF file)");
  check_gltf_buffers(doc, path, binary);
  check_gltf_primitives(doc, path, binary);
  if (!doc.contains("nodes")) return;
  const nlohmann::json& nodes = doc["nodes"];
  NodeGraph g;
  std::unordered_map<std::string, std::size_t> index;  // node id → graph node
  std::vector<const nlohmann::json*> json_of;
  auto add = [&](const std::string& id, const nlohmann::json& node) {
    index.emplace(id, g.add(id, 0));
    json_of.push_back(&node);
  };
  if (nodes.is_array())
    for (std::size_t i = 0; i < nodes.size(); ++i) add(std::to_string(i), nodes[i]);
  else if (nodes.is_object())
    for (const auto& [id, node] : nodes.items()) add(id, node);
  else
    return;
  std::vector<bool> is_child(json_of.size(), false);
  for (std::size_t v = 0; v < json_of.size(); ++v) {
    const nlohmann::json& node = *json_of[v];
    g.own_corners[v] = gltf_node_corners(doc, node);
    if (!node.is_object() || !node.contains("children") || !node["children"].is_array()) continue;
    for (const auto& c : node["children"]) {
      std::string id;
      if (c.is_number_unsigned()) id = std::to_string(c.get<std::uint64_t>());
      else if (c.is_string()) id = c.get<std::string>();
      const auto it = index.find(id);
      if (it == index.end()) continue;  // Assimp reports a dangling child
      g.children[v].push_back(it->second);
      is_child[it->second] = true;
    }
  }
  // The roots Assimp builds: every scene's nodes; without scenes, the nodes nobody parents.
  std::vector<std::size_t> roots;
  if (doc.contains("scenes") && (doc["scenes"].is_array() || doc["scenes"].is_object()))
    for (const auto& s : doc["scenes"])
      if (s.is_object() && s.contains("nodes") && s["nodes"].is_array())
        for (const auto& r : s["nodes"]) {
          const std::string id = r.is_number_unsigned() ? std::to_string(r.get<std::uint64_t>())
                                                        : (r.is_string() ? r.get<std::string>() : "");
          if (const auto it = index.find(id); it != index.end()) roots.push_back(it->second);
        }
  if (roots.empty())
    for (std::size_t v = 0; v < is_child.size(); ++v)
      if (!is_child[v]) roots.push_back(v);
  // Every node is walked (not only those under the roots): the depth limit held for all of
  // them before, and a hierarchy Assimp would not build costs only this walk.
  std::vector<std::size_t> all(json_of.size());
  for (std::size_t v = 0; v < all.size(); ++v) all[v] = v;
  expand(g, all, path, "children");
  double own_corners = 0.0;
  if (doc.contains("meshes") && (doc["meshes"].is_array() || doc["meshes"].is_object()))
    for (const auto& m : doc["meshes"]) own_corners += gltf_mesh_corners(doc, m);
  check_expansion(expand(g, roots, path, "children"), static_cast<double>(json_of.size()), own_corners, path, 0,
                  "scene nodes");
}

}  // namespace loom
