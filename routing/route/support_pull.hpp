#pragma once
/// Pulls a planned route towards structure where it runs too far from it to be clamped
/// (DESIGN §5 supports; FORMATS `clamp_spacing`, `clamp_reach`).
///
/// A sampling planner leaves routes in the middle of free space; a harness is clamped to
/// structure at most `spacing` apart. This pass walks the key-point polyline, finds the
/// stretches longer than `spacing` with no point firmly within reach of a supporting part
/// (an unsupported span, as the audit counts them; "firmly": within (target + reach) / 2,
/// because the spline through the key points strays from them), and inserts a key point
/// there: at the point of the span nearest to structure, moved straight towards its closest
/// structure point until it is `target` from it. The move is along the closest-point
/// direction, so the new point stays outside the part; both new segments are checked as
/// capsules of radius `required` against every part, and a move that would break clearance
/// is tried shorter (¾, ½, ¼) and dropped unless it still ends firmly within reach.
/// Deterministic; it never removes a point, so a clear polyline stays clear.
///
/// Ends: a port end holds the cable (a connector is a support); a branch-point end does not,
/// so the first and last supports must lie within spacing / 2 of it — two segments meeting
/// at a node then leave at most `spacing` unsupported across it.

#include "core/geometry.hpp"
#include "index/obstacle_index.hpp"

#include <vector>

namespace loom {

/// What the pull aims at. Distances are centre-line distances to part surfaces, scene units.
struct SupportPullSettings {
  double spacing = 0.0;   ///< longest unsupported stretch allowed (> 0)
  double reach = 0.0;     ///< a clamp holds the centre line this far from a supporting part (> required)
  double required = 0.0;  ///< least centre-line distance to every part (bundle radius + clearance)
  /// Distance from structure a pulled point is placed at; ≤ 0: midway between required and
  /// reach, so the spline through it may stray by half the band either way.
  double target = 0.0;
  bool start_is_port = true;  ///< the first point's end holds the cable
  bool end_is_port = true;    ///< the last point's end holds the cable
  int max_insertions = 64;    ///< at most this many key points are inserted
  /// By part id: the part can carry a clamp (structure; keep-outs cannot). Empty = all.
  std::vector<bool> part_supports;
};

/// Outcome of one pull.
struct SupportPullResult {
  std::vector<Vec3> points;        ///< the polyline with the inserted key points (world frame)
  int inserted = 0;                ///< key points inserted
  int unfixed_spans = 0;           ///< unsupported spans left (no clear move reaches structure)
  double longest_span_before = 0;  ///< longest unsupported stretch of the input, scene units
  double longest_span_after = 0;   ///< of the output
};

/// Pulls `points` (a clear key-point polyline, world frame) towards the supporting parts of
/// `index` as described above. Throws std::invalid_argument for non-positive spacing or a
/// reach not beyond required.
SupportPullResult pull_to_structure(const ObstacleIndex& index, const std::vector<Vec3>& points,
                                    const SupportPullSettings& settings);

}  // namespace loom
