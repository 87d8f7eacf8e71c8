#include "core/io/gltf_primitive_checks.hpp"

#include "core/error.hpp"
#include "core/io/glb_container.hpp"
#include "core/io/input_file.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace loom {

namespace {

/// Element `id` of the array `doc[key]` when it is an object there, else null.
const nlohmann::json* element(const nlohmann::json& doc, const char* key, const nlohmann::json& id) {
  if (!doc.contains(key) || !doc[key].is_array() || !id.is_number_unsigned()) return nullptr;
  const nlohmann::json& array = doc[key];
  const std::uint64_t i = id.get<std::uint64_t>();
  return i < array.size() && array[i].is_object() ? &array[i] : nullptr;
}

/// The whole number `o[key]`, `fallback` when absent, nullopt when it is something else.
std::optional<std::uint64_t> whole(const nlohmann::json& o, const char* key, std::uint64_t fallback) {
  if (!o.contains(key)) return fallback;
  if (!o[key].is_number_unsigned()) return std::nullopt;
  return o[key].get<std::uint64_t>();
}

/// The bytes base64 text `s` encodes (RFC 4648; padding optional), nullopt on a byte
/// outside the alphabet.
std::optional<std::string> base64_decode(const std::string& s) {
  std::string out;
  out.reserve(s.size() / 4 * 3 + 3);
  std::uint32_t acc = 0;
  int bits = 0;
  for (const char c : s) {
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '+') v = 62;
    else if (c == '/') v = 63;
    else if (c == '=') break;
    if (v < 0) return std::nullopt;
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFFu);
    }
  }
  return out;
}

/// The bytes of a glTF file's buffers, each read once when first asked for.
class BufferBytes {
 public:
  BufferBytes(const nlohmann::json& doc, const std::filesystem::path& path, bool binary)
      : doc_(doc), path_(path), binary_(binary) {}

  /// Buffer `id`'s bytes (at most its byteLength), or null when they cannot be had.
  const std::string* bytes(const nlohmann::json& id) {
    const nlohmann::json* b = element(doc_, "buffers", id);
    if (!b) return nullptr;
    const std::uint64_t key = id.get<std::uint64_t>();
    auto it = cache_.find(key);
    if (it == cache_.end()) it = cache_.emplace(key, read(*b)).first;
    return it->second ? &*it->second : nullptr;
  }

 private:
  std::optional<std::string> read(const nlohmann::json& b) const {
    const std::optional<std::uint64_t> length = whole(b, "byteLength", 0);
    if (!length) return std::nullopt;
    if (!b.contains("uri")) {
      if (!binary_) return std::nullopt;
      const GlbLayout glb = read_glb_layout(path_);
      const std::string all = file_bytes(path_, static_cast<std::size_t>(glb.bin_offset + glb.bin_length));
      if (all.size() < glb.bin_offset) return std::nullopt;
      return all.substr(static_cast<std::size_t>(glb.bin_offset));
    }
    if (!b["uri"].is_string()) return std::nullopt;
    const std::string uri = b["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
      const std::size_t comma = uri.find(',');
      if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos) return std::nullopt;
      return base64_decode(uri.substr(comma + 1));
    }
    std::error_code ec;
    const std::filesystem::path file = path_.parent_path() / uri;
    if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
    return file_bytes(file, static_cast<std::size_t>(*length));
  }

  const nlohmann::json& doc_;
  std::filesystem::path path_;
  bool binary_;
  std::map<std::uint64_t, std::optional<std::string>> cache_;
};

/// Bytes of one index of glTF component type `t` (unsigned byte, short, int), 0 for others.
std::uint64_t index_bytes(std::uint64_t t) { return t == 5121 ? 1 : t == 5123 ? 2 : t == 5125 ? 4 : 0; }

/// The vertices a primitive's mode needs for one face, 0 for modes without such a need.
std::uint64_t least_vertices(std::uint64_t mode) {
  if (mode == 2 || mode == 3) return 2;  // line loop, line strip
  if (mode == 5 || mode == 6) return 3;  // triangle strip, triangle fan
  return 0;
}

/// The count of accessor `id` of `doc`, 0 when there is none to read.
std::uint64_t accessor_count(const nlohmann::json& doc, const nlohmann::json& id) {
  const nlohmann::json* a = element(doc, "accessors", id);
  const std::optional<std::uint64_t> n = a ? whole(*a, "count", 0) : std::nullopt;
  return n ? *n : 0;
}

/// A strip, fan or loop has the vertices its mode needs for one face (`where` names it).
void check_mode_vertices(const nlohmann::json& doc, const nlohmann::json& prim, const std::filesystem::path& path,
                         const std::string& where) {
  const std::optional<std::uint64_t> mode = whole(prim, "mode", 4);
  const std::uint64_t least = mode ? least_vertices(*mode) : 0;
  if (least == 0) return;
  const bool indexed = prim.contains("indices");
  const bool positioned = prim.contains("attributes") && prim["attributes"].is_object() &&
                          prim["attributes"].contains("POSITION");
  const std::uint64_t n = indexed      ? accessor_count(doc, prim["indices"])
                          : positioned ? accessor_count(doc, prim["attributes"]["POSITION"])
                                       : 0;
  if (n < least)
    throw InputError({path.string(), 0, where},
                     "mode " + std::to_string(*mode) + " needs at least " + std::to_string(least) + " vertices; it has " +
                         std::to_string(n) +
                         (indexed ? " indices" : positioned ? " positions" : " (no POSITION attribute, no indices)"));
}

