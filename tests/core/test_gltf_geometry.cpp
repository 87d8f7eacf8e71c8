// glTF 2.0 through Assimp: the file reduced to its geometry (core/io/gltf_geometry) and the
// accessors of positions and indices checked within their buffers
// (core/io/gltf_primitive_checks). Each hostile variant below crashed, aborted or
// over-read in Assimp 5.2 before; here it reads as the tetrahedron it carries, or is
// refused with a message naming the file, the primitive and the accessor.

#include "core/error.hpp"
#include "core/io/mesh_read.hpp"
#include "common/gltf_seed.hpp"
#include "common/test_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace loom {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// The tetrahedron seed of the fuzz corpus, parsed.
json tetra() { return json::parse(testing::tetra_gltf_text()); }

/// The seed's buffer bytes.
std::string tetra_bytes() { return testing::tetra_gltf_buffer(); }

/// `doc` written as `name` in `dir`, read by loom.
Mesh read(const fs::path& dir, const std::string& name, const json& doc) {
  testing::write_file(dir / name, doc.dump(1));
  return read_mesh_file(dir / name);
}

/// The InputError message of reading `doc` as `name` in `dir`.
std::string refusal(const fs::path& dir, const std::string& name, const json& doc) {
  testing::write_file(dir / name, doc.dump(1));
  return testing::input_error([&] { read_mesh_file(dir / name); });
}

/// A GLB of `doc` (its buffer 0 the BIN chunk `bin`), padded as the format asks.
std::string glb(const json& doc, std::string bin) {
  std::string text = doc.dump();
  text.append((4 - text.size() % 4) % 4, ' ');
  bin.append((4 - bin.size() % 4) % 4, '\0');
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const auto total = static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size());
  return "glTF" + u32(2) + u32(total) + u32(static_cast<std::uint32_t>(text.size())) + "JSON" + text +
         u32(static_cast<std::uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
}

