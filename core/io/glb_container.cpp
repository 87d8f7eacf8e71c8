#include "core/io/glb_container.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"

#include <string>

namespace loom {

namespace {

constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON", little-endian
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

/// Little-endian 32-bit word at byte `at` of `bytes` (the caller checks the range).
std::uint32_t u32(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(k)]);
  return v;
}

}  // namespace

GlbLayout read_glb_layout(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
  if (ec) throw InputError({path.string(), 0, "GLB header"}, "cannot read the file size: " + ec.message());
  const std::string head = file_bytes(path, 20);
  auto refuse = [&](const std::string& what, const std::string& why) { throw InputError({path.string(), 0, what}, why); };
  if (head.size() < 12 || head.compare(0, 4, "glTF") != 0)
    refuse("GLB header", "not a binary glTF file (no 12-byte header starting with 'glTF')");
  const std::uint32_t version = u32(head, 4);
  const std::uint64_t length = u32(head, 8);
  if (version != 1 && version != 2) refuse("GLB header", "version " + std::to_string(version) + " is not 1 or 2");
  if (length > size)
    refuse("GLB header", "declares " + std::to_string(length) + " bytes, the file holds " + std::to_string(size) +
                             " (a truncated or corrupt file?)");
  GlbLayout out;
  if (version == 1) {
    if (head.size() < 20 || length < 20) refuse("GLB header", "a glTF 1.0 binary header takes 20 bytes");
    out.json_offset = 20;
    out.json_length = u32(head, 12);
    if (out.json_length > length - 20)
      refuse("GLB content", "content length " + std::to_string(out.json_length) + " reaches beyond the declared " +
                                std::to_string(length) + " bytes");
    out.bin_offset = 20 + out.json_length;
    out.bin_length = length - 20 - out.json_length;
    return out;
  }
  // glTF 2.0: walk the chunk table; each chunk's 8-byte header and data must fit.
  std::uint64_t at = 12;
  for (int chunk = 0; at < length; ++chunk) {
    const std::string what = "GLB chunk " + std::to_string(chunk);
    if (length - at < 8) refuse(what, "its 8-byte header reaches beyond the declared " + std::to_string(length) + " bytes");
    const std::string ch = file_bytes(path, static_cast<std::size_t>(at) + 8).substr(static_cast<std::size_t>(at));
    if (ch.size() < 8) refuse(what, "the file ends inside the chunk header");
    const std::uint64_t n = u32(ch, 0);
    const std::uint32_t type = u32(ch, 4);
    if (n > length - at - 8)
      refuse(what, "declares " + std::to_string(n) + " bytes from byte " + std::to_string(at + 8) +
                       ", beyond the declared " + std::to_string(length) + " bytes");
    if (chunk == 0 && type != kChunkJson) refuse(what, "the first chunk is not JSON");
    if (chunk == 0) {
      out.json_offset = at + 8;
      out.json_length = n;
    } else if (chunk == 1 && type == kChunkBin) {
      out.bin_offset = at + 8;
      out.bin_length = n;
    }
    at += 8 + n;
  }
  if (out.json_offset == 0) refuse("GLB chunk 0", "the file has no JSON chunk");
  return out;
}

std::string gltf_json(const std::filesystem::path& path, bool binary) {
  if (!binary) return file_bytes(path);
  const GlbLayout glb = read_glb_layout(path);
  return file_bytes(path, static_cast<std::size_t>(glb.json_offset + glb.json_length))
      .substr(static_cast<std::size_t>(glb.json_offset));
}

}  // namespace loom
