#include "core/io/mesh_file_checks.hpp"

#include "core/error.hpp"

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace loom {

namespace {

/// At most `limit` bytes from the start of the file.
std::string head_of(const std::filesystem::path& path, std::size_t limit) {
  std::ifstream in(path, std::ios::binary);
  std::string s(limit, '\0');
  in.read(s.data(), static_cast<std::streamsize>(limit));
  s.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return s;
}

std::string whole_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream is(line);
  std::vector<std::string> w;
  for (std::string t; is >> t;) w.push_back(t);
  return w;
}

/// A decimal count; false for anything else. Values beyond 64 bits saturate (they are
/// refused by the size checks like any other count the file cannot hold).
bool parse_count(const std::string& t, std::uint64_t& v) {
  if (t.empty() || !std::isdigit(static_cast<unsigned char>(t[0]))) return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec == std::errc::result_out_of_range) {
    v = UINT64_MAX;
    return true;
  }
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// --- PLY ---------------------------------------------------------------------------------

/// Bytes of one PLY scalar type, 0 if the name is unknown.
std::uint64_t ply_scalar_bytes(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

/// The PLY header's elements against the bytes after it: an instance takes at least one
/// byte in ASCII (a line) and at least its fixed properties' bytes in binary (a list at
/// least its length field). A header this check cannot parse is left to Assimp.
void check_ply(const std::filesystem::path& path) {
  constexpr std::size_t kMaxHeader = 1 << 20;  // PLY headers are a few hundred bytes
  const std::string head = head_of(path, kMaxHeader);
  const std::size_t end = head.find("end_header");
  if (end == std::string::npos) return;
  const std::size_t data_at = head.find('\n', end);
  if (data_at == std::string::npos) return;
  std::error_code ec;
  const auto size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
  if (ec || size < data_at + 1) return;
  const std::uint64_t bytes = size - (data_at + 1);

  std::vector<PlyElementExtent> elements;
  bool ascii = false;
  std::istringstream is(head.substr(0, end));
  int line_no = 0;
  for (std::string line; std::getline(is, line);) {
    ++line_no;
    const auto w = words(line);
    if (w.empty()) continue;
    if (w[0] == "format" && w.size() >= 2) {
      ascii = w[1] == "ascii";
    } else if (w[0] == "element" && w.size() == 3) {
      PlyElementExtent e;
      e.name = w[1];
      e.line = line_no;
      if (!parse_count(w[2], e.count)) return;
      elements.push_back(e);
    } else if (w[0] == "property" && !elements.empty()) {
      const std::string& type = (w.size() == 5 && w[1] == "list") ? w[2] : (w.size() >= 2 ? w[1] : w[0]);
      const std::uint64_t b = ply_scalar_bytes(type);
      if (b == 0) return;
      elements.back().min_bytes += b;
    }
  }
  check_ply_extents(elements, ascii, bytes, path.string());
}

// --- OFF ---------------------------------------------------------------------------------

/// The OFF header's vertex and face counts against the file size: each vertex and face takes
/// at least one line. A header this check cannot parse is left to Assimp.
void check_off(const std::filesystem::path& path) {
  const std::string head = head_of(path, 1 << 16);
  std::istringstream is(head);
  std::vector<std::string> tokens;
  std::vector<int> lines;
  int line_no = 0;
  for (std::string line; tokens.size() < 4 && std::getline(is, line);) {
    ++line_no;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    for (const auto& w : words(line)) {
      tokens.push_back(w);
      lines.push_back(line_no);
    }
  }
  if (tokens.size() < 3) return;
  std::size_t at = 0;
  const std::string& magic = tokens[0];
  if (magic.size() >= 3 && magic.compare(magic.size() - 3, 3, "OFF") == 0) at = 1;
  std::uint64_t nv = 0, nf = 0;
  if (at + 1 >= tokens.size() || !parse_count(tokens[at], nv) || !parse_count(tokens[at + 1], nf)) return;
  std::error_code ec;
  const auto size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
  if (ec) return;
  if (nv > size || nf > size || nv + nf > size)
    throw InputError({path.string(), lines[at], "OFF header"},
                     "declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                         " faces, more than the file's " + std::to_string(size) +
                         " bytes can hold (a truncated or corrupt file?)");
  // Face indices: Assimp's OFF reader replaces one beyond the vertices by the last vertex
  // (logging an error nobody sees), a silently different triangle. Lines after the header's:
  // nv vertex lines, then faces "k i1 .. ik [colour]"; blank and '#' lines skipped.
  std::istringstream all(whole_file(path));
  int no = 0;
  std::uint64_t seen_v = 0, seen_f = 0;
  for (std::string line; seen_f < nf && std::getline(all, line);) {
    ++no;
    if (no <= lines[at + 1]) continue;  // the header, through the line of the counts
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const auto w = words(line);
    if (w.empty()) continue;
    if (seen_v < nv) {
      ++seen_v;
      continue;
    }
    std::uint64_t k = 0;
    if (!parse_count(w[0], k) || k + 1 > w.size()) return;  // Assimp reports malformed faces
    for (std::size_t i = 1; i <= k; ++i) {
      std::uint64_t index = 0;
      if (!parse_count(w[i], index) || index >= nv)
        throw InputError({path.string(), no, "face " + std::to_string(seen_f)},
                         "vertex index " + w[i] + " is not one of the " + std::to_string(nv) + " vertices (0.." +
                             std::to_string(nv == 0 ? 0 : nv - 1) + ")");
    }
    ++seen_f;
  }
}

// --- nesting -----------------------------------------------------------------------------

[[noreturn]] void too_deep(const std::filesystem::path& path, int line, const std::string& what) {
  throw InputError({path.string(), line, what},
                   "nested more than " + std::to_string(kMaxMeshNesting) +
                       " levels deep (Assimp reads the hierarchy recursively and would overflow the stack)");
}

/// The deepest XML element nesting of a DAE file (pugixml parses without recursion).
void check_dae(const std::filesystem::path& path) {
  const std::string text = whole_file(path);
  pugi::xml_document doc;
  if (!doc.load_buffer(text.data(), text.size(), pugi::parse_minimal)) return;
  std::vector<std::pair<pugi::xml_node, std::size_t>> stack{{doc, 0}};
  while (!stack.empty()) {
    const auto [node, depth] = stack.back();
    stack.pop_back();
    if (depth > kMaxMeshNesting) {
      const auto offset = node.offset_debug();
      const int line = offset < 0 ? 0 : static_cast<int>(std::count(text.begin(), text.begin() + offset, '\n')) + 1;
      too_deep(path, line, "<" + std::string(node.name()) + ">");
    }
    for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling())
      if (c.type() == pugi::node_element) stack.push_back({c, depth + 1});
  }
}

/// The JSON of a glTF file, or of a GLB file's first (JSON) chunk; empty if there is none.
std::string gltf_json(const std::filesystem::path& path, bool binary) {
  if (!binary) return whole_file(path);
  const std::string head = head_of(path, 20);
  if (head.size() < 20 || head.compare(0, 4, "glTF") != 0) return {};
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(head[at + static_cast<std::size_t>(k)]);
    return v;
  };
  const std::uint32_t length = u32(12);
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || 20 + static_cast<std::uint64_t>(length) > size) return {};
  std::ifstream in(path, std::ios::binary);
  in.seekg(20);
  std::string json(length, '\0');
  in.read(json.data(), static_cast<std::streamsize>(length));
  return json;
}

