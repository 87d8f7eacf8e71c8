#pragma once
/// The 2D α-shape of the α-SIM paper (seed: alpha-sim, §3.1 step 3): the union of the
/// triangles of the Delaunay triangulation DT(S) whose circumradius is < α, with its outer
/// and inner boundaries. Built on CGAL's exact-predicate Delaunay_triangulation_2 (CGAL's
/// Alpha_shape_2 in GENERAL mode never marks vertices exterior, DESIGN §9). Coordinates
/// are those of the projection plane the caller chose (scene units).

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

namespace loom {

/// A point in a projection plane (scene units).
using Vec2 = Eigen::Vector2d;

/// True if p comes before q in (x, then y) order: the lexicographic order every sorted
/// point list of α-SIM uses.
inline bool xy_less(const Vec2& p, const Vec2& q) { return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y()); }

/// One connected piece of an α-shape: outer boundary counter-clockwise, holes clockwise.
struct PolygonWithHoles2 {
  std::vector<Vec2> outer;               ///< CCW, not repeated at the end
  std::vector<std::vector<Vec2>> holes;  ///< each CW, not repeated at the end
};

/// The kept-triangle region of a 2D Delaunay triangulation with membership, distance and
/// boundary queries. The region starts as the paper's α-shape and can only grow
/// (cover(), keep_all()), never shrink. Queries are const and thread-safe.
class AlphaShape2D {
 public:
  /// Triangulates `points` (duplicates allowed) and keeps every triangle whose
  /// circumradius is < alpha (alpha ≥ 0; +inf keeps the convex hull), and also every
  /// triangle whose longest edge is ≤ short_edge (0: none): flat slivers between nearly
  /// collinear samples have a huge circumradius but span no gap wider than the sampling.
  AlphaShape2D(const std::vector<Vec2>& points, double alpha, double short_edge = 0.0);
  ~AlphaShape2D();
  AlphaShape2D(AlphaShape2D&&) noexcept;
  AlphaShape2D& operator=(AlphaShape2D&&) noexcept;

  /// The α this shape was built with.
  double alpha() const;
  /// True if the points have fewer than three non-collinear members: no triangle exists.
  bool degenerate() const;
  /// Number of finite Delaunay triangles.
  std::size_t delaunay_triangle_count() const;
  /// Number of kept triangles (the region).
  std::size_t kept_triangle_count() const;
  /// Area of the kept region (scene units²).
  double area() const;
  /// Area of the convex hull of the points (= area after keep_all()).
  double hull_area() const;

  /// Denser sampling where the shape erodes the projection: inserts every given point that
  /// is farther than tol from the region as a triangulation vertex and re-applies the α rule
  /// to all triangles (earlier cover()/keep_all() changes are dropped: call it first).
  /// A notch that a boundary chord cuts into a sliver of the projection then closes with
  /// small triangles instead of the large ones cover() would add. Returns the number of
  /// points that were farther than tol (and inserted); 0: the region is unchanged and holds
  /// every point within tol, so cover() of the same points would only add vertex triangles.
  /// `exact` points are inserted unless they lie in the region (tolerance 0): points of
  /// segment_gaps, whose segment must come within a smaller tolerance than tol.
  std::size_t refine(const std::vector<Vec2>& points, double tol, const std::vector<Vec2>& exact = {});
  /// Keeps every finite Delaunay triangle: the region becomes the convex hull.
  void keep_all();
  /// Makes the region contain every triangulation vertex (an isolated one gets its incident
  /// triangle of smallest circumradius kept) and every given point: a point farther than `tol` from the
  /// region gets the Delaunay triangle(s) containing it kept. Points outside the convex
  /// hull by more than tol cannot be covered and are counted in *uncovered (if given).
  /// Returns the area added (scene units²).
  double cover(const std::vector<Vec2>& points, double tol, std::size_t* uncovered = nullptr);

  /// Keeps the faces that make the region a 2-manifold at every vertex: where its kept
  /// faces around a vertex form several fans (pieces touching at the vertex, which an
  /// extrusion turns into pieces touching along an edge), the gaps between them are filled,
  /// all but the widest (or the one open to the outside of the hull). Returns the area
  /// added (scene units²).
  double fill_pinches();

