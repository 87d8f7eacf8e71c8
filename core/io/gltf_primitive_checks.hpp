#pragma once
/// The mesh primitives of a glTF 2.0 file, checked before Assimp reads it:
///  - a strip or fan has enough vertices for one face (a line strip or loop 2, a triangle
///    strip or fan 3): Assimp 5.2 sizes its faces as count − 2 (or − 1), unsigned, and a
///    triangle strip with no vertices asked for 2³² faces (69 GB);
///  - its POSITION and index accessors are of their types, stored whole and inside their
///    bufferView and buffer: Assimp bounds an accessor without its byteOffset and copied
///    vertices from past the buffer, and dereferenced a sparse accessor's missing view;
///  - every index of an indexed primitive names one of its vertices: Assimp skips a line
///    of a LINE_LOOP whose index is out of range but leaves its face empty, and
///    dereferenced the empty face later (SIGSEGV); for other modes it reports the index,
///    or builds faces on vertices that are not there.

#include <nlohmann/json_fwd.hpp>

#include <filesystem>

namespace loom {

/// Checks every mesh primitive of `doc` (the file's JSON; `binary`: a GLB, whose buffer 0
/// Assimp takes from the BIN chunk) as above, reading index accessors from their buffers —
/// the BIN chunk, a base64 data URI or a file beside `path` — and throws InputError naming
/// the file, the mesh and primitive and the figures: the mode and its vertices, the
/// accessor and what is wrong with it, or the index's position and value. A buffer file
/// that does not open is left to Assimp, which reports it; glTF 1.0 (meshes by name) is
/// not checked here.
void check_gltf_primitives(const nlohmann::json& doc, const std::filesystem::path& path, bool binary);

}  // namespace loom
