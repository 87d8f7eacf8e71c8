#include "index/obstacle_index.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

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

}  // namespace

std::vector<ClosestHit> ObstacleIndex::closest_batch(const std::vector<Vec3>& points,
                                                     double max_radius, int threads) const {
  std::vector<ClosestHit> out(points.size());
  parallel_points(points.size(), threads, [&](std::size_t i) { out[i] = closest(points[i], max_radius); });
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