  /// True if p lies in the region or within tol of it. Points deep inside are answered in
  /// O(1) from a grid of cells known to lie wholly inside the region.
  bool contains(const Vec2& p, double tol = 0.0) const;
  /// Same answer as contains(), by point location only (without that grid): its oracle.
  bool contains_unaccelerated(const Vec2& p, double tol = 0.0) const;
  /// That grid: cell (i, j) is [origin + (i, j)·cell, origin + (i + 1, j + 1)·cell].
  struct InsideGrid {
    Vec2 origin = Vec2::Zero();  ///< lower corner (scene units)
    double cell = 0.0;           ///< cell side (scene units); 0: no grid
    int nx = 0, ny = 0;          ///< cells per axis
    std::size_t inside_cells = 0;  ///< cells that lie wholly inside the region
  };
  /// The grid of the O(1) inside answers of contains() (rebuilt when the region changes).
  InsideGrid inside_grid() const;
  /// Points of the segment ab (plane coordinates) farther than tol from the region: for
  /// each stretch of ab that neither a kept triangle (closed, rounding slack) nor the
  /// tol-neighbourhood of a boundary edge covers, its midpoint and points at most `spacing`
  /// apart along it. Empty: all of ab lies in the region or within tol of it (exact up to
  /// rounding, unlike a test of points sampled on ab). spacing > 0.
  std::vector<Vec2> segment_gaps(const Vec2& a, const Vec2& b, double tol, double spacing) const;
  /// Points of the closed triangle abc (plane coordinates, inside the convex hull of the
  /// points) farther than tol from the region: for each piece of it that a removed
  /// Delaunay triangle d holds, less the strips along d's edges on the boundary that lie
  /// within tol of those edges, the piece's centroid and points along its sides at most
  /// `spacing` apart (all inside d). Empty: the triangle lies in the region or within tol
  /// of it (exact up to rounding; the strips of a flat d are narrower than tol, so such a
  /// d may be reported where it lies within tol). A triangle without area is checked as
  /// its longest edge (segment_gaps). spacing > 0.
  std::vector<Vec2> triangle_gaps(const Vec2& a, const Vec2& b, const Vec2& c, double tol, double spacing) const;
  /// triangle_gaps of every triangle (corners a, b, c), in parallel: their gap points,
  /// sorted (x, then y) and unique, whatever the thread schedule.
  std::vector<Vec2> triangles_gaps(const std::vector<std::array<Vec2, 3>>& triangles, double tol,
                                   double spacing) const;
  /// Signed distance to the region's boundary: negative inside, +inf if the region is empty.
  double signed_distance(const Vec2& p) const;
  /// Every finite Delaunay triangle (plane coordinates, CCW from its lowest corner in
  /// (x, y) order) with 1 if it is kept, 0 if not, in no particular order: where two
  /// snapshots differ, the triangulation or the region changed in between.
  std::vector<std::pair<std::array<Vec2, 3>, char>> snapshot() const;
  /// Boundary loops grouped per connected piece (outer CCW, holes CW), in deterministic order.
  std::vector<PolygonWithHoles2> polygons() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Replaces runs of a closed polygon's vertices that are collinear (paper step 4: included
/// angle < angle_tol_rad) or within dist_tol of the chord that replaces them by that chord,
/// and removes repeated vertices. Every removed vertex stays within
/// max(dist_tol, sin(angle_tol)·chord) of the new boundary. Returns the number removed.
std::size_t merge_collinear(std::vector<Vec2>& ring, double angle_tol_rad, double dist_tol = 0.0);

/// Simplifies the boundary of a region (its pieces: outer rings CCW, holes CW, so the
/// region lies left of every ring) so that the region only GROWS, by less than max_dev
/// (scene units, accumulated over the moves that built each edge). Two moves:
/// - notch: a vertex where the boundary turns right (a notch, a hole's rim) is removed;
///   the triangle it adds must hold no other vertex of any ring;
/// - corner (merge_corners): two consecutive left turns b, c (a convex arc) become one
///   vertex where the lines of the edges before b and after c meet; the triangle it adds
///   must hold no other vertex and its new sides must meet no other edge.
/// Rings stay simple and disjoint and keep at least three vertices. Deterministic
/// (smallest deviation first, ties by position). Returns the number of vertices removed.
std::size_t grow_simplify(std::vector<PolygonWithHoles2>& polys, double max_dev, bool merge_corners = true);

/// Signed area of a closed polygon (positive when counter-clockwise).
double ring_signed_area(const std::vector<Vec2>& ring);

}  // namespace loom