// What loom does not read — skins, morph targets, materials and their extensions, images,
// animations — is not handed to Assimp, whose readers of it trusted the file: each variant
// below crashed or aborted a Release `loom info` (null skin matrices, a morph target set
// of −1, a one-value texture offset read as two, an image mimeType without '/', a weights
// animation divided by its 0 keyframes).
TEST(GltfGeometry, AssimpReadsTheGeometryAlone) {
  const fs::path d = testing::scratch_dir("loom_gltf_geometry_");
  const Mesh plain = read(d, "plain.gltf", tetra());
  ASSERT_EQ(plain.triangle_count(), 4u);
  std::vector<std::pair<std::string, json>> variants;
  json skin = tetra();
  skin["nodes"][0]["skin"] = 0;
  skin["skins"] = json::parse(R"([{"joints": [0]}])");
  variants.emplace_back("skin without inverse bind matrices", skin);
  json morph = tetra();
  morph["meshes"][0]["primitives"][0]["targets"] = json::parse(R"([{"POSITION_-1": 0}])");
  variants.emplace_back("morph target POSITION_-1", morph);
  json texture = tetra();
  texture["extensionsUsed"] = {"KHR_texture_transform"};
  texture["materials"] = json::array(
      {{{"pbrMetallicRoughness",
         {{"baseColorTexture", {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {1}}}}}}}}}}}});
  texture["textures"] = json::array({{{"source", 0}}});
  texture["images"] = json::array({{{"uri", "data:image/png;base64,AAAA"}}});
  texture["meshes"][0]["primitives"][0]["material"] = 0;
  variants.emplace_back("texture transform of one offset value", texture);
  json image = tetra();
  image["images"] = json::array({{{"bufferView", 0}, {"mimeType", "png"}}});
  image["textures"] = json::array({{{"source", 0}}});
  image["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  image["meshes"][0]["primitives"][0]["material"] = 0;
  variants.emplace_back("image mimeType without '/'", image);
  json weights = tetra();
  weights["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 0}}});
  weights["accessors"].push_back({{"bufferView", 1}, {"componentType", 5126}, {"count", 0}, {"type", "SCALAR"}});
  weights["animations"] = json::parse(R"([{"samplers": [{"input": 2, "output": 2}],
      "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}])");
  variants.emplace_back("weights animation of no keyframes", weights);
  for (const auto& [what, doc] : variants) {
    SCOPED_TRACE(what);
    const Mesh m = read(d, "variant.gltf", doc);
    ASSERT_EQ(m.triangle_count(), plain.triangle_count());
    EXPECT_EQ(m.vertices, plain.vertices);
  }
}

// A GLB is handed to Assimp rebuilt around the reduced JSON with its BIN chunk byte for
// byte: the seeds read as written, and a buffer 0 that names a file is still the BIN chunk
// to Assimp — so the index check reads the BIN chunk too (it read the file, whose indices
// were in range, while Assimp built lines on the BIN chunk's 65 and 512).
TEST(GltfGeometry, GlbIsReadFromItsBinChunk) {
  const fs::path d = testing::scratch_dir("loom_gltf_geometry_");
  for (const char* seed : {"tetra.glb", "tetra-nested.glb"})
    EXPECT_GT(read_mesh_file(fs::path(LOOM_SOURCE_DIR) / "tests/fuzz/seeds/glb" / seed).triangle_count(), 0u) << seed;
  json doc = tetra();
  doc["buffers"][0] = {{"byteLength", 72}, {"uri", "good.bin"}};
  testing::write_file(d / "good.bin", tetra_bytes());
  testing::write_file(d / "body.glb", glb(doc, tetra_bytes()));
  EXPECT_EQ(read_mesh_file(d / "body.glb").triangle_count(), 4u);
  std::string bad = tetra_bytes();
  bad[48] = 65;
  doc["meshes"][0]["primitives"][0]["mode"] = 2;
  testing::write_file(d / "shadow.glb", glb(doc, bad));
  const std::string e = testing::input_error([&] { read_mesh_file(d / "shadow.glb"); });
  EXPECT_NE(e.find("shadow.glb: mesh 0 primitive 0: index 0 of accessor 1 names vertex 65; the primitive has 4"),
            std::string::npos)
      << e;
}

// Positions and indices are read only where their accessors lie whole inside their
// bufferView and buffer, stored whole (not sparse, not implied zeros) and of the types the
// format gives them; a data URI is base64 that decodes. Assimp bounded an accessor by
// count · stride, leaving out its byteOffset (it copied vertices from past the buffer:
// heap-buffer-overflow, garbage vertices in Release), dereferenced a sparse accessor's
// missing bufferView, copied a data URI without ";base64" as raw bytes and decoded a
// character outside the alphabet as 0 — data the index check could not read, and skipped.
TEST(GltfGeometry, AccessorsAreReadWithinTheirBuffers) {
  const fs::path d = testing::scratch_dir("loom_gltf_geometry_");
  struct Case {
    const char* what;
    void (*edit)(json&);
    const char* expected;
  };
  const Case cases[] = {
      {"offset", [](json& j) { j["accessors"][0]["byteOffset"] = 4; },
       "POSITION accessor 0 (4 elements of 12 bytes, 12 apart, from byte 4) reaches beyond its bufferView's 48 bytes"},
      {"stride", [](json& j) { j["bufferViews"][0]["byteStride"] = 8; },
       "POSITION accessor 0 has a bufferView whose byteOffset, byteLength, byteStride (at least 12)"},
      {"sparse",
       [](json& j) {
         j["accessors"][0]["sparse"] = {{"count", 1}, {"indices", {{"componentType", 5123}}}, {"values", json::object()}};
       },
       "POSITION accessor 0 is sparse: loom reads positions and indices stored whole"},
      {"zeros", [](json& j) { j["accessors"][0].erase("bufferView"); },
       "POSITION accessor 0 has no bufferView (all zeros)"},
      {"float indices", [](json& j) { j["accessors"][1]["componentType"] = 5126; },
       "index accessor 1 is not SCALAR of unsigned bytes, shorts or ints"},
      {"no count", [](json& j) { j["accessors"][1].erase("count"); }, "index accessor 1 has no elements: its count is missing"},
      {"raw URI",
       [](json& j) { j["buffers"][0]["uri"] = "data:application/octet-stream," + std::string(72, 'A'); },
       "buffer 0: a data URI that is not base64"},
      {"base64",
       [](json& j) {
         std::string uri = j["buffers"][0]["uri"];
         uri[uri.size() - 3] = '.';
         j["buffers"][0]["uri"] = uri;
       },
       "buffer 0: its data URI holds a character that is not base64"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    json doc = tetra();
    c.edit(doc);
    const std::string e = refusal(d, "bad.gltf", doc);
    EXPECT_NE(e.find(std::string("bad.gltf: ") + (std::strncmp(c.expected, "buffer", 6) ? "mesh 0 primitive 0: " : "") +
                     c.expected),
              std::string::npos)
        << e;
  }
}

}  // namespace
}  // namespace loom
