#include "index/obstacle_index.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <utility>

namespace loom {

namespace {

/// Points per TBB task: small enough to balance, large enough to amortise scheduling.
constexpr std::size_t kBatchGrain = 256;

/// Runs body(i) for i in [0, n) in a task arena of `threads` workers (≤ 0: all cores).
template <class Body>
void parallel_points(std::size_t n, int threads, const Body& body) {
  if (n == 0) return;
  const int workers = threads > 0 ? threads : tbb::task_arena::automatic;
  tbb::task_arena arena(workers);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBatchGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                      });
  });
}

/// Below this many points a batch is answered in input order (sorting would not pay).
constexpr std::size_t kCoherentMin = 4096;
/// Bits per axis of the Morton code (3 × 21 = 63 bits).
constexpr int kMortonBits = 21;

/// Spreads the low 21 bits of v so that two zero bits follow each one.
std::uint64_t spread3(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace

std::vector<std::size_t> coherent_order(const std::vector<Vec3>& points) {
  std::vector<std::size_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  if (points.size() < kCoherentMin) return order;
  AABB box;
  for (const Vec3& p : points)
    if (p.allFinite()) box.extend(p);
  if (box.empty()) return order;
  const Vec3 size = box.size();
  const double extent = std::max({size.x(), size.y(), size.z()});
  if (!(extent > 0.0)) return order;  // all points equal
  const double scale = static_cast<double>((1u << kMortonBits) - 1) / extent;
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    std::uint64_t code = 0;  // non-finite points go first, in input order
    if (p.allFinite()) {
      const Vec3 q = (p - box.min) * scale;
      code = spread3(static_cast<std::uint64_t>(q.x())) | spread3(static_cast<std::uint64_t>(q.y())) << 1 |
             spread3(static_cast<std::uint64_t>(q.z())) << 2;
    }
    keyed[i] = {code, i};
  }
  tbb::parallel_sort(keyed.begin(), keyed.end());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = keyed[i].second;
  return order;
}

std::vector<ClosestHit> ObstacleIndex::closest_batch(const std::vector<Vec3>& points,
                                                     double max_radius, int threads) const {
  // Closest-point queries are memory-bound: answered along a Morton curve, consecutive
  // queries reuse the BVH nodes and triangles already in cache.
  std::vector<ClosestHit> out(points.size());
  const std::vector<std::size_t> order = coherent_order(points);
  parallel_points(points.size(), threads, [&](std::size_t k) {
    const std::size_t i = order[k];
    out[i] = closest(points[i], max_radius);
  });
  return out;
}

std::vector<char> ObstacleIndex::inside_batch(const std::vector<Vec3>& points, int threads) const {
  std::vector<char> out(points.size(), 0);
  parallel_points(points.size(), threads, [&](std::size_t i) { out[i] = inside(points[i]) ? 1 : 0; });
  return out;
}

std::vector<char> ObstacleIndex::any_within_batch(const std::vector<Vec3>& points, double r,
                                                  int threads) const {
  std::vector<char> out(points.size(), 0);
  parallel_points(points.size(), threads,
                  [&](std::size_t i) { out[i] = any_within(points[i], r) ? 1 : 0; });
  return out;
}

}  // namespace loom
