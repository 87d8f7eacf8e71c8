#pragma once
/// Checks of the node graphs of DAE (COLLADA) and glTF/GLB files made before Assimp reads
/// them (part of check_mesh_file_structure). Assimp 5.2 walks a node hierarchy recursively
/// and builds every instance of a shared node and its meshes, so a node graph that is deep,
/// cyclic or fans out (a "billion laughs" of instancing) crashes it or exhausts memory. The
/// DAE check also covers the COLLADA data Assimp trusts: accessor ranges and index lists.

#include <filesystem>

namespace loom {

/// Most node instances a DAE or glTF file may expand to through nodes shared by several
/// parents (instance_node, repeated glTF children), unless the file holds that many nodes
/// itself. Measured: Assimp and loom take ~2.4 KB per instance (a DAE instancing one
/// triangle 262,144 times through 18 doubling levels: 684 MB resident, 12 s, `loom info`),
/// so 2^18 instances stay under 1 GB; 24 such levels took >6 GB and did not finish.
constexpr double kMaxMeshNodeInstances = 1 << 18;

/// Most triangle corners (vertex references of the index lists) a DAE or glTF file may
/// expand to through instancing, unless the file holds that many itself. Measured: a read
/// triangle costs ~1.4 KB at the peak of `loom info` (a 1,000,000-triangle OBJ: 1.47 GB
/// resident), so 3·2^22 corners (4.2M triangles) stay near 6 GB, as a mesh file of that many
/// triangles of its own would.
constexpr double kMaxMeshInstancedCorners = 3.0 * (1 << 22);

/// Throws InputError naming the file, the element and its line for a DAE file whose XML nests
/// deeper than kMaxMeshNesting, whose nodes instance each other in a cycle or expand beyond
/// kMaxMeshNodeInstances / kMaxMeshInstancedCorners, whose <p> or <vcount> lists hold a value
/// that is not an index, or whose accessor reaches beyond its array.
void check_dae_file(const std::filesystem::path& path);

/// Throws InputError naming the file and node for a glTF (or GLB, `binary`) file whose node
/// hierarchy is deeper than kMaxMeshNesting, cyclic, or expands beyond kMaxMeshNodeInstances /
/// kMaxMeshInstancedCorners, and for one whose JSON does not parse or is not an object (Assimp
/// would offer it to its other importers by content).
void check_gltf_file(const std::filesystem::path& path, bool binary);

}  // namespace loom
