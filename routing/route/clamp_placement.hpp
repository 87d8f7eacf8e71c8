#pragma once
/// Clamp placement after routing (DESIGN §3 Supports): along each routed segment, clamps at
/// most `clamp_spacing` apart at centreline points whose bundle is within `clamp_reach` of
/// a structure part. World frame, scene units.

#include "core/harness.hpp"
#include "core/part.hpp"
#include "index/obstacle_index.hpp"

#include <vector>

namespace loom {

/// What place_clamps did.
struct ClampPlacement {
  std::vector<Clamp> clamps;        ///< the clamps placed (placed = true), by segment
  double cable_length = 0.0;        ///< centreline length of the routed segments carrying cables
  double length_within_reach = 0.0;  ///< of it, the length whose bundle is within reach of structure
  /// length_within_reach / cable_length (1 when there is no cable length).
  double share_within_reach() const { return cable_length > 0.0 ? length_within_reach / cable_length : 1.0; }
};

/// Places clamps greedily along each routed segment that carries cables: from a port (which
/// holds the cable) or from spacing / 2 before a branch point (so that a cable passing it
/// is held within the spacing across it), the farthest point within reach no more than the
/// spacing on, else the nearest one beyond (the audit then reports the longer span); where
/// no point ahead is within reach it stops. Points are taken every min(spacing / 20, reach)
/// along the curve. Ids "clamp-N" avoid the harness's own; each records its part and bundle
/// diameter.
ClampPlacement place_clamps(const Harness& h, const std::vector<Part>& parts, const ObstacleIndex& index,
                            double clamp_spacing, double clamp_reach);

}  // namespace loom
