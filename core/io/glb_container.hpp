#pragma once
/// The container of a binary glTF (.glb) file, checked before Assimp reads it. Assimp 5.2
/// allocates a chunk by the length its header declares before reading it, so a GLB of a
/// few hundred bytes declaring a 4 GB chunk allocated 4 GB. Layouts:
///  - glTF 2.0: 12-byte header (magic "glTF", version 2, total length), then chunks of
///    (length, type, data); the first chunk is JSON, an optional second one BIN.
///  - glTF 1.0 (KHR_binary_glTF): 20-byte header (magic, version 1, total length, content
///    length, content format 0); the JSON content follows, the binary body after it.

#include <cstdint>
#include <filesystem>
#include <string>

namespace loom {

/// Where a GLB file's JSON and binary body are (bytes from the start of the file).
struct GlbLayout {
  std::uint64_t json_offset = 0;
  std::uint64_t json_length = 0;
  std::uint64_t bin_offset = 0;  ///< first byte of the BIN chunk's data / binary body
  std::uint64_t bin_length = 0;  ///< bytes of the BIN chunk / binary body (0: none)
};

/// Reads and checks a GLB file's header and chunk table against its size: magic, version
/// 1 or 2, a total length no larger than the file, every chunk inside it, a JSON chunk
/// first. Throws InputError naming the file and the header field or chunk otherwise.
GlbLayout read_glb_layout(const std::filesystem::path& path);

/// The JSON of a glTF file, or of a GLB file's JSON chunk (its container checked first).
std::string gltf_json(const std::filesystem::path& path, bool binary);

}  // namespace loom
