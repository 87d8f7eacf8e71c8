#include "index/simplify/lost_space.hpp"

#include "index/embree_index.hpp"
#include "index/simplify/alpha_sim.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace loom {

namespace {

/// A candidate ball: its radius and the grid index of its centre.
struct Ball {
  double radius = 0.0;
  std::size_t index = 0;
};

/// The larger ball; the earlier grid point among equals, so that the result does not
/// depend on how TBB splits the range.
Ball larger(const Ball& a, const Ball& b) {
  if (a.radius != b.radius) return a.radius > b.radius ? a : b;
  return a.index <= b.index ? a : b;
}

}  // namespace

LostSpace probe_lost_space(const std::vector<const AlphaSimSolid*>& solids, const EmbreeIndex& original,
                           const AABB& box, double min_spacing, std::size_t max_samples) {
  LostSpace out;
  if (box.empty()) return out;
  const Vec3 ext = box.size();
  const double vol = std::max(ext.x(), 1e-12) * std::max(ext.y(), 1e-12) * std::max(ext.z(), 1e-12);
  const double h = std::max(min_spacing, std::cbrt(vol / static_cast<double>(std::max<std::size_t>(max_samples, 1))));
  out.resolution = h;
  const int nx = std::max(1, static_cast<int>(std::floor(ext.x() / h))),
            ny = std::max(1, static_cast<int>(std::floor(ext.y() / h))),
            nz = std::max(1, static_cast<int>(std::floor(ext.z() / h)));
  const std::size_t total = static_cast<std::size_t>(nx) * ny * nz;
  auto point = [&](std::size_t i) {
    const std::size_t ix = i % nx, iy = (i / nx) % ny, iz = i / (static_cast<std::size_t>(nx) * ny);
    return Vec3(box.min + Vec3((ix + 0.5) * ext.x() / nx, (iy + 0.5) * ext.y() / ny, (iz + 0.5) * ext.z() / nz));
  };
  // A ball equal to the best so far still counts when its index is smaller: the chunks
  // TBB hands a body do not come in grid order.
  const Ball best = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, total, 256), Ball{},
      [&](const tbb::blocked_range<std::size_t>& rg, Ball acc) {
        for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
          const Vec3 p = point(i);
          // Outside every solid (or on one) the depth is ≤ 0 ≤ acc: skip the distances.
          if (std::none_of(solids.begin(), solids.end(), [&](const AlphaSimSolid* s) { return s->contains(p); }))
            continue;
          // Inside the original's material no free space is hidden. Why first: most points
          // inside a solid are in material, and the parity test costs less than the depth
          // (a search of the prisms' boundaries out to the point's distance from them).
          if (original.inside(p)) continue;
          double depth = 0.0;
          for (const AlphaSimSolid* s : solids)
            if (s->contains(p)) depth = std::max(depth, -s->distance_bound(p));  // exact inside one solid
          if (depth <= 0.0 || depth < acc.radius) continue;
          const Ball ball{std::min(depth, original.closest(p).distance), i};
          if (larger(acc, ball).index == i) acc = ball;
        }
        return acc;
      },
      larger);
  out.radius = best.radius;
  if (best.radius > 0.0) out.center = point(best.index);
  return out;
}

}  // namespace loom
