#pragma once
/// Harness-aware planning obstacles: the parts plus the bundles routed so far, each bundle a
/// chain of capsules (its centre line sampled as a polyline, its radius). A segment planned
/// against this index keeps its required distance (radius + clearance) from the parts and
/// from the surface of every bundle already routed, so two segments do not clash in empty
/// space. Near a node the segment shares with a bundle the two legitimately meet: the bundle
/// is cut back there (clip_near_node) before it becomes an obstacle.
///
/// Part ids: [0, parts.part_count()) are the parts; parts.part_count() + k is bundle k.
/// Distances to a bundle are to its surface (centre-line distance − radius, never below 0).

#include "core/geometry.hpp"
#include "index/obstacle_index.hpp"

#include <string>
#include <vector>

namespace loom {

/// A routed bundle as an obstacle: its centre line as a polyline (world frame, scene units),
/// its radius, and the harness segment it belongs to.
struct BundleTube {
  int segment = -1;          ///< index into Harness::segments
  std::vector<Vec3> points;  ///< centre-line polyline (≥ 2 points to block anything)
  double radius = 0.0;       ///< bundle radius plus any margin the caller adds (≥ 0)
};

/// The pieces of `points` (a polyline) that lie outside the ball of radius `reach` around
/// `node`: each maximal run outside it as its own polyline (the cut points on the sphere
/// included). Runs shorter than `min_length` are dropped.
std::vector<std::vector<Vec3>> clip_near_node(const std::vector<Vec3>& points, const Vec3& node, double reach,
                                              double min_length = 0.0);

/// Parts plus capsule chains. Queries are exact for both (segment–segment distances for the
/// capsules); the capsules are searched through a bounding-volume hierarchy built once.
/// Rays and inside tests see the parts only: a bundle is not a closed solid and never seals
/// a cavity.
class HarnessAwareIndex : public ObstacleIndex {
 public:
  /// `parts` must outlive this index. Tubes with fewer than two points are ignored.
  HarnessAwareIndex(const ObstacleIndex& parts, const std::vector<BundleTube>& tubes);

  /// The harness segment of a part id beyond the parts (−1 for a part or a bad id).
  int bundle_segment(int part) const;
  /// Number of capsules (polyline pieces) indexed.
  std::size_t capsule_count() const { return caps_.size(); }

  std::string name() const override { return parts_.name() + "+bundles"; }
  IndexAccuracy accuracy() const override { return parts_.accuracy(); }
  int part_count() const override { return parts_.part_count() + static_cast<int>(tube_segment_.size()); }
  std::optional<AABB> part_bounds(int part) const override;
  ClosestHit closest(const Vec3& p, double max_radius) const override;
  ClosestHit closest_on_part(const Vec3& p, int part, double max_radius) const override;
  bool inside(const Vec3& p, int* part) const override { return parts_.inside(p, part); }
  void inside_parts(const Vec3& p, std::vector<int>& out) const override { parts_.inside_parts(p, out); }
  RayHit ray(const Vec3& o, const Vec3& d, double t_max) const override { return parts_.ray(o, d, t_max); }
  /// The parts' lower bound, or the exact distance to a bundle surface closer than it.
  double distance_lower_bound(const Vec3& p) const override;
  bool any_within(const Vec3& p, double r) const override;
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override;
  ClosestHit segment_closest(const Vec3& a, const Vec3& b, double max_radius, double* segment_param) const override;
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                     double* segment_param) const override;

 private:
  struct Capsule {
    Vec3 a, b;
    double radius;
    int tube;  ///< index into tube_segment_
  };
  struct Node {
    AABB box;               ///< of the capsules below, inflated by their radii
    int left = -1, right = -1;  ///< children (−1: leaf)
    int first = 0, count = 0;   ///< leaf: caps_[first, first + count)
  };
  int build(int first, int count);
  /// Nearest capsule surface to segment ab (a == b: a point) within max_radius; `only_tube`
  /// ≥ 0 restricts the search to that tube; *param (if given) receives the parameter on ab.
  ClosestHit nearest_capsule(const Vec3& a, const Vec3& b, double max_radius, int only_tube, double* param) const;

  const ObstacleIndex& parts_;
  std::vector<Capsule> caps_;
  std::vector<Node> nodes_;
  std::vector<int> tube_segment_;
};

}  // namespace loom
