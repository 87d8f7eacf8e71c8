#pragma once
/// One interface for every obstacle query loom makes (DESIGN §5–§7). Implementations:
/// EmbreeIndex (exact triangles, float BVH, re-centred), FclIndex (exact, double, used to
/// certify), VoxelMap (OctoMap + Euclidean distance map, approximate, for planning).
/// All queries are const and thread-safe; batch forms run in parallel (TBB).
/// Coordinates are world frame, scene units. Part ids index Scene::parts.

#include "core/geometry.hpp"

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace loom {

/// Result of a closest-point query.
struct ClosestHit {
  double distance = std::numeric_limits<double>::infinity();  ///< unsigned distance to the surface
  Vec3 point = Vec3::Zero();  ///< closest point on the surface
  int part = -1;              ///< part id, -1 if nothing within the search radius
  std::int64_t triangle = -1; ///< triangle index within the part's mesh (-1 for voxel answers)
  bool found() const { return part >= 0; }
};

/// Result of a ray cast.
struct RayHit {
  double t = std::numeric_limits<double>::infinity();  ///< distance along the unit direction
  int part = -1;
  std::int64_t triangle = -1;
  Vec3 normal = Vec3::Zero();  ///< geometric normal of the hit triangle (unit)
  bool found() const { return part >= 0; }
};

/// What an index guarantees about its distances.
struct IndexAccuracy {
  bool exact = false;       ///< true if distances come from exact triangle geometry
  double abs_error = 0.0;   ///< bound on |reported - true| distance, scene units
  std::string description;  ///< e.g. "Embree float BVH, re-centred: ≤ 2e-5 mm"
};

/// A permutation of [0, points.size()) visiting the points along a Morton (Z-order) curve
/// over their bounding box, so that consecutive queries touch nearby data; the identity for
/// small batches and when all points are equal. Non-finite points come first.
std::vector<std::size_t> coherent_order(const std::vector<Vec3>& points);

/// The obstacle query interface. Every method is const and safe to call concurrently.
class ObstacleIndex {
 public:
  virtual ~ObstacleIndex() = default;

  /// Name of the implementation ("embree", "fcl", "voxel", "brute").
  virtual std::string name() const = 0;
  /// Accuracy of the distances this index returns.
  virtual IndexAccuracy accuracy() const = 0;
  /// Number of parts indexed.
  virtual int part_count() const = 0;

  /// Closest point on any part within max_radius of p (found() == false if none).
  /// A tight max_radius is most of the speed: pass what you know.
  virtual ClosestHit closest(const Vec3& p,
                             double max_radius = std::numeric_limits<double>::infinity()) const = 0;
  /// (1 + rel_error)-approximate closest point: a surface point within max_radius whose
  /// distance D is at most (1 + rel_error)·d, d being the exact distance to the nearest
  /// surface — so D / (1 + rel_error) is a certified lower bound on d. found() == false
  /// only if no surface lies within max_radius (that answer is exact). Far from a finely
  /// tessellated surface this visits a few leaves instead of every triangle whose box comes
  /// within d. rel_error ≥ 0; the default implementation answers exactly.
  virtual ClosestHit closest_approx(const Vec3& p, double max_radius, double rel_error) const {
    (void)rel_error;
    return closest(p, max_radius);
  }
  /// Closest point on one given part (found() == false if farther than max_radius).
  virtual ClosestHit closest_on_part(const Vec3& p, int part,
                                     double max_radius = std::numeric_limits<double>::infinity()) const = 0;
  /// World-frame box (scene units) of the triangles of one part, when the index keeps it:
  /// saves a caller a pass over the mesh. std::nullopt when this index does not store it.
  /// Throws std::out_of_range for a bad part id in indices that store it.
  virtual std::optional<AABB> part_bounds(int part) const {
    (void)part;
    return std::nullopt;
  }
  /// A certified lower bound on the distance from p to the nearest part surface, at a cost far
  /// below closest() (≤ 0 where the index cannot tell). The default knows nothing: 0.
  virtual double distance_lower_bound(const Vec3& p) const {
    (void)p;
    return 0.0;
  }
  /// True if p is strictly inside a closed part (open parts have no inside); the part id
  /// is written to *part when given. Correct for points near edges and vertices.
  virtual bool inside(const Vec3& p, int* part = nullptr) const = 0;
  /// Every closed part holding p strictly inside, as ascending part ids in *out (cleared
  /// first; empty if none). Closed parts may overlap — a keep-out zone drawn around a box,
  /// two solids modelled through each other — and a point inside both is inside each; inside()
  /// names only one of them.
  virtual void inside_parts(const Vec3& p, std::vector<int>& out) const = 0;
  /// First hit along origin + t·dir, 0 ≤ t ≤ t_max (dir need not be unit).
  virtual RayHit ray(const Vec3& origin, const Vec3& dir,
                     double t_max = std::numeric_limits<double>::infinity()) const = 0;
  /// True if any part surface comes within r of the point (early exit).
  virtual bool any_within(const Vec3& p, double r) const = 0;
  /// True if any part surface comes within r of the segment ab, i.e. the capsule of radius
  /// r around ab touches a part (early exit). r = 0 tests the segment itself.
  virtual bool segment_within(const Vec3& a, const Vec3& b, double r) const = 0;
  /// Distance from segment ab to the nearest part surface, with the closest points.
  /// `point` is on the surface; `*segment_param` (if given) is the parameter in [0,1] on ab.
  virtual ClosestHit segment_closest(const Vec3& a, const Vec3& b,
                                     double max_radius = std::numeric_limits<double>::infinity(),
                                     double* segment_param = nullptr) const = 0;

  /// (1 + rel_error)-approximate segment_closest(): a surface point within max_radius of ab
  /// whose distance D from ab is at most (1 + rel_error)·d, d being the exact distance from
  /// ab to the nearest surface; found() == false only if none lies within max_radius.
  /// The default implementation answers exactly.
  virtual ClosestHit segment_closest_approx(const Vec3& a, const Vec3& b, double max_radius, double rel_error,
                                            double* segment_param = nullptr) const {
    (void)rel_error;
    return segment_closest(a, b, max_radius, segment_param);
  }
  /// segment_closest() against one given part only (found() == false if farther than
  /// max_radius). Throws std::out_of_range for a bad part id.
  virtual ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                             double* segment_param = nullptr) const = 0;
  /// Batch closest(): out[i] for points[i]; parallel over points (TBB), `threads` ≤ 0 = all.
  virtual std::vector<ClosestHit> closest_batch(const std::vector<Vec3>& points, double max_radius,
                                                int threads = 0) const;
  /// Batch inside().
  virtual std::vector<char> inside_batch(const std::vector<Vec3>& points, int threads = 0) const;
  /// Batch any_within().
  virtual std::vector<char> any_within_batch(const std::vector<Vec3>& points, double r,
                                             int threads = 0) const;
};

}  // namespace loom
