#pragma once
/// Triangle meshes: the exact geometry that loom indexes and audits against.

#include "core/geometry.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace loom {

/// Indexed triangle mesh in world coordinates (scene units). Triangles index
/// `vertices`; orientation is counter-clockwise seen from outside for closed meshes.
struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  /// True when the mesh has no triangles.
  bool empty() const { return triangles.empty(); }
  /// Number of triangles.
  std::size_t triangle_count() const { return triangles.size(); }
  /// Bounding box of the vertices referenced by triangles (all vertices if none).
  AABB bounds() const;
  /// Total surface area (scene units²).
  double area() const;
  /// Signed volume by the divergence theorem (positive for outward orientation).
  /// Meaningful only when is_closed().
  double signed_volume() const;
  /// The three corners of triangle t.
  std::array<Vec3, 3> corners(std::size_t t) const {
    const auto& f = triangles[t];
    return {vertices[f[0]], vertices[f[1]], vertices[f[2]]};
  }
  /// Applies an affine map to every vertex (flips triangle orientation if the map
  /// mirrors, so that outward stays outward).
  void transform(const Eigen::Affine3d& m);
  /// Appends another mesh (indices shifted).
  void append(const Mesh& other);
};

/// Result of the closedness analysis of a mesh.
struct MeshTopology {
  bool closed = false;             ///< every edge shared by exactly two triangles, opposite directions
  std::size_t boundary_edges = 0;  ///< edges used by one triangle
  std::size_t nonmanifold_edges = 0;  ///< edges used by three or more triangles
  std::size_t misoriented_edges = 0;  ///< edges used twice in the same direction
  std::size_t degenerate_triangles = 0;  ///< triangles with a repeated vertex index or zero area
};

/// Merges vertices with identical coordinates (exact match: tessellators and STL
/// writers repeat shared corners bit-for-bit) and drops triangles that repeat an index.
/// Returns the number of vertices removed.
std::size_t weld_identical_vertices(Mesh& mesh);

/// Edge-based closedness analysis (call after weld_identical_vertices).
MeshTopology analyse_topology(const Mesh& mesh);

/// If the mesh is closed and its signed volume is negative, reverses every triangle so
/// that normals point outward. Returns true if it flipped.
bool orient_outward(Mesh& mesh, const MeshTopology& topo);

/// Index of the first non-finite vertex, or -1 if all are finite.
long first_non_finite_vertex(const Mesh& mesh);

}  // namespace loom
