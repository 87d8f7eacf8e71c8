#pragma once
/// The index data of a glTF 2.0 file, checked before Assimp reads it: every index of every
/// indexed mesh primitive names one of the primitive's vertices. Why: Assimp 5.2 skips a
/// line of a LINE_LOOP primitive whose index is out of range but leaves its face empty, and
/// dereferenced the empty face later (SIGSEGV); for other modes it reports the index, or
/// builds faces on vertices that are not there.

#include <nlohmann/json_fwd.hpp>

#include <filesystem>

namespace loom {

/// Reads the index accessor of every mesh primitive of `doc` (the file's JSON; `binary`: a
/// GLB, whose buffer without a uri is its BIN chunk) from its buffer — the BIN chunk, a
/// base64 data URI or a file beside `path` — and throws InputError naming the file, the mesh
/// and primitive, the index's position and value when an index is not below the count of
/// the primitive's POSITION accessor, or when the accessor's data reach beyond its buffer
/// view or buffer. Primitives it cannot follow (glTF 1.0 names, sparse or missing
/// accessors, a buffer file that does not open) are left to Assimp, which reports them.
void check_gltf_indices(const nlohmann::json& doc, const std::filesystem::path& path, bool binary);

}  // namespace loom
