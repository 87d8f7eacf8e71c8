#pragma once
/// Bend-radius repair of an interpolated cable centerline: fair within a growing deviation
/// budget, then round the offending corners with inserted key points, until every point of
/// the curve has 1/κ ≥ min_bend_radius — or report where and why it cannot (DESIGN §5:
/// "Bend: curvature radius 1/κ(s) < min_bend_radius"). Lengths in scene units.

#include "core/centerline.hpp"

#include <string>
#include <vector>

namespace loom {

/// How a bend repair ended.
enum class BendRepairStatus {
  AlreadySatisfied,  ///< the interpolant already bends gently enough
  Faired,            ///< energy fairing within max_deviation was enough
  PointsInserted,    ///< corners were rounded with inserted key points (then faired)
  Failed,            ///< not possible within max_deviation / max_iterations (see `worst`, `reason`)
};

/// Limits of a bend repair.
struct BendRepairOptions {
  double min_bend_radius = 0.0;  ///< required smallest 1/κ, scene units (> 0)
  double max_deviation = 0.0;    ///< largest allowed move of any key point (or of the path at a corner), scene units (> 0)
  int max_iterations = 8;        ///< rounds of corner rounding
  /// Fairing budgets tried in order are max_deviation·2^(k − fairing_steps + 1), k = 0..fairing_steps−1:
  /// the smallest budget that satisfies the radius wins (least change to the route).
  int fairing_steps = 4;
  InterpolationOptions interpolation;  ///< knots and end tangents of the curve
};

/// What a bend repair produced.
struct BendRepairResult {
  Centerline curve;                ///< the repaired curve (or the best attempt on failure)
  BendRepairStatus status = BendRepairStatus::Failed;
  BendExtremum worst;              ///< the curve's smallest bend radius and where (final curve)
  double deviation_used = 0.0;     ///< the fairing budget ε that was used (0 if none)
  int points_inserted = 0;         ///< key points added by corner rounding
  int iterations = 0;              ///< rounds of corner rounding
  std::vector<Vec3> points;        ///< the key points of `curve`
  std::string reason;              ///< empty unless Failed: what stopped the repair
};

/// Repairs the bend radius of the interpolating cubic through `points`. Throws
/// std::invalid_argument on bad input (as Centerline::interpolate, or a limit ≤ 0).
BendRepairResult repair_bend_radius(const std::vector<Vec3>& points, const BendRepairOptions& opt);

}  // namespace loom
