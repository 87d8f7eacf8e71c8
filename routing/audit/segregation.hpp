#pragma once
/// Segregation of cable classes (DESIGN §3, §5): two cables whose classes have a separation
/// in [routing.separation] must keep their surfaces at least that far apart (centreline
/// distance − radii), and may not share a bundle segment. World frame, scene units; s is
/// arc length from each cable's first port.

#include "routing/audit/clash_check.hpp"

#include <functional>
#include <string>
#include <vector>

namespace loom {

/// One stretch of two cables closer than their classes' separation, at its closest point,
/// or (segment ≥ 0) a bundle segment both run in.
struct SegregationFinding {
  int cable = -1;  ///< index into the checked cables (the lower of the two)
  int other = -1;  ///< index into the checked cables
  double distance = 0.0;  ///< surface distance there (centreline distance − radii; 0 in a shared segment)
  double required = 0.0;  ///< the separation of the two classes
  double s = 0.0;         ///< arc length on `cable` of the closest point (shared segment: its middle)
  double s_other = 0.0;   ///< arc length on `other`
  Vec3 point = Vec3::Zero();  ///< midway between the two closest centreline points
  int segment = -1;       ///< harness segment both run in (−1: a stretch of two separate routes)
};

/// Separation required between the classes of two checked cables (0: none).
using SeparationFn = std::function<double(int a, int b)>;

/// Checks every pair of cables with a separation: centrelines flattened into chords at most
/// min(required / 8, radius) long (exact segment–segment distances, a uniform grid as the
/// broad phase), contiguous runs of chords of `cable` closer than required grouped into one
/// finding each; and one finding per bundle segment (CableInput::segments) both share, whose
/// chords are not checked again. Sorted by cable, other, s.
std::vector<SegregationFinding> check_segregation(const std::vector<CableInput>& cables, const SeparationFn& separation);

}  // namespace loom
