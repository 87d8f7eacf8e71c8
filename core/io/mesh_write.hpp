#pragma once
/// Writing triangle meshes: binary STL, binary PLY (optionally with per-vertex colour),
/// and OBJ. All writes are atomic (AtomicFile).

#include "core/mesh.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace loom {

/// Mesh file formats loom writes.
enum class MeshFormat { Stl, Ply, Obj };

/// Format from a file extension (.stl/.ply/.obj, case-insensitive); throws InputError otherwise.
MeshFormat mesh_format_for(const std::filesystem::path& p);

/// Writes `mesh` to `path` in the format of its extension. `colors`, if non-empty, gives one
/// RGB colour per vertex (PLY only; ignored by STL/OBJ).
void write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                const std::vector<std::array<std::uint8_t, 3>>& colors = {});

}  // namespace loom
