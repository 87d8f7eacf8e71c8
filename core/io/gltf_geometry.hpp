#pragma once
/// The part of a glTF 2.0 file that loom hands to Assimp: its geometry alone.
///
/// loom reads a glTF file's triangles and node transforms, nothing else. Assimp 5.2 reads
/// everything, and its readers of what loom ignores trust their input: a skin without
/// inverse bind matrices, a morph target named `POSITION_-1`, a KHR_texture_transform
/// offset of one value, an image mimeType without '/' and a weights animation of no
/// keyframes each crashed or aborted it, and a CUBICSPLINE weights sampler of one output
/// allocated 16 GB. Assimp therefore reads a copy of the file reduced to its scenes,
/// nodes (hierarchy and transforms), meshes (POSITION, indices and mode of each
/// primitive), accessors, buffer views and buffers; the buffers themselves are the file's.

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace loom {

/// The bytes Assimp reads in place of the glTF 2.0 file `path` (`binary`: a GLB, whose
/// container is rebuilt around the reduced JSON and the file's BIN chunk), given its JSON
/// `doc` (checked already). nullopt for a glTF 1.0 file, which Assimp reads as it stands.
std::optional<std::string> gltf_geometry_for_assimp(const nlohmann::json& doc, const std::filesystem::path& path,
                                                    bool binary);

}  // namespace loom
