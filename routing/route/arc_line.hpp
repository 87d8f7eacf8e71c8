#pragma once
/// Arc–line routes: a polyline whose every corner is rounded by a circular arc of one radius,
/// tangent to both legs (the 3-D analogue of a Dubins path with free headings at the
/// vertices). A corner turning θ needs a tangent length t = R·tan(θ/2) on each of its legs;
/// the route is bend-feasible iff every leg holds the tangents of both its ends. The two end
/// vertices are stub ends: their outer leg is the straight run of the stub (its far end, the
/// port or branch point, is fixed and does not turn). World frame, scene units.

#include "core/geometry.hpp"
#include "index/obstacle_index.hpp"

#include <vector>

namespace loom {

/// Straight run, in bend radii, that a bend-feasible route keeps between the arcs of two
/// consecutive corners turning in opposite senses (an inflection): a cubic through the
/// rounded points bends tighter than the arcs where they meet there directly (the curvature
/// jumps by 2/R) than at a lone corner; this much straight between them keeps it within the
/// margin the router rounds with (test_arc_line). Arcs continuing one another in one plane
/// need none.
inline constexpr double kInnerLegSlack = 0.2;

/// The fixed headings and straight runs at the two ends of an arc–line route.
struct ArcLineEnds {
  Vec3 start_heading = Vec3::UnitX();  ///< unit direction of travel arriving at the first vertex
  double start_run = 0.0;              ///< straight length before the first vertex (its stub)
  Vec3 end_heading = Vec3::UnitX();    ///< unit direction of travel leaving the last vertex
  double end_run = 0.0;                ///< straight length after the last vertex (its stub)
};

/// The leg of an arc–line route that cannot hold the tangents of its two corners.
struct ShortLeg {
  int leg = -1;            ///< −1: feasible; k: the leg ending at vertex k (0: the start run; n: the end run)
  Vec3 at = Vec3::Zero();  ///< the corner of the leg that turns most (world frame)
  double needed = 0.0;     ///< tangent lengths (and slack) the leg must hold (scene units)
  double length = 0.0;     ///< the leg's length (scene units)
};

/// Unit direction of travel into vertex k of `v` (the start heading at k = 0).
Vec3 arc_line_in(const std::vector<Vec3>& v, const ArcLineEnds& ends, std::size_t k);
/// Unit direction of travel out of vertex k of `v` (the end heading at the last vertex).
Vec3 arc_line_out(const std::vector<Vec3>& v, const ArcLineEnds& ends, std::size_t k);

/// Unit normal in × out of a corner's plane (zero for a corner that does not turn).
Vec3 corner_normal(const Vec3& in, const Vec3& out);

/// Straight run kept between the arcs of two consecutive corners with unit normals n1, n2
/// (corner_normal; either may be zero): kInnerLegSlack·radius·min(1, |n1 − n2|), none between
/// arcs turning one way in one plane, the whole from planes 60° apart. Scene units.
double leg_slack(const Vec3& n1, const Vec3& n2, double radius);

/// Tangent length R·tan(θ/2) of a corner between unit directions `in` and `out` (scene
/// units); infinity for a reversal (θ = π).
double corner_tangent(const Vec3& in, const Vec3& out, double radius);

/// Tangent length at each vertex of `v` (size n + 1 ≥ 1; consecutive vertices distinct).
std::vector<double> arc_line_tangents(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius);

/// The first leg that cannot hold its tangents and, on an inner leg, the leg_slack between
/// its two arcs (ShortLeg::leg = −1 if the route is bend-feasible).
ShortLeg arc_line_short_leg(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius);

/// Length of the rounded route from the first vertex's tangent point to the last one's
/// (arcs included; the stubs' straight runs before and after are not). Scene units.
double arc_line_length(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius);

/// Key points of the rounded route: at each vertex, its two tangent points and arc points
/// at most `max_step` radians apart between them (0: π/12; at least four pieces), and up to
/// two points on each leg next to the arc as far apart as the arc's points; a vertex that
/// does not turn stays itself. The first and last points lie on the stubs (an arc that takes
/// all but 1e-3 radii of a stub's run starts at the stub's far end, which the caller adds:
/// its tangent point is left out). A cubic through these points and the two nodes bends up to
/// ~22% tighter than the arcs where the curvature jumps (test_arc_line).
std::vector<Vec3> arc_line_points(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius,
                                  double max_step);

/// True iff the arc rounding the corner at `vertex` (unit directions `in`, `out`, tangent
/// length from corner_tangent) keeps ≥ `required` from every part: checked as chords, each
/// capsule grown by its sagitta. The legs themselves are the caller's to check.
bool corner_arc_clear(const ObstacleIndex& index, const Vec3& vertex, const Vec3& in, const Vec3& out, double radius,
                      double required);

}  // namespace loom
