#pragma once
/// α-SIM (seed: alpha-sim; DESIGN §6–§7): simplify a part to the level of detail a cable
/// needs. Sample the surface (L_max = 0.5·dim_pre), project onto XY, XZ, YZ (+ user planes),
/// take the 2D α-shape of each projection (α = 0.95·dim_pre), extrude each along its plane
/// normal over the part's extent and intersect. The result must CONTAIN the original part
/// (a route clear of it is clear of the real part): it is verified on dense samples, and
/// where the method fails the failure is reported and a safe fallback is used.
/// All coordinates are world frame, scene units.

#include "core/mesh.hpp"
#include "core/part.hpp"
#include "core/progress.hpp"
#include "index/simplify/alpha_shape_2d.hpp"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace loom {

/// How a part is simplified. dim_pre is required; every other value has the paper's default.
/// Containment of every triangle in every projection is made exact (up to rounding): each
/// triangle's gaps — pieces of it farther than the tolerance from the α-shape
/// (AlphaShape2D::triangle_gaps; those seen edge-on by their longest edge, segment_gaps) —
/// are found and repaired, a few passes, then the plane falls back to its hull. The
/// `measure` pass still verifies dense random samples, against the mesh and the implicit
/// solid.
struct AlphaSimOptions {
  double dim_pre = 0.0;          ///< features smaller than this vanish (scene units, > 0)
  double sampling_factor = 0.5;  ///< L_max = sampling_factor·dim_pre (paper §3.2: 0.5)
  double alpha_factor = 0.95;    ///< α = alpha_factor·dim_pre (paper §3.2: 0.95)
  /// Delaunay triangles whose longest edge is ≤ min(short_edge_factor·L_max, α) are kept whatever
  /// their circumradius: flat slivers between nearly collinear samples of a silhouette
  /// (otherwise they erode the projection; 0 = the paper's definition only).
  double short_edge_factor = 1.0;
  bool coordinate_planes = true;  ///< project onto XY, XZ, YZ
  std::vector<Vec3> extra_planes;  ///< normals of user projection planes (need not be unit)
  /// Scene size used for tolerances (bbox diagonal); ≤ 0: the part's own diagonal.
  double scene_size = 0.0;
  /// "Inside or on" tolerance = containment_tolerance_factor·scene_size.
  double containment_tolerance_factor = 1e-6;
  /// A projection whose repaired (added) area exceeds this fraction of its final area is
  /// "torn" (α too small for the sampling) and replaced by its convex hull.
  double torn_fraction = 0.05;
  /// A part thinner than thin_factor·dim_pre along a plane normal is a sheet: kept as is.
  double thin_factor = 1e-4;
  /// Lost-space check (the paper's "blocked projection"): if a ball of radius
  /// lost_space_factor·dim_pre fits inside the simplified part but outside the original,
  /// a feature was hidden in every projection → status Blocked, original part kept.
  bool detect_lost_space = true;
  double lost_space_factor = 2.0;
  std::size_t lost_space_max_samples = 1u << 18;  ///< grid points probed at most
  /// A closed part whose lost-space probe finds a hidden feature is split rather than kept
  /// whole (simplify_part_split): cut by axis-aligned planes around the lost ball, each
  /// piece simplified on its own and probed against the whole part, recursively while a
  /// piece is blocked. No piece is cut thinner than dim_pre. false keeps such a part as it is.
  bool split_blocked = true;
  /// Cut levels at most: a guard on the recursion, not the stop (a piece never thinner than
  /// dim_pre is); a curved shell needs 7–8 levels before each piece's arc hides too little.
  int split_max_depth = 16;
  std::size_t split_max_pieces = 256;  ///< pieces of one part at most: bounds the work
  /// Dense containment samples of the original surface: about this many per L_max² of area
  /// (at least the vertices, edge midpoints, centroids and two random points per triangle).
  double containment_density = 4.0;
  std::size_t containment_max_samples = 400000;
  /// Most samples in one projection plane (memory bound, ~100 bytes per point).
  std::size_t max_cloud_points = 4000000;
  /// The boundary polygons that are extruded may grow the α-shape (never shrink it) by
  /// less than polygon_growth_factor·dim_pre where that removes vertices (notches, hole
  /// rims, and with merge_convex_corners pairs of corners on convex arcs): fewer faces and
  /// triangles. The implicit solid keeps the exact α-shapes (so the lost-space probe,
  /// which uses it, may miss up to this much of the mesh's growth).
  double polygon_growth_factor = 0.25;
  /// Convex arcs (a cylinder seen end-on) are also coarsened, outwards (grow_simplify).
  bool merge_convex_corners = true;
  bool build_mesh = true;       ///< prisms ∩ → triangle mesh (else implicit only)
  bool measure = true;          ///< containment of the mesh + Hausdorff distance
  /// The output mesh's vertices are rounded to float32 (the binary STL that `loom
  /// simplify` writes holds nothing finer) before the mesh is checked closed and measured,
  /// so that the checks hold for the file. The shapes are built within the tolerance less
  /// float_rounding_reserve; a rounding larger than that (a part far from the origin,
  /// |x| ≳ 2^23·tolerance, whose simplified mesh has vertices that are not float32 already)
  /// keeps the original (status failed, with the reason). false keeps the exact double
  /// vertices (then a binary STL of the mesh may not contain the original).
  bool float32_vertices = true;
  /// The part of the containment tolerance kept for that rounding (scene units, at most
  /// half the tolerance): the shapes are built within the rest. < 0: a bound on the
  /// rounding derived from the part's bounding box (simplify_parts sets one for all parts,
  /// from all of them, that also covers a moved copy's second rounding).
  double float_rounding_reserve = -1.0;
  /// With measure: also the Hausdorff distance (a figure for the report: routing, which
  /// needs the containment check and the lost-space probe only, skips it; then 0).
  bool hausdorff = true;
  /// If set, writes <step_dir>/<stem>.step (OpenCASCADE); the stem is simplify_part's
  /// `step_stem`, in simplify_parts the part's output_file_stems entry.
  std::filesystem::path step_dir;
  std::uint64_t seed = 1;       ///< random containment samples
  /// simplify_parts: stage "simplify", parts done, one call at a time from TBB workers.
  ProgressFn progress;
};

