#pragma once
/// Extrusions (α-SIM's prisms: a plane region swept along the plane normal) and the cheap
/// part of intersecting them. A prism whose region is one axis-aligned rectangle, in a
/// frame whose axes are world axes, is the intersection of three axis slabs; each slab is
/// either implied by another prism's extent or applied by clipping another prism's depth
/// range (or rectangle). Absorbing such prisms leaves fewer general Booleans to run, and
/// none at all when one prism remains (meshed directly) or two whose normals are different
/// axes (sliced along the third).
/// All coordinates are world frame, scene units.

#include "core/mesh.hpp"
#include "index/simplify/alpha_shape_2d.hpp"
#include "index/simplify/face_vertices.hpp"
#include "index/simplify/mesh_boolean.hpp"

#include <cstddef>
#include <vector>

namespace loom {

/// A region of the plane (u, v) swept along n over [depth_min, depth_max].
struct Extrusion {
  Vec3 u = Vec3::UnitX(), v = Vec3::UnitY(), n = Vec3::UnitZ();  ///< orthonormal, n = u × v
  double depth_min = 0.0, depth_max = 0.0;                         ///< range of p·n
  std::vector<PolygonWithHoles2> polygons;  ///< in (p·u, p·v): outer rings CCW, holes CW
};

/// True if u, v and n are each exactly ± a world axis.
bool axis_aligned(const Extrusion& e);

/// True if e is axis_aligned and its region is one rectangle with sides along u and v
/// (four vertices, no hole): then e is the intersection of three world-axis slabs.
bool is_axis_box(const Extrusion& e);

/// What reduce_extrusions kept.
struct ExtrusionReduction {
  /// The intersection of these contains the intersection of the input and lies within
  /// `slack` of it along every world axis (equal when slack is 0).
  std::vector<Extrusion> kept;
  std::size_t absorbed = 0;  ///< axis boxes whose slabs were all implied or applied elsewhere
};

/// Absorbs axis boxes into the other extrusions (see the file comment). A box's slab along
/// a world axis is implied by a kept extrusion whose in-plane extent along that axis lies
/// within the slab widened by `slack` (≥ 0; the result then stands off by at most that),
/// else applied to a kept extrusion whose normal is that axis (its depth range is clipped)
/// or which is itself a box (its rectangle is clipped). Boxes are kept where neither holds.
/// Input order is kept among the non-box extrusions. If clipping would leave an empty
/// range, the input is returned unchanged (absorbed = 0): the caller's general path decides.
ExtrusionReduction reduce_extrusions(const std::vector<Extrusion>& in, double slack);

/// Closed, outward-oriented triangle mesh of one extrusion: each polygon's caps from a
/// constrained Delaunay triangulation of its rings (CGAL), two triangles per ring edge on
/// the walls; vertices are shared, so the mesh is watertight by construction. Throws
/// std::runtime_error when a polygon's rings cross (a cap would need new vertices), when
/// the region is empty or when depth_min ≥ depth_max.
Mesh extrusion_mesh(const Extrusion& e);

/// B-rep faces of the extrusion as a solid: one wall per ring edge, two caps per polygon.
int extrusion_faces(const Extrusion& e);

/// A closed, outward-oriented mesh of an intersection of extrusions, and its faces: B-rep
/// faces for one extrusion (extrusion_faces), distinct face planes for two.
struct ExtrusionsMesh : FacedMesh {
  int booleans = 0;  ///< general Booleans run (CGAL corefinements, mesh_intersection)
};

/// The intersection of two axis-aligned extrusions whose normals are different world axes
/// (so both regions contain the third axis, c). Sliced along c at every vertex of either
/// region and where an edge crosses the other extrusion's depth bounds, each slab is a
/// union of hexahedra (a slice of one region times a slice of the other, bounds moving
/// linearly); at each slice plane the faces are the cells of the bounds' grid that lie
/// below or above only, and every edge in that plane is split at every grid point it
/// passes, so vertices are shared (computed once per edge and height) and the mesh is
/// conforming. Faces stay split where their pieces are: re-triangulating each face plane as
/// a whole gave fewer triangles but long ones across whole faces, coarser Embree leaves and
/// ~20% slower clearance queries on the wing. Throws std::runtime_error when the frames are
/// not of that kind or the intersection is empty.
ExtrusionsMesh extrusion_pair_mesh(const Extrusion& a, const Extrusion& b);

/// The intersection of `kept` (≥ 1): one extrusion is meshed directly (extrusion_mesh),
/// two axis extrusions across each other are sliced (extrusion_pair_mesh); any other is
/// intersected with the rest by exact corefinement of the meshes (mesh_intersection), one
/// general Boolean each, after which the vertices the corefinement left inside faces and
/// along straight edges are removed (merge_face_vertices; the solid moves by at most
/// `tol`, scene units; a thousandth of it is used before the Boolean, on the vertices the
/// slicing left on straight edges). Of three, the pair sliced first is the first of (0, 1), (0, 2),
/// (1, 2) whose Boolean succeeds (pieces that touch make CGAL refuse it). Faces: as those
/// give them. Throws std::runtime_error for an empty list, and what those throw.
ExtrusionsMesh mesh_extrusions(const std::vector<Extrusion>& kept, double tol);

}  // namespace loom
