#pragma once
/// Triangulation of a plane region given by its boundary rings, on the rings' own vertices
/// (CGAL constrained Delaunay triangulation). Used for the caps of extrusions and for the
/// faces that mesh_intersection re-triangulates. Plane coordinates, any units.

#include <Eigen/Core>

#include <array>
#include <vector>

namespace loom {

/// Plane point (as in index/alpha_shape_2d.hpp).
using Vec2 = Eigen::Vector2d;

/// Triangles (indices into `points`, counter-clockwise) covering the region inside an odd
/// number of the `rings` (each a closed loop of indices into `points`; consecutive equal
/// indices are skipped; points with equal coordinates must be one index). No vertex is added: throws std::runtime_error when two rings'
/// edges cross (a triangulation would need a new vertex there).
std::vector<std::array<int, 3>> triangulate_rings(const std::vector<Vec2>& points,
                                                  const std::vector<std::vector<int>>& rings);

}  // namespace loom
