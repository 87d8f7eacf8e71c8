#pragma once
/// Removing the vertices a polyhedral mesh does not need. Exact corefinement
/// (mesh_intersection) keeps every point where it split the inputs' triangles: points along
/// the straight edges between two faces and inside faces, which multiply the triangles
/// without changing the solid. They are removed and the faces that lose one are
/// re-triangulated on the vertices left on their boundary. World frame, scene units.

#include "index/simplify/mesh_boolean.hpp"

#include <cstddef>

namespace loom {

/// What merge_face_vertices removed.
struct FaceVertexMerge {
  std::size_t interior = 0;  ///< vertices inside one face (every triangle around them has one label)
  std::size_t crease = 0;    ///< vertices on a straight edge between two faces
  std::size_t faces_retriangulated = 0;
};

/// Removes from the closed, labelled mesh `m` (each edge in two triangles) every vertex
/// around which all triangles have one label, and every vertex around which they have two
/// labels, with exactly two edges between different labels, lying within `tol` (scene
/// units, ≥ 0) of the segment between the nearest kept vertices along that edge line
/// (Douglas–Peucker along each such chain, so removals never add up beyond `tol`). Each
/// face (connected triangles of one label) that loses a vertex is re-triangulated in its
/// plane on its remaining boundary vertices (triangulate_rings); a face whose boundary
/// touches itself (a vertex twice, or two vertices at one point, as where corefinement's
/// pieces meet) keeps its triangles and vertices instead. The solid moves by at most
/// `tol`; labels and `faces` are kept; unused vertices are dropped, the rest keep their order.
/// Throws std::runtime_error (and leaves m unchanged) if a face's boundary is not a set of
/// simple loops in its plane (it touches itself, or its loops cross once projected) or its
/// new triangles do not cover its area.
FaceVertexMerge merge_face_vertices(FacedMesh& m, double tol);

}  // namespace loom
