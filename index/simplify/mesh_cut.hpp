#pragma once
/// Cutting a triangle mesh by an axis-aligned plane into the parts on either side (α-SIM
/// splits a part whose projections hide a feature). World frame, scene units.

#include "core/mesh.hpp"

namespace loom {

/// The two sides of a cut.
struct MeshHalves {
  Mesh below;  ///< triangles (pieces of triangles) with coordinate ≤ the plane's
  Mesh above;  ///< triangles (pieces of triangles) with coordinate ≥ the plane's
};

/// Cuts `mesh` by the plane x[axis] = at (axis 0, 1, 2). A triangle on one side goes whole
/// to that side; a triangle across the plane is clipped into a polygon on each side, fanned
/// into triangles that keep its orientation; a triangle in the plane goes below. A point
/// where an edge crosses the plane is computed once from the edge's two vertices in index
/// order, with its axis coordinate set to `at`, so both sides share it bit for bit and
/// neighbouring triangles stay joined. The union of the halves is the mesh's surface.
MeshHalves cut_mesh(const Mesh& mesh, int axis, double at);

}  // namespace loom
