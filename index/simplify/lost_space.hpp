#pragma once
/// The lost-space probe (the α-SIM paper's "blocked projection"): the largest ball that a
/// simplified solid fills although it lies outside the original part — space a cable could
/// use. World frame, scene units.

#include "core/geometry.hpp"

#include <cstddef>
#include <vector>

namespace loom {

class AlphaSimSolid;
class EmbreeIndex;

/// The largest lost ball found, and where.
struct LostSpace {
  double radius = 0.0;      ///< largest probed ball inside the solid and outside the original (0: none)
  Vec3 center = Vec3::Zero();  ///< its centre (meaningful when radius > 0)
  double resolution = 0.0;  ///< grid spacing of the probe
};

/// Probes a grid over `box` (spacing max(min_spacing, cbrt(volume / max_samples))) for
/// points inside the union of `solids` and outside the closed part indexed by `original`;
/// the ball at a point is min(depth in the deepest solid holding it, distance to the
/// original) — for a union, a lower bound on the ball that fits. The centre of the largest
/// is the first in grid order among equals (deterministic). Parallel (TBB); const inputs.
LostSpace probe_lost_space(const std::vector<const AlphaSimSolid*>& solids, const EmbreeIndex& original,
                           const AABB& box, double min_spacing, std::size_t max_samples);

}  // namespace loom