/// What happened to one projection plane.
enum class ProjectionStatus {
  Ok,        ///< the α-shape covered every triangle
  Repaired,  ///< Delaunay triangles were added (or points inserted) so that it does
  Empty,     ///< α too small for the sampling: no triangle kept → convex hull
  Torn,      ///< too much had to be repaired → convex hull
  Eroded,    ///< the α-shape still missed part of the surface after its repairs → convex hull
};
/// "ok" | "repaired" | "empty" | "torn" | "eroded".
const char* projection_status_name(ProjectionStatus s);

/// Outcome of simplifying one part.
enum class AlphaSimStatus {
  Ok,          ///< simplified, every projection an α-shape
  HullFallback,///< simplified, some projection replaced by its convex hull (see projections)
  Thin,        ///< too thin along a projection normal (a sheet): original kept
  Blocked,     ///< a feature hidden in every projection: space a cable could use was filled; original kept
  Failed,      ///< the mesh could not be built or did not contain the original: original kept
  EmptyInput,  ///< the part has no triangles
  TooFine,     ///< dim_pre so small that a plane would exceed max_cloud_points samples: original kept
};
/// "ok" | "hull_fallback" | "thin" | "blocked" | "failed" | "empty_input" | "too_fine".
const char* alpha_sim_status_name(AlphaSimStatus s);

/// Which fallback was used.
enum class AlphaSimFallback { None, ConvexHull, Original };
/// "none" | "convex_hull" | "original".
const char* alpha_sim_fallback_name(AlphaSimFallback f);

/// Report of one projection plane.
struct ProjectionReport {
  std::string plane;  ///< "XY", "XZ", "YZ" or "user0"...
  Vec3 normal = Vec3::UnitZ();
  ProjectionStatus status = ProjectionStatus::Ok;
  std::size_t points = 0;              ///< projected cloud points
  std::size_t delaunay_triangles = 0;
  std::size_t kept_triangles = 0;      ///< after repair / fallback
  double alpha_area = 0.0;             ///< area of the plain α-shape (scene units²)
  double area = 0.0;                   ///< final area
  double hull_area = 0.0;              ///< convex hull area
  std::size_t edge_on_triangles = 0;   ///< triangles seen edge-on: checked by their longest edge, not sampled
  std::size_t edge_on_segments = 0;    ///< the unique edges those checks ran on
  std::size_t exact_triangles = 0;     ///< the others, tested whole
  std::size_t exact_gaps = 0;          ///< gap points those exact tests found and repaired
  std::size_t polygon_vertices = 0;    ///< boundary vertices after merging collinear ones
  std::size_t polygons = 0;            ///< connected pieces
  std::size_t holes = 0;
};

