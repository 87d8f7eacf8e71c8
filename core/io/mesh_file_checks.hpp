#pragma once
/// Checks of a mesh file made before Assimp reads it, for what Assimp 5.2 does not check
/// itself and what makes it crash or allocate without bound:
///
///  - PLY and OFF headers declare element counts that Assimp allocates up front; a count
///    that the file's bytes cannot hold (a 200-byte file declaring 4·10⁹ vertices) is
///    refused before any allocation.
///  - Assimp's OFF reader replaces a face index beyond the vertices by the last vertex (a
///    silently different triangle); such an index is refused, naming its line.
///  - A PLY header must end (Assimp's line reader spun forever on one that did not), and
///    each ASCII instance must be one line of its properties' values (Assimp takes a missing
///    one as 0, and aborted on the face of no vertices that made); each element name is
///    declared once (Assimp wrote a second one's values past the first one's list).
///  - ASCII STL facets (stl_file_checks.hpp): a normal and three vertices each, numbers
///    that are numbers (Assimp leaked every solid it rejected).
///  - DAE (COLLADA) and glTF/GLB node graphs (mesh_node_checks.hpp): nesting deeper than
///    kMaxMeshNesting, instancing cycles and fan-outs, DAE index lists and accessor ranges.
///
/// Files of other formats, and files these checks cannot parse (Assimp then reports its own
/// error), pass unchanged.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace loom {

/// Deepest XML element nesting of a DAE file, and deepest node hierarchy of a glTF/GLB file,
/// accepted. Assimp 5.2 overflowed an 8 MB stack at 8,000 nested DAE nodes and at 20,000
/// glTF nodes; real assemblies nest tens of levels.
constexpr std::size_t kMaxMeshNesting = 1000;

/// One element of a PLY header: its declared instance count and the bytes one instance
/// takes at least in binary (its fixed properties; a list at least its length field).
struct PlyElementExtent {
  std::string name;
  std::uint64_t count = 0;
  std::uint64_t min_bytes = 0;
  int line = 0;  ///< header line, 1-based
};

/// Throws InputError naming `file`, the element and its header line when the declared
/// counts cannot fit the `bytes` after the header: an instance takes at least a byte in
/// ASCII (a line) and min_bytes in binary, and no count may exceed `bytes` (a binary
/// element without properties takes none, yet readers allocate or loop over each one).
/// Shared by the mesh check (before Assimp) and loom's own point-cloud PLY reader.
void check_ply_extents(const std::vector<PlyElementExtent>& elements, bool ascii, std::uint64_t bytes,
                       const std::string& file);

/// The file's extension lower-cased, with its dot (".ply"; "" for none): the format key the
/// checks here and the mesh reader dispatch on.
std::string lower_extension(const std::filesystem::path& path);

/// Throws InputError naming the file (and the line or element) when the file's declared
/// counts exceed what its size can hold, an OFF face names no vertex, an ASCII STL facet
/// fails check_stl_file, a PLY header does not end or an ASCII PLY line does not hold its
/// instance, or a DAE/glTF node graph fails check_dae_file / check_gltf_file.
void check_mesh_file_structure(const std::filesystem::path& path);

}  // namespace loom
