#pragma once
/// Exact Boolean intersection of closed triangle meshes (CGAL Polygon Mesh Processing
/// corefinement on a kernel with exact constructions). α-SIM uses it to intersect the
/// prisms that the slicers of index/extrusion cannot take (three general outlines): the
/// same solid OpenCASCADE's Booleans give, from the meshes the extrusions already are.
/// All coordinates are world frame, scene units.

#include "core/mesh.hpp"

#include <cstddef>
#include <vector>

namespace loom {

/// A closed mesh whose triangles carry the label of the solid's face they lie on.
struct FacedMesh {
  Mesh mesh;              ///< closed, outward-oriented (world frame)
  std::vector<int> face;  ///< per triangle: its face label (≥ 0; one label per plane of the solid)
  /// Faces of the solid: connected sets of triangles with one label (a plane met in two
  /// separate pieces is two faces, as in a B-rep).
  int faces = 0;
};

/// Per triangle of `m`, its face: the smallest triangle index of its connected set of
/// triangles with one label (adjacent across an edge with equal vertex ids). `face` has
/// one label per triangle.
std::vector<std::size_t> labelled_face_ids(const Mesh& m, const std::vector<int>& face);

/// Number of those faces (labelled_face_ids).
int labelled_faces(const Mesh& m, const std::vector<int>& face);

/// The intersection of the solids bounded by a.mesh and b.mesh (each closed,
/// outward-oriented, not self-intersecting, a 2-manifold: pieces that touch along an edge
/// or at a vertex are refused). Computed
/// exactly; the result's vertices are then rounded to double (≤ half an ulp each). Each
/// result triangle keeps the label of the input triangle it is a piece of (b's labels
/// shifted past a's). Corefinement keeps the points where the inputs' triangles were split,
/// so faces are triangulated on more vertices than their corners. Throws
/// std::runtime_error if an input is not a closed, consistently oriented 2-manifold, if CGAL cannot make
/// the result a manifold, or if the result is empty.
FacedMesh mesh_intersection(const FacedMesh& a, const FacedMesh& b);

}  // namespace loom