/// One node of a split part's tree: a piece cut from the part and what happened to it.
struct AlphaSimPiece {
  std::string id;   ///< path in the tree: "1" (second child of the part), "1.0", ...
  std::string cut;  ///< the slab of its last cut, e.g. "-28 <= x <= 28" (scene units)
  AABB box;         ///< bounds of the piece's (cut) triangles, world frame
  /// false: the piece was cut again (its children follow it): blocked, or failed and halved
  bool leaf = true;
  AlphaSimStatus status = AlphaSimStatus::Ok;  ///< Blocked or Failed for a piece cut again
  std::string reason;
  std::size_t triangles_before = 0, triangles_after = 0;
  double containment = 1.0;        ///< as AlphaSimResult::containment, for the piece
  double lost_space_radius = 0.0;  ///< against the whole part
};

/// Per-part result (DESIGN §4 simplify.json fields + diagnostics).
struct AlphaSimResult {
  std::string name;
  AlphaSimStatus status = AlphaSimStatus::Ok;
  AlphaSimFallback fallback = AlphaSimFallback::None;
  std::string reason;  ///< why a fallback was used (empty when none)
  double dim_pre = 0.0, alpha = 0.0, l_max = 0.0, tolerance = 0.0;
  std::size_t sample_points = 0;       ///< projected samples, summed over the planes
  std::size_t triangles_before = 0, triangles_after = 0;
  int faces_before = 0, faces_after = 0;  ///< B-rep faces (STEP sources), OpenCASCADE result faces
  bool closed_before = false, closed_after = false;
  double volume_before = 0.0, volume_after = 0.0;  ///< 0 when the mesh is not closed
  double containment = 1.0;           ///< fraction of dense original samples inside/on the output mesh
  /// Same against the implicit solid (1 by construction when not measured).
  double containment_implicit = 1.0;
  std::size_t containment_samples = 0;
  double hausdorff = 0.0;             ///< max over the output surface of the distance to the original (0 unless measured)
  /// Largest move of an output vertex rounded to float32 (float32_vertices; scene units).
  double float_rounding = 0.0;
  double lost_space_radius = 0.0;     ///< largest probed ball radius filled by the simplification
  Vec3 lost_space_center = Vec3::Zero();  ///< centre of that ball (world frame; when the radius is > 0)
  double lost_space_resolution = 0.0; ///< grid spacing of that probe
  double time_ms = 0.0;
  double shapes_ms = 0.0;   ///< sampling + α-shapes + repair + implicit verification
  double mesh_ms = 0.0;     ///< extrusion, intersection (OpenCASCADE Booleans where needed), meshing
  /// Prisms whose region was an axis-aligned rectangle and whose slabs the other prisms
  /// carry (reduce_extrusions): each one is a Boolean fewer.
  int prisms_absorbed = 0;
  /// General Boolean operations run (0: one prism was left, or two sliced by loom).
  int booleans = 0;
  /// What ran them: "none", "cgal" (exact mesh corefinement) or "opencascade" (B-rep).
  std::string booleans_by = "none";
  /// Why OpenCASCADE ran them where loom's own path was tried first and refused (its
  /// message), or "--step" when asked (STEP output needs the B-rep); empty otherwise.
  std::string booleans_note;
  double measure_ms = 0.0;  ///< mesh containment, Hausdorff, lost-space probe
  std::vector<ProjectionReport> projections;
  /// simplify_parts: the earlier part this one is a moved copy of (its result was moved,
  /// not recomputed; time_ms is the copy's); empty otherwise.
  std::string copy_of;
  /// A split part's tree, depth first (empty when the part was not split). When every leaf
  /// was simplified the part's mesh is the union of theirs; else the original is kept.
  std::vector<AlphaSimPiece> pieces;
};

/// One extrusion: a 2D region in a plane frame swept over a depth range.
struct AlphaSimPrism {
  Vec3 u = Vec3::UnitX(), v = Vec3::UnitY(), n = Vec3::UnitZ();  ///< orthonormal, n = u × v
  double depth_min = 0.0, depth_max = 0.0;  ///< range of p·n
  std::shared_ptr<const AlphaShape2D> shape;
  /// Projection coordinates (p·u, p·v).
  Vec2 project(const Vec3& p) const { return Vec2(p.dot(u), p.dot(v)); }
};

/// The implicit simplified solid: p is inside iff every projection lies in its 2D shape and
/// p lies within every prism's depth range. Queries are const and thread-safe.
class AlphaSimSolid {
 public:
  AlphaSimSolid() = default;
  explicit AlphaSimSolid(std::vector<AlphaSimPrism> prisms);
  /// True if p is inside or within tol of every prism.
  bool contains(const Vec3& p, double tol = 0.0) const;
  /// Signed distance bound: max over prisms of the signed distance to the prism.
  /// Exact sign; outside, a lower bound on the true distance (never overestimates clearance).
  double distance_bound(const Vec3& p) const;
  /// The prisms.
  const std::vector<AlphaSimPrism>& prisms() const { return prisms_; }

