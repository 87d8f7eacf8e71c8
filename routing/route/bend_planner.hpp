#pragma once
/// Bend-feasible planning: a route between two stub ends whose headings are fixed, every
/// corner of which can be rounded by an arc of the bend radius that stays clear
/// (routing/route/arc_line.hpp). The bend radius is a constraint of the plan, not a repair
/// after it.
///
/// Two trees grow from the stub ends (a bidirectional RRT; OMPL's GNAT finds neighbours,
/// OMPL's RNG draws samples). A node is a position, the heading it is reached with and the
/// straight run before it that its corner may still use; a step towards a sample leaves from
/// the near node that lacks the least turn to reach it, turns at most as much as its run and
/// the step allow (steered towards the heading otherwise), and is kept only if the step and
/// the arc at its corner are clear. A new node joins the other tree where the segment between
/// them, the arcs at both ends and the tangents on the segment fit. Consecutive arcs keep
/// leg_slack of straight between them. A corridor known to be clear (`hint`, e.g. the plan
/// of an unconstrained planner) draws half the samples around it. Each route found is
/// shortened while it stays bend-feasible and clear (shortcuts between random pairs of
/// points along it, corners pulled towards their neighbours, then every vertex left out);
/// the trees grow on after the first for as many samples again (at least 2,000, within the
/// budget), and the shortest of up to 16 routes is kept.
///
/// Reproducible: samples and shortcuts draw from an RNG seeded by BendPlanRequest::seed, so a
/// run that ends on its sample budget is the same in any process (BendPlanResult::
/// time_limited says when the clock ended it).

#include "core/geometry.hpp"
#include "index/obstacle_index.hpp"
#include "routing/route/arc_line.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace loom {

/// Points closer than this × the required distance are one point (the two ends of a query
/// must be farther apart).
inline constexpr double kBendPlanSamePoint = 1e-6;

/// One bend-feasible planning query.
struct BendPlanRequest {
  Vec3 start = Vec3::Zero();  ///< first stub end (world frame)
  Vec3 goal = Vec3::Zero();   ///< second stub end
  /// Heading and straight run at each end: start_heading is the first stub's direction
  /// (towards `start`), end_heading the direction from `goal` along the second stub.
  ArcLineEnds ends;
  double required = 0.0;     ///< centre-line distance kept from every surface (radius + clearance, > 0)
  double bend_radius = 0.0;  ///< radius of every rounding arc (> 0; the cable's minimum with its margin)
  AABB bounds;               ///< planning bounds (every vertex lies inside)
  std::vector<Vec3> hint;    ///< a clear polyline from start to goal to sample around (may be empty)
  double hint_width = 0.0;   ///< radius of the samples around the hint; 0: 2·bend_radius + required
  std::uint32_t seed = 1;    ///< seed of every random draw
  std::uint64_t max_iterations = 20000;  ///< samples drawn at most (both trees together)
  double time_limit = 5.0;   ///< seconds (wall clock; the iteration budget is tested first)
  int shortcut_rounds = 1000;  ///< random shortcut attempts after a solution
};

/// Outcome of a bend-feasible plan.
enum class BendPlanStatus { Solved, NoPath };

/// A bend-feasible route, or why none was found.
struct BendPlanResult {
  BendPlanStatus status = BendPlanStatus::NoPath;
  std::vector<Vec3> vertices;    ///< corners from start to goal (the stub ends included)
  std::vector<Vec3> key_points;  ///< arc_line_points of the vertices (tangent and arc points)
  double length = 0.0;           ///< arc_line_length of the vertices (scene units)
  std::uint64_t iterations = 0;  ///< samples drawn
  std::uint64_t shortcuts = 0;   ///< shortcuts kept (over every route compared)
  /// The wall clock ended the search before its sample budget (or, after a first route, its
  /// extra samples) did: another run may return another route.
  bool time_limited = false;
  double time_ms = 0.0;          ///< wall time of the query
  /// When NoPath: where the hint's corners need more straight run than their legs hold
  /// (ShortLeg::leg −1 if the hint is bend-feasible or absent), and a message with it.
  ShortLeg tightest;
  std::string message;
  bool solved() const { return status == BendPlanStatus::Solved; }
};

/// Plans a bend-feasible route among the parts of `index`. Throws std::invalid_argument
/// for non-positive or non-finite required distance or bend radius, or ends closer than
/// kBendPlanSamePoint × required.
BendPlanResult plan_bend_feasible(const ObstacleIndex& index, const BendPlanRequest& request);

/// True iff the polyline `v` (stub end to stub end) is bend-feasible under `ends` at
/// `bend_radius` (leg_slack kept between arcs) and every rounding arc keeps `required` from the parts of `index` (the
/// legs themselves are not checked: the caller's planner verified them).
bool arcs_fit(const ObstacleIndex& index, const std::vector<Vec3>& v, const ArcLineEnds& ends, double bend_radius,
              double required);

}  // namespace loom
