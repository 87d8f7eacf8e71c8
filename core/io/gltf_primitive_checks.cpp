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

  /// Buffer `id`'s bytes, or null when it is no buffer of the file or its file does not
  /// open; throws InputError for a data URI that is not base64 or does not decode.
  const std::string* bytes(const nlohmann::json& id) {
    const nlohmann::json* b = element(doc_, "buffers", id);
    if (!b) return nullptr;
    const std::uint64_t key = id.get<std::uint64_t>();
    auto it = cache_.find(key);
    if (it == cache_.end()) it = cache_.emplace(key, read(key, *b)).first;
    return it->second ? &*it->second : nullptr;
  }

 private:
  std::optional<std::string> read(std::uint64_t key, const nlohmann::json& b) const {
    const std::optional<std::uint64_t> length = whole(b, "byteLength", 0);
    if (!length) return std::nullopt;
    // Assimp takes a GLB's first buffer from its BIN chunk, whatever its uri says.
    const GlbLayout glb = binary_ ? read_glb_layout(path_) : GlbLayout{};
    if (binary_ && (!b.contains("uri") || (key == 0 && glb.bin_length > 0))) {
      const std::string all = file_bytes(path_, static_cast<std::size_t>(glb.bin_offset + glb.bin_length));
      if (all.size() < glb.bin_offset) return std::nullopt;
      return all.substr(static_cast<std::size_t>(glb.bin_offset));
    }
    if (!b.contains("uri") || !b["uri"].is_string()) return std::nullopt;
    const std::string uri = b["uri"].get<std::string>();
    const std::string what = "buffer " + std::to_string(key);
    if (uri.rfind("data:", 0) == 0) {
      // Assimp copies the text of a data URI without ";base64" as its bytes, and decodes a
      // character outside the alphabet as 0: neither is data a file means.
      const std::size_t comma = uri.find(',');
      if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos)
        throw InputError({path_.string(), 0, what}, "a data URI that is not base64 (\"" +
                                                        printable(uri.substr(0, std::min<std::size_t>(comma, 60))) +
                                                        "\"): loom reads base64 data URIs");
      std::optional<std::string> data = base64_decode(uri.substr(comma + 1));
      if (!data)
        throw InputError({path_.string(), 0, what}, "its data URI holds a character that is not base64");
      return data;
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

/// Whether primitive `prim` (an object) names a POSITION attribute.
bool has_position(const nlohmann::json& prim) {
  return prim.contains("attributes") && prim["attributes"].is_object() && prim["attributes"].contains("POSITION");
}

/// A strip, fan or loop has the vertices its mode needs for one face (`where` names it).
void check_mode_vertices(const nlohmann::json& doc, const nlohmann::json& prim, const std::filesystem::path& path,
                         const std::string& where) {
  const std::optional<std::uint64_t> mode = whole(prim, "mode", 4);
  const std::uint64_t least = mode ? least_vertices(*mode) : 0;
  if (least == 0) return;
  const bool indexed = prim.contains("indices");
  const bool positioned = has_position(prim);
  const std::uint64_t n = indexed      ? accessor_count(doc, prim["indices"])
                          : positioned ? accessor_count(doc, prim["attributes"]["POSITION"])
                                       : 0;
  if (n < least)
    throw InputError({path.string(), 0, where},
                     "mode " + std::to_string(*mode) + " needs at least " + std::to_string(least) + " vertices; it has " +
                         std::to_string(n) +
                         (indexed ? " indices" : positioned ? " positions" : " (no POSITION attribute, no indices)"));
}

/// Where the elements of an accessor lie in its buffer's bytes, once checked.
struct AccessorBytes {
  const std::string* data = nullptr;  ///< the buffer's bytes
  std::size_t first = 0;              ///< byte of element 0
  std::uint64_t stride = 0, size = 0, count = 0;
};

/// Checks accessor `id` of a primitive (`where`) as Assimp will read it — `role` the
/// attribute ("POSITION") or "index" — and says where its elements lie. Why: Assimp 5.2
/// bounds an accessor by count · stride against its bufferView, leaving out the
/// accessor's byteOffset and an element longer than the stride, and copied vertices from
/// past the buffer; it zero-fills an accessor without a bufferView by its declared count,
/// and a sparse one dereferenced null or a wild offset.
AccessorBytes accessor_bytes(const nlohmann::json& doc, const nlohmann::json& id, BufferBytes& buffers,
                             const std::filesystem::path& path, const std::string& where, const std::string& role) {
  const bool index = role == "index";
  const std::string name = (index ? "index accessor " : role + " accessor ") + id.dump();
  auto refuse = [&](const std::string& why) { throw InputError({path.string(), 0, where}, name + " " + why); };
  const nlohmann::json* a = element(doc, "accessors", id);
  if (!a) refuse("is not an accessor of the file");
  if (a->contains("sparse")) refuse("is sparse: loom reads positions and indices stored whole");
  if (!a->contains("bufferView")) refuse("has no bufferView (all zeros): loom reads positions and indices from buffers");
  const std::optional<std::uint64_t> type = whole(*a, "componentType", 0), count = whole(*a, "count", 0),
                                     offset = whole(*a, "byteOffset", 0);
  const std::string shape = a->contains("type") && (*a)["type"].is_string() ? (*a)["type"].get<std::string>() : "";
  if (index ? !type || index_bytes(*type) == 0 || shape != "SCALAR" : !type || *type != 5126 || shape != "VEC3")
    refuse(std::string("is not ") + (index ? "SCALAR of unsigned bytes, shorts or ints (5121, 5123, 5125)"
                                           : "VEC3 of floats (5126)"));
  if (!count || *count == 0)
    refuse("has no elements: its count is " + (a->contains("count") ? (*a)["count"].dump() : std::string("missing")));
  if (!offset) refuse("has a byteOffset that is not a whole number of bytes");
  const std::uint64_t size = index ? index_bytes(*type) : 12;
  const nlohmann::json* view = element(doc, "bufferViews", (*a)["bufferView"]);
  if (!view) refuse("names bufferView " + (*a)["bufferView"].dump() + ", which is not one of the file");
  const std::optional<std::uint64_t> view_offset = whole(*view, "byteOffset", 0),
                                     view_length = whole(*view, "byteLength", 0), stride = whole(*view, "byteStride", size);
  if (!view_offset || !view_length || !stride || *stride < size || !view->contains("buffer"))
    refuse("has a bufferView whose byteOffset, byteLength, byteStride (at least " + std::to_string(size) +
           ") or buffer is not given as whole numbers");
  if (!element(doc, "buffers", (*view)["buffer"]))
    refuse("lies in buffer " + (*view)["buffer"].dump() + ", which is not one of the file");
  const std::string* data = buffers.bytes((*view)["buffer"]);
  // A buffer file that does not open: Assimp cannot read it either, and says so.
  if (!data) return {nullptr, 0, *stride, size, *count};
  // (count − 1)·stride + size ≤ the bytes after the offset, in a form that cannot wrap.
  const std::uint64_t room = *offset <= *view_length ? *view_length - *offset : 0;
  if (*offset > *view_length || size > room || *count - 1 > (room - size) / *stride)
    refuse("(" + std::to_string(*count) + " elements of " + std::to_string(size) + " bytes, " +
           std::to_string(*stride) + " apart, from byte " + std::to_string(*offset) + ") reaches beyond its bufferView's " +
           std::to_string(*view_length) + " bytes");
  if (*view_offset > data->size() || *view_length > data->size() - *view_offset)
    refuse("lies in a bufferView (bytes " + std::to_string(*view_offset) + " + " + std::to_string(*view_length) +
           ") reaching beyond its buffer's " + std::to_string(data->size()) + " bytes");
  return {data, static_cast<std::size_t>(*view_offset + *offset), *stride, size, *count};
}

/// Checks one primitive (`where` names it): its mode's vertices, its POSITION and index
/// accessors, and each index against its vertex count.
void check_primitive(const nlohmann::json& doc, const nlohmann::json& prim, BufferBytes& buffers,
                     const std::filesystem::path& path, const std::string& where) {
  if (!prim.is_object()) return;
  check_mode_vertices(doc, prim, path, where);
  const bool positioned = has_position(prim);
  const AccessorBytes positions =
      positioned ? accessor_bytes(doc, prim["attributes"]["POSITION"], buffers, path, where, "POSITION") : AccessorBytes{};
  if (!prim.contains("indices")) return;
  // Indices name vertices: without a POSITION accessor Assimp builds faces over no vertices
  // and dereferences null.
  if (!positioned)
    throw InputError({path.string(), 0, where}, "indices (accessor " + prim["indices"].dump() +
                                                    ") name vertices, but the primitive has no POSITION attribute");
  const AccessorBytes indices = accessor_bytes(doc, prim["indices"], buffers, path, where, "index");
  if (!indices.data) return;
  for (std::uint64_t k = 0; k < indices.count; ++k) {
    const std::size_t at = indices.first + static_cast<std::size_t>(k * indices.stride);
    std::uint64_t v = 0;
    for (std::uint64_t b = indices.size; b-- > 0;) v = (v << 8) | static_cast<unsigned char>((*indices.data)[at + b]);
    if (v >= positions.count)
      throw InputError({path.string(), 0, where},
                       "index " + std::to_string(k) + " of accessor " + prim["indices"].dump() + " names vertex " +
                           std::to_string(v) + "; the primitive has " + std::to_string(positions.count) +
                           " (POSITION accessor " + prim["attributes"]["POSITION"].dump() + ")");
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
