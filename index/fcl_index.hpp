#pragma once
/// FclIndex: exact distances from FCL 0.7 (fcl::BVHModel<fcl::OBBRSSd> per part, double
/// precision), used to certify audits and to cross-check EmbreeIndex. Points and segments
/// are queried as a one-triangle BVHModel of the same BV type (FCL 0.7 computes mesh–mesh
/// distance only between equal BV types) whose triangle is degenerate (a, b, b); its leaf
/// BV is refitted from the two points because FCL's 3-point OBB fit normalises a zero
/// cross product. Mesh–mesh distance then runs FCL's exact triangle–triangle distance, no
/// GJK/libccd. Pitfalls handled (see tests/index/test_fcl_index.cpp):
///  - zero-area triangles in a part would get a corrupt leaf BV: they are kept out of the
///    FCL model and checked directly with the exact kernels;
///  - FCL's triangle distance skips its face tests when |normal|² ≤ 1e-15 (absolute), so
///    triangles with edges below ~1e-4 scene units are checked with the exact kernels too.
/// Inside tests: generalized winding number of closed parts (exact, O(n)). Ray casts:
/// FCL collision of the ray segment with the model for candidates, double intersection.

#include "core/part.hpp"
#include "index/obstacle_index.hpp"

#include <memory>
#include <vector>

namespace loom {

/// Exact, double precision obstacle queries through FCL; see ObstacleIndex for the contract.
class FclIndex : public ObstacleIndex {
 public:
  /// Builds one OBBRSS BVH per part (meshes in world frame). Throws InputError for a
  /// triangle indexing a missing vertex or a non-finite vertex.
  explicit FclIndex(const std::vector<Part>& parts);
  ~FclIndex() override;
  FclIndex(const FclIndex&) = delete;
  FclIndex& operator=(const FclIndex&) = delete;

  std::string name() const override { return "fcl"; }
  IndexAccuracy accuracy() const override;
  int part_count() const override;

  ClosestHit closest(const Vec3& p, double max_radius = std::numeric_limits<double>::infinity()) const override;
  ClosestHit closest_on_part(const Vec3& p, int part,
                             double max_radius = std::numeric_limits<double>::infinity()) const override;
  bool inside(const Vec3& p, int* part = nullptr) const override;
  void inside_parts(const Vec3& p, std::vector<int>& out) const override;
  RayHit ray(const Vec3& origin, const Vec3& dir,
             double t_max = std::numeric_limits<double>::infinity()) const override;
  bool any_within(const Vec3& p, double r) const override;
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override;
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                     double* segment_param = nullptr) const override;
  ClosestHit segment_closest(const Vec3& a, const Vec3& b,
                             double max_radius = std::numeric_limits<double>::infinity(),
                             double* segment_param = nullptr) const override;

  /// Capsule (segment ab, radius r) against one part: signed gap = distance − r
  /// (negative when the capsule penetrates the surface), with the closest points.
  ClosestHit capsule_on_part(const Vec3& a, const Vec3& b, double r, int part,
                             double* segment_param = nullptr) const;

  /// Triangles answered by the exact kernels instead of FCL (degenerate or tiny), all parts.
  std::size_t direct_triangle_count() const;

  struct Impl;

 private:
  /// Distance from segment ab (a == b: a point) to one part; found() false if empty.
  ClosestHit part_distance(const Vec3& a, const Vec3& b, int part, double* s) const;
  std::unique_ptr<Impl> impl_;
};

}  // namespace loom
