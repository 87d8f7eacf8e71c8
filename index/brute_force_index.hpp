#pragma once
/// BruteForceIndex: every query loops over every triangle in double precision (no culling,
/// not even by part bounding boxes, except that inside tests skip parts whose box does
/// not contain the point). It is the
/// test oracle for the other indices and the benchmark baseline (the seed paper's brute
/// force). Inside tests use the generalized winding number of closed parts.

#include "core/part.hpp"
#include "index/obstacle_index.hpp"

#include <array>
#include <vector>

namespace loom {

/// The triangles of one part as explicit corners (world frame, double), with its bounds.
struct PartTriangles {
  std::vector<std::array<Vec3, 3>> triangles;  ///< corners of each triangle, mesh order
  AABB bounds;                                 ///< box of the corners (empty for no triangles)
  bool closed = false;                         ///< Part::closed
};

/// Copies the parts' triangles into PartTriangles (same part and triangle indices).
std::vector<PartTriangles> extract_part_triangles(const std::vector<Part>& parts);

/// Winding number of a closed triangle soup around p: ≈1 inside, ≈0 outside (outward
/// orientation); sum of signed solid angles / 4π.
double winding_number(const PartTriangles& part, const Vec3& p);

/// Distance (scene units) within which a point counts as on the surface of a part with the
/// given bounds, not inside it: the double closest-point kernel's rounding at the part's
/// scale, a few ulps of its largest coordinate (as BruteForceIndex::accuracy).
double surface_rounding(const AABB& bounds);

/// The closed parts holding p strictly (winding number > 1/2 and p farther from the surface
/// than surface_rounding: on a face the face's own solid angle is ±2π by the sign of a
/// rounded zero, so the winding number there is 0 or 1), as ascending indices into `parts`, in
/// *out (cleared first); with first_only, at most the first of them. O(all triangles of the
/// parts whose boxes contain p): the oracle's inside test, shared by the exact indices.
void parts_holding(const std::vector<PartTriangles>& parts, const Vec3& p, bool first_only, std::vector<int>& out);

/// Exact O(n) obstacle queries; see ObstacleIndex for the contract of each method.
class BruteForceIndex : public ObstacleIndex {
 public:
  /// Copies the parts' triangles (world frame).
  explicit BruteForceIndex(const std::vector<Part>& parts);

  std::string name() const override { return "brute"; }
  IndexAccuracy accuracy() const override;
  int part_count() const override { return static_cast<int>(parts_.size()); }

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

  /// Winding number of closed part `part` around p (throws std::out_of_range on a bad id).
  double part_winding_number(int part, const Vec3& p) const;

 private:
  void scan_part(int part, const Vec3& p, ClosestHit& best) const;
  /// segment_closest() over every part (only_part < 0) or one part.
  ClosestHit segment_scan(const Vec3& a, const Vec3& b, int only_part, double max_radius, double* segment_param) const;
  std::vector<PartTriangles> parts_;
};

}  // namespace loom
