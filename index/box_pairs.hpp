// Broad phase: every pair of overlapping axis-aligned boxes, through an Embree BVH, with
// an optional filter and bounds on the work.
#pragma once

#include "core/geometry.hpp"
#include "index/box_tree.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace loom {

/// Every pair {i, j}, i < j, of boxes that overlap as closed boxes (touching faces count),
/// sorted by (i, j), without duplicates. A box is never paired with itself. Boxes are in
/// any one frame (the pairs do not depend on it); the test that decides a pair is exact in
/// double precision, the BVH (Embree's rtcCollide over float boxes rounded outwards) only
/// proposes candidates. `threads` ≤ 0 uses every core. Throws std::invalid_argument for a
/// box with a non-finite or inverted corner (naming its index); an empty input gives no pairs.
std::vector<BoxPair> overlapping_box_pairs(const std::vector<AABB>& boxes, int threads);

/// What a bounded broad phase keeps and how much work it may take on.
struct BoxPairRequest {
  /// Which overlapping pairs are kept, and how many at most (BoxTree::PairFilter).
  BoxTree::PairFilter filter;
  /// Most overlapping pairs, kept or not, the enumeration may visit (Embree's rtcCollide
  /// cannot be stopped, so this is judged before it starts, from an estimate).
  std::size_t max_overlaps = std::numeric_limits<std::size_t>::max();
  int threads = 0;  ///< ≤ 0: every core
};

/// How a bounded broad phase ended (expected outcomes, not errors).
enum class BoxPairStatus {
  Done,             ///< `pairs` holds every kept pair
  TooManyOverlaps,  ///< the estimate exceeds max_overlaps: nothing enumerated
  TooManyKept,      ///< more than filter.max_pairs pairs kept (or estimated far beyond it)
};

/// The outcome of overlapping_box_pairs(boxes, request).
struct BoxPairResult {
  BoxPairStatus status = BoxPairStatus::Done;
  std::vector<BoxPair> pairs;  ///< kept pairs, as the unbounded form lists them (Done only)
  /// Estimated overlapping pairs {i, j}, i ≠ j: from at most kBoxPairSample boxes drawn with
  /// a fixed seed, each counting its overlaps up to a cap that lets the estimate reach twice
  /// max_overlaps; exact when every box is counted and none reaches the cap. 0 when
  /// max_overlaps is unbounded (no estimate is made).
  double estimated_overlaps = 0.0;
  /// Of estimated_overlaps, the pairs filter.keep would keep (same sample). Past twice
  /// filter.max_pairs the call refuses (TooManyKept) without enumerating.
  double estimated_kept = 0.0;
  std::uint32_t busiest = 0;  ///< a counted box with the most overlaps (for messages)
};

/// Boxes counted for the estimate (all of them when there are no more).
constexpr std::size_t kBoxPairSample = 1024;

/// The bounded form: estimates the overlaps first (cheap: a sample), enumerates only if
/// within `request.max_overlaps`, keeps what the filter keeps up to its max_pairs. Throws
/// std::invalid_argument for a bad box, as the unbounded form.
BoxPairResult overlapping_box_pairs(const std::vector<AABB>& boxes, const BoxPairRequest& request);

}  // namespace loom
