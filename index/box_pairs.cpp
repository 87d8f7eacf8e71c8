// Broad phase over boxes: a BoxTree collided with itself, on a TBB arena of the asked size,
// its work estimated from a sample of boxes before Embree enumerates the pairs.
#include "index/box_pairs.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

namespace loom {
namespace {

/// Seed of the estimate's draw (the estimate, and so a refusal, is reproducible).
constexpr std::uint64_t kSampleSeed = 0x6c6f6f6d;  // "loom"
/// Smallest cap on one drawn box's counted overlaps (the cap is 4 · max_overlaps / boxes,
/// at least this): a chord block in a large bundle meets a few blocks of every cable in it.
constexpr std::size_t kMinCountCap = 1000;
/// Refuse without enumerating when the estimated kept pairs exceed filter.max_pairs by
/// this factor (BoxPairResult::estimated_kept).
constexpr double kKeptEstimateMargin = 2.0;

/// Fills result.estimated_overlaps, estimated_kept and busiest (see BoxPairResult). Why a sample:
/// counting every box's overlaps costs what enumerating them does.
void estimate_overlaps(const BoxTree& tree, const std::vector<AABB>& boxes, std::size_t budget,
                       const BoxTree::PairFilter& filter, BoxPairResult& result) {
  const std::size_t n = boxes.size();
  if (n < 2) return;
  std::vector<std::size_t> drawn(std::min(n, kBoxPairSample));
  if (drawn.size() == n) {
    std::iota(drawn.begin(), drawn.end(), std::size_t{0});
  } else {
    std::mt19937_64 rng(kSampleSeed);
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    for (std::size_t& k : drawn) k = pick(rng);
  }
  // No box overlaps more than n boxes, so a cap of n counts exactly (and cannot overflow).
  const std::size_t per_box = budget / n + 1;
  const std::size_t cap = std::max(kMinCountCap, per_box > n / 4 ? n : 4 * per_box);
  std::vector<std::size_t> count(drawn.size()), kept(drawn.size());
  tbb::parallel_for(std::size_t{0}, drawn.size(), [&](std::size_t k) {
    const auto i = static_cast<std::uint32_t>(drawn[k]);
    // The filter sees each pair as self_pairs hands it over: lower index first.
    const std::function<bool(std::uint32_t)> keep = [&](std::uint32_t j) {
      return j != i && (!filter.keep || filter.keep(std::min(i, j), std::max(i, j)));
    };
    const BoxTree::OverlapCount c = tree.count_overlapping(boxes[i], cap, keep);
    count[k] = c.all;
    kept[k] = c.kept;
  });
  double sum = 0.0, sum_kept = 0.0;
  std::size_t busiest = 0;
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    sum += static_cast<double>(count[k] > 0 ? count[k] - 1 : 0);  // a box overlaps itself
    sum_kept += static_cast<double>(kept[k]);
    if (count[k] > count[busiest]) busiest = k;
  }
  result.busiest = static_cast<std::uint32_t>(drawn[busiest]);
  // Each pair is counted from both its boxes.
  const double scale = 0.5 * static_cast<double>(n) / static_cast<double>(drawn.size());
  result.estimated_overlaps = sum * scale;
  result.estimated_kept = sum_kept * scale;
}

}  // namespace

BoxPairResult overlapping_box_pairs(const std::vector<AABB>& boxes, const BoxPairRequest& request) {
  // Stricter than BoxTree: a broad phase is given the boxes of real geometry, so an unset
  // box here is a caller's bug, not a part without triangles. BoxTree rejects the rest.
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (box_is_unset(boxes[i]))
      throw std::invalid_argument("overlapping_box_pairs: box " + std::to_string(i) + " is unset (no point added)");
  BoxPairResult result;
  // Build, estimate and traversal all run on the arena, so `threads` bounds the whole call.
  tbb::task_arena arena(request.threads > 0 ? request.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    const BoxTree tree(boxes);  // validates every box, so even one or two boxes are checked
    const bool bounded = request.max_overlaps != std::numeric_limits<std::size_t>::max();
    if (bounded) estimate_overlaps(tree, boxes, request.max_overlaps, request.filter, result);
    if (bounded && result.estimated_overlaps > static_cast<double>(request.max_overlaps)) {
      result.status = BoxPairStatus::TooManyOverlaps;
      return;
    }
    // Why a margin: near the limit the estimate may err either way, and the enumeration
    // decides exactly; far beyond it the enumeration would only confirm the refusal.
    if (bounded && result.estimated_kept > kKeptEstimateMargin * static_cast<double>(request.filter.max_pairs)) {
      result.status = BoxPairStatus::TooManyKept;
      return;
    }
    try {
      result.pairs = tree.self_pairs(request.filter);
    } catch (const std::length_error&) {
      result.status = BoxPairStatus::TooManyKept;
    }
  });
  return result;
}

std::vector<BoxPair> overlapping_box_pairs(const std::vector<AABB>& boxes, int threads) {
  BoxPairRequest request;
  request.threads = threads;
  return overlapping_box_pairs(boxes, request).pairs;
}

}  // namespace loom