/// The deepest node hierarchy of a glTF (2.0: "nodes" an array, children indices; 1.0: an
/// object, children names), memoised so that shared subtrees are walked once.
void check_gltf(const std::filesystem::path& path, bool binary) {
  const nlohmann::json doc = nlohmann::json::parse(gltf_json(path, binary), nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("nodes")) return;
  const nlohmann::json& nodes = doc["nodes"];
  std::map<std::string, std::vector<std::string>> children;
  auto add = [&](const std::string& id, const nlohmann::json& node) {
    auto& out = children[id];
    if (!node.is_object() || !node.contains("children") || !node["children"].is_array()) return;
    for (const auto& c : node["children"]) {
      if (c.is_number_unsigned()) out.push_back(std::to_string(c.get<std::uint64_t>()));
      else if (c.is_string()) out.push_back(c.get<std::string>());
    }
  };
  if (nodes.is_array())
    for (std::size_t i = 0; i < nodes.size(); ++i) add(std::to_string(i), nodes[i]);
  else if (nodes.is_object())
    for (const auto& [id, node] : nodes.items()) add(id, node);
  else
    return;
  // Height of each node's subtree, computed iteratively (post-order). A node met again
  // while still open is a cycle: Assimp reports those itself, so it ends the walk here.
  std::map<std::string, std::size_t> height;
  std::map<std::string, bool> open;
  for (const auto& [root, unused] : children) {
    (void)unused;
    if (height.count(root)) continue;
    std::vector<std::pair<std::string, std::size_t>> stack{{root, 0}};  // node, next child
    open[root] = true;
    while (!stack.empty()) {
      auto& [id, next] = stack.back();
      const auto it = children.find(id);
      const std::vector<std::string> none;
      const auto& kids = it == children.end() ? none : it->second;
      if (next < kids.size()) {
        const std::string kid = kids[next++];
        if (height.count(kid)) continue;
        if (open[kid]) return;  // a cycle
        open[kid] = true;
        stack.push_back({kid, 0});
        if (stack.size() > kMaxMeshNesting) too_deep(path, 0, "node " + kid);
        continue;
      }
      std::size_t h = 0;
      for (const auto& k : kids) h = std::max(h, height.count(k) ? height[k] + 1 : 0);
      if (h > kMaxMeshNesting) too_deep(path, 0, "node " + id);
      height[id] = h;
      open[id] = false;
      stack.pop_back();
    }
  }
}

}  // namespace

void check_ply_extents(const std::vector<PlyElementExtent>& elements, bool ascii, std::uint64_t bytes,
                       const std::string& file) {
  std::uint64_t needed = 0;
  for (const PlyElementExtent& e : elements) {
    const std::uint64_t per = ascii ? 1 : e.min_bytes;
    const std::uint64_t room = bytes - std::min(needed, bytes);
    if (e.count > bytes || (per > 0 && e.count > room / per))
      throw InputError({file, e.line, "element " + e.name},
                       "declares " + std::to_string(e.count) + " instances, more than the " + std::to_string(bytes) +
                           " bytes after the header can hold (a truncated or corrupt file?)");
    needed += e.count * per;
  }
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

void check_mesh_file_structure(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply") check_ply(path);
  else if (ext == ".off") check_off(path);
  else if (ext == ".dae") check_dae(path);
  else if (ext == ".gltf") check_gltf(path, false);
  else if (ext == ".glb") check_gltf(path, true);
}

}  // namespace loom
