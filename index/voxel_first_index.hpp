#pragma once
/// Voxel-first obstacle queries for planning (DESIGN §6–§7): a VoxelMap's O(1) distance
/// lookup, less its error bound, is a certified lower bound on the distance to the parts.
/// A query it decides — a point or a segment proven farther than the radius asked, a point
/// proven outside every closed part — is answered without the exact index; every other
/// query goes to the exact index unchanged. So answers are exactly the exact index's: the
/// map only saves work, it never changes a result.
///
/// Part ids and per-part queries are the exact index's. Coordinates are world frame, scene
/// units.

#include "index/obstacle_index.hpp"
#include "index/voxel_map.hpp"

#include <atomic>
#include <cstdint>
#include <string>

namespace loom {

/// How many queries the map decided and how many went to the exact index.
struct VoxelFirstCounts {
  std::uint64_t decided = 0;  ///< answered from the map's lower bound
  std::uint64_t exact = 0;    ///< passed to the exact index
};

/// The exact index behind a voxel map's lower bound. Both must outlive this object and
/// describe the same parts (the map built from them, or a superset: a lower bound of a
/// superset's distance is a lower bound of the parts' distance). Without a map every query
/// goes to the exact index and is counted (the reference for the counts).
class VoxelFirstIndex : public ObstacleIndex {
 public:
  VoxelFirstIndex(const ObstacleIndex& exact, const VoxelMap* coarse);

  /// The map's distance less its error bound (scene units; ≤ 0 near or inside a part, 0
  /// without a map); counts nothing.
  double distance_lower_bound(const Vec3& p) const override;
  /// Queries decided by the map and passed on so far (all threads).
  VoxelFirstCounts counts() const;

  std::string name() const override { return exact_.name() + "+voxel"; }
  IndexAccuracy accuracy() const override { return exact_.accuracy(); }
  int part_count() const override { return exact_.part_count(); }
  std::optional<AABB> part_bounds(int part) const override { return exact_.part_bounds(part); }
  ClosestHit closest(const Vec3& p, double max_radius) const override;
  ClosestHit closest_on_part(const Vec3& p, int part, double max_radius) const override {
    return exact_.closest_on_part(p, part, max_radius);
  }
  bool inside(const Vec3& p, int* part) const override;
  void inside_parts(const Vec3& p, std::vector<int>& out) const override { exact_.inside_parts(p, out); }
  RayHit ray(const Vec3& o, const Vec3& d, double t_max) const override { return exact_.ray(o, d, t_max); }
  bool any_within(const Vec3& p, double r) const override;
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override;
  ClosestHit segment_closest(const Vec3& a, const Vec3& b, double max_radius, double* segment_param) const override;
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                     double* segment_param) const override {
    return exact_.segment_closest_on_part(a, b, part, max_radius, segment_param);
  }

 private:
  /// True if the map proves every point of segment ab farther than r from the parts.
  bool segment_clear(const Vec3& a, const Vec3& b, double r) const;
  void count(bool decided) const;

  const ObstacleIndex& exact_;
  const VoxelMap* coarse_;  ///< null: nothing is decided
  double bound_;      ///< the map's error bound (scene units)
  double far_bound_;  ///< lower bound where the map says "beyond max_distance"
  mutable std::atomic<std::uint64_t> decided_{0};
  mutable std::atomic<std::uint64_t> exact_queries_{0};
};

}  // namespace loom
