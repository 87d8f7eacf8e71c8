#include "core/io/gltf_geometry.hpp"

#include "core/io/glb_container.hpp"
#include "core/io/input_file.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <initializer_list>

namespace loom {

namespace {

/// `from` with only the members `keys` names (a value that is not an object is kept as it
/// stands: Assimp reports it).
nlohmann::json only(const nlohmann::json& from, std::initializer_list<const char*> keys) {
  if (!from.is_object()) return from;
  nlohmann::json out = nlohmann::json::object();
  for (const char* k : keys)
    if (from.contains(k)) out[k] = from[k];
  return out;
}

/// Each element of the array or object `from` mapped by `f` (the ids stay what they were).
template <class F>
nlohmann::json each(const nlohmann::json& from, F f) {
  if (!from.is_array() && !from.is_object()) return from;
  nlohmann::json out = from;
  for (auto& [id, v] : out.items()) v = f(v);
  return out;
}

/// A primitive's geometry: its POSITION attribute, indices and mode.
nlohmann::json primitive_geometry(const nlohmann::json& p) {
  nlohmann::json out = only(p, {"indices", "mode"});
  if (p.is_object() && p.contains("attributes")) out["attributes"] = only(p["attributes"], {"POSITION"});
  return out;
}

/// The little-endian bytes of `v`.
std::string u32(std::uint32_t v) {
  std::string s(4, '\0');
  for (int i = 0; i < 4; ++i) s[static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFFu);
  return s;
}

/// A GLB of `json` (padded with spaces to 4 bytes) and the BIN chunk of the GLB `path`,
/// byte for byte, when it has one.
std::string glb_of(std::string json, const std::filesystem::path& path) {
  const GlbLayout layout = read_glb_layout(path);
  json.append((4 - json.size() % 4) % 4, ' ');
  std::string bin;
  if (layout.bin_length > 0)
    bin = file_bytes(path, static_cast<std::size_t>(layout.bin_offset + layout.bin_length))
              .substr(static_cast<std::size_t>(layout.bin_offset));
  std::string out = "glTF" + u32(2) + u32(0) + u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json;
  if (!bin.empty()) out += u32(static_cast<std::uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
  const std::string total = u32(static_cast<std::uint32_t>(out.size()));
  out.replace(8, 4, total);
  return out;
}

}  // namespace

std::optional<std::string> gltf_geometry_for_assimp(const nlohmann::json& doc, const std::filesystem::path& path,
                                                    bool binary) {
  // glTF 1.0 names its meshes (an object) and is read by Assimp's other glTF importer.
  if (!doc.contains("meshes") || !doc["meshes"].is_array()) {
    const nlohmann::json& asset = doc.contains("asset") ? doc["asset"] : nlohmann::json();
    const bool v2 = asset.is_object() && asset.contains("version") && asset["version"].is_string() &&
                    asset["version"].get<std::string>().rfind("2", 0) == 0;
    if (!v2) return std::nullopt;
  }
  nlohmann::json out = only(doc, {"asset", "scene", "scenes", "accessors", "bufferViews", "buffers"});
  if (doc.contains("nodes"))
    out["nodes"] = each(doc["nodes"], [](const nlohmann::json& n) {
      return only(n, {"name", "children", "mesh", "matrix", "translation", "rotation", "scale"});
    });
  if (doc.contains("meshes"))
    out["meshes"] = each(doc["meshes"], [](const nlohmann::json& m) {
      nlohmann::json g = only(m, {"name"});
      if (m.is_object() && m.contains("primitives")) g["primitives"] = each(m["primitives"], primitive_geometry);
      return g;
    });
  const std::string json = out.dump();
  return binary ? glb_of(json, path) : json;
}

}  // namespace loom
