#include "index/voxel_first_index.hpp"

#include <algorithm>
#include <cmath>

namespace loom {

namespace {
/// Most map lookups one segment test makes before it hands the segment to the exact index:
/// a segment that runs close to a part would otherwise be traced in half-voxel steps.
constexpr int kMaxTraceSteps = 64;
}  // namespace

VoxelFirstIndex::VoxelFirstIndex(const ObstacleIndex& exact, const VoxelMap* coarse)
    : exact_(exact), coarse_(coarse), bound_(coarse ? coarse->accuracy().abs_error : 0.0) {
  // A cell marked "beyond max_distance" has its centre farther than max_distance; the
  // point is within the error bound of its centre's value.
  far_bound_ = coarse ? coarse->max_distance() - bound_ : 0.0;
}

double VoxelFirstIndex::distance_lower_bound(const Vec3& p) const {
  if (!coarse_) return 0.0;
  const double d = coarse_->distance(p);
  return std::isfinite(d) ? d - bound_ : far_bound_;
}

VoxelFirstCounts VoxelFirstIndex::counts() const {
  return {decided_.load(std::memory_order_relaxed), exact_queries_.load(std::memory_order_relaxed)};
}

void VoxelFirstIndex::count(bool decided) const {
  (decided ? decided_ : exact_queries_).fetch_add(1, std::memory_order_relaxed);
}

bool VoxelFirstIndex::segment_clear(const Vec3& a, const Vec3& b, double r) const {
  // Sphere tracing on the lower bound L (1-Lipschitz less a constant): every point within
  // L(x) − r of x is farther than r, so a step of that length skips nothing.
  const double len = (b - a).norm();
  const Vec3 u = len > 0.0 ? Vec3((b - a) / len) : Vec3::Zero();
  double t = 0.0;
  for (int step = 0; step < kMaxTraceSteps; ++step) {
    const double gap = distance_lower_bound(a + t * u) - r;
    if (!(gap > 0.0)) return false;
    if (t >= len) return true;
    t = std::min(len, t + gap);
  }
  return false;
}

ClosestHit VoxelFirstIndex::closest(const Vec3& p, double max_radius) const {
  const bool decided = distance_lower_bound(p) > max_radius;
  count(decided);
  return decided ? ClosestHit{} : exact_.closest(p, max_radius);
}

bool VoxelFirstIndex::inside(const Vec3& p, int* part) const {
  // A point farther than 0 from every surface lies on the side of its voxel centre, and a
  // centre inside a closed part reads 0: so a positive bound proves the point outside.
  const bool decided = distance_lower_bound(p) > 0.0;
  count(decided);
  return decided ? false : exact_.inside(p, part);
}

bool VoxelFirstIndex::any_within(const Vec3& p, double r) const {
  const bool decided = distance_lower_bound(p) > r;
  count(decided);
  return decided ? false : exact_.any_within(p, r);
}

bool VoxelFirstIndex::segment_within(const Vec3& a, const Vec3& b, double r) const {
  const bool decided = segment_clear(a, b, r);
  count(decided);
  return decided ? false : exact_.segment_within(a, b, r);
}

ClosestHit VoxelFirstIndex::segment_closest(const Vec3& a, const Vec3& b, double max_radius,
                                            double* segment_param) const {
  const bool decided = segment_clear(a, b, max_radius);
  count(decided);
  return decided ? ClosestHit{} : exact_.segment_closest(a, b, max_radius, segment_param);
}

}  // namespace loom