 private:
  std::vector<AlphaSimPrism> prisms_;
};

/// A simplified part: the mesh for viewing and indices, the implicit solid, the report.
struct AlphaSimPart {
  Mesh mesh;                                   ///< world frame; the original mesh on fallback Original
  std::shared_ptr<const AlphaSimSolid> solid;  ///< null when the original is kept or the part was split
  /// A split part's leaves' solids (the simplified part is their union), in tree order.
  std::vector<std::shared_ptr<const AlphaSimSolid>> piece_solids;
  AlphaSimResult result;
};

/// Simplifies one part. Throws std::invalid_argument if opt.dim_pre is not finite and > 0.
/// With opt.step_dir set, the STEP file is <step_dir>/<step_stem>.step (empty: the part's
/// name made a file name by output_file_stems).
AlphaSimPart simplify_part(const Part& part, const AlphaSimOptions& opt, const std::string& step_stem = {});

/// Simplifies one part like simplify_part and, when a hidden feature blocks it and
/// opt.split_blocked is set, splits it (part_split.cpp): the result's mesh is then the union
/// of closed pieces that overlap only within the prisms' margin, result.pieces the tree.
/// No STEP file is written for a split part (its pieces are separate solids).
AlphaSimPart simplify_part_split(const Part& part, const AlphaSimOptions& opt, const std::string& step_stem = {});

/// Simplifies every part in parallel (TBB), blocked parts split (simplify_part_split), and
/// returns them with the simplified meshes (names, roles, clearances kept), ready for any
/// ObstacleIndex. opt.scene_size ≤ 0 is
/// replaced by the diagonal of all parts. Results in part order if `results` is given.
/// A part that is a moved copy of an earlier one (same triangles; vertices = R·v + t within
/// 1e-2 of the tolerance, R a rotation mapping the axes onto themselves, e.g. a part turned
/// end for end; R = identity only when user planes are given) gets that part's result
/// moved the same way (copy_of).
std::vector<Part> simplify_parts(const std::vector<Part>& parts, const AlphaSimOptions& opt,
                                 std::vector<AlphaSimResult>* results);

/// The samples of one projection plane (α-SIM steps 1–2), plane coordinates (p·u, p·v),
/// snapped, each set sorted (x, then y) and unique.
struct AlphaSimPlaneSamples {
  std::vector<Vec2> points;  ///< the point cloud the α-shape is built on
  std::vector<Vec2> checks;  ///< points between them that the α-shape must cover
};

/// The samples simplify_part takes in the plane of `frame` (u, v; world frame, scene units)
/// at spacing l_max, snapped to the grid `snap`: projected vertices, outline edges (all but
/// those inside the projection of their two triangles) subdivided to ≤ l_max, and the
/// nodes (points) and cell centres (checks) of the lattice of spacing
/// l_max inside each projected triangle, plus sub-edge midpoints and centroids (checks).
/// Vertices and subdivision points in a lattice cell whose four corners are nodes are
/// left out of the points (the corners already cover that cell); every check is kept.
/// lattice_bitmap = false deduplicates by sorting every point (the reference; same sets).
/// coarse_interior drops the nodes of odd index, and the cell centres, inside the cells of
/// spacing 2·l_max whose nine nodes are all met (the interior; simplify_part coarsens it).
/// all_checks = false leaves out the cell centres, the centroids and the midpoints of edges
/// inside the projection (simplify_part tests the triangles whole; the outline's sub-edge
/// midpoints stay).
AlphaSimPlaneSamples alpha_sim_plane_samples(const Mesh& mesh, const AlphaSimPrism& frame, double l_max, double snap,
                                             bool lattice_bitmap = true, bool coarse_interior = false,
                                             bool all_checks = true);

/// Dense samples of a mesh surface: the fixed points — vertices and edge midpoints (each
/// once) and centroids — unless fixed_points is false, and random points (≈ density per
/// spacing² of area, at least two per triangle), capped at max_samples random ones;
/// deterministic for a seed. World frame.
std::vector<Vec3> dense_surface_samples(const Mesh& mesh, double spacing, double density,
                                        std::size_t max_samples, std::uint64_t seed, bool fixed_points = true);

}  // namespace loom