/// Checks one primitive (`where` names it): its mode's vertices, and its indices against
/// its vertex count.
void check_primitive(const nlohmann::json& doc, const nlohmann::json& prim, BufferBytes& buffers,
                     const std::filesystem::path& path, const std::string& where) {
  if (!prim.is_object()) return;
  check_mode_vertices(doc, prim, path, where);
  if (!prim.contains("indices")) return;
  // Indices name vertices: without a POSITION accessor Assimp builds faces over no vertices
  // and dereferences null.
  const bool positioned = prim.contains("attributes") && prim["attributes"].is_object() &&
                          prim["attributes"].contains("POSITION");
  const nlohmann::json* positions = positioned ? element(doc, "accessors", prim["attributes"]["POSITION"]) : nullptr;
  if (!positions)
    throw InputError({path.string(), 0, where},
                     "indices (accessor " + prim["indices"].dump() + ") name vertices, but " +
                         (positioned ? "the POSITION attribute " + prim["attributes"]["POSITION"].dump() +
                                           " names no accessor of the file"
                                     : std::string("the primitive has no POSITION attribute")));
  const nlohmann::json* indices = element(doc, "accessors", prim["indices"]);
  if (!indices || indices->contains("sparse") || !indices->contains("bufferView")) return;
  const std::optional<std::uint64_t> vertices = whole(*positions, "count", 0), count = whole(*indices, "count", 0),
                                     type = whole(*indices, "componentType", 0),
                                     offset = whole(*indices, "byteOffset", 0);
  const nlohmann::json* view = element(doc, "bufferViews", (*indices)["bufferView"]);
  if (!vertices || !count || !type || !offset || !view || *count == 0 || index_bytes(*type) == 0) return;
  const std::uint64_t size = index_bytes(*type);
  const std::optional<std::uint64_t> view_offset = whole(*view, "byteOffset", 0),
                                     view_length = whole(*view, "byteLength", 0), stride = whole(*view, "byteStride", size);
  if (!view_offset || !view_length || !stride || *stride < size || !view->contains("buffer")) return;
  const std::string* data = buffers.bytes((*view)["buffer"]);
  if (!data) return;
  const std::string accessor = "accessor " + prim["indices"].dump();
  // (count − 1)·stride + size ≤ the bytes after the offset, in a form that cannot wrap.
  const std::uint64_t room = *offset <= *view_length ? *view_length - *offset : 0;
  if (*offset > *view_length || size > room || *count - 1 > (room - size) / *stride)
    throw InputError({path.string(), 0, where},
                     "index " + accessor + " (" + std::to_string(*count) + " indices of " + std::to_string(size) +
                         " bytes from byte " + std::to_string(*offset) + ") reaches beyond its bufferView's " +
                         std::to_string(*view_length) + " bytes");
  if (*view_offset > data->size() || *view_length > data->size() - *view_offset)
    throw InputError({path.string(), 0, where}, "the bufferView of index " + accessor + " (bytes " +
                                                    std::to_string(*view_offset) + " + " + std::to_string(*view_length) +
                                                    ") reaches beyond its buffer's " + std::to_string(data->size()) +
                                                    " bytes");
  const std::size_t first = static_cast<std::size_t>(*view_offset + *offset);
  for (std::uint64_t k = 0; k < *count; ++k) {
    const std::size_t at = first + static_cast<std::size_t>(k * *stride);
    std::uint64_t v = 0;
    for (std::uint64_t b = size; b-- > 0;) v = (v << 8) | static_cast<unsigned char>((*data)[at + b]);
    if (v >= *vertices)
      throw InputError({path.string(), 0, where},
                       "index " + std::to_string(k) + " of " + accessor + " names vertex " + std::to_string(v) +
                           "; the primitive has " + std::to_string(*vertices) + " (POSITION accessor " +
                           prim["attributes"]["POSITION"].dump() + ")");
  }
}

}  // namespace

void check_gltf_primitives(const nlohmann::json& doc, const std::filesystem::path& path, bool binary) {
  if (!doc.contains("meshes") || !doc["meshes"].is_array()) return;  // glTF 1.0 names its meshes
  BufferBytes buffers(doc, path, binary);
  const nlohmann::json& meshes = doc["meshes"];
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    if (!meshes[m].is_object() || !meshes[m].contains("primitives") || !meshes[m]["primitives"].is_array()) continue;
    const nlohmann::json& prims = meshes[m]["primitives"];
    for (std::size_t p = 0; p < prims.size(); ++p)
      check_primitive(doc, prims[p], buffers, path, "mesh " + std::to_string(m) + " primitive " + std::to_string(p));
  }
}

}  // namespace loom
