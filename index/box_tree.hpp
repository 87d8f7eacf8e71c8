// A static BVH over axis-aligned boxes (Embree user geometry): which boxes overlap a query
// box, and every overlapping pair. The assembly-level index of a scene's part boxes.
#pragma once

#include "core/geometry.hpp"

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

namespace loom {

/// One unordered pair of box indices, first < second.
using BoxPair = std::pair<std::uint32_t, std::uint32_t>;

/// True if the closed boxes a and b share a point (touching faces count); false if either
/// is empty.
inline bool boxes_overlap(const AABB& a, const AABB& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

/// True for a box nothing was added to (AABB's default: min +inf, max −inf everywhere).
inline bool box_is_unset(const AABB& b) {
  return (b.min.array() == std::numeric_limits<double>::infinity()).all() &&
         (b.max.array() == -std::numeric_limits<double>::infinity()).all();
}

/// Embree BVH over a fixed list of boxes (any one frame and unit). The BVH holds float
/// boxes, re-centred on the set's centre and rounded outwards, and only proposes
/// candidates; every answer is decided by the exact double overlap test, so results are
/// exact. Immutable after construction; queries are const and thread-safe.
class BoxTree {
 public:
  /// Builds the BVH. An unset box (box_is_unset: a default AABB) is kept as an index but
  /// overlaps nothing. Throws std::invalid_argument naming the index of a box with a NaN
  /// corner or an inverted, non-empty extent, and for more boxes than 32-bit ids.
  explicit BoxTree(std::vector<AABB> boxes);
  ~BoxTree();
  BoxTree(const BoxTree&) = delete;
  BoxTree& operator=(const BoxTree&) = delete;
  BoxTree(BoxTree&&) noexcept;
  BoxTree& operator=(BoxTree&&) noexcept;

  /// Number of boxes (unset ones included).
  std::size_t size() const;

  /// Clears `out`, then fills it with the indices of the boxes that overlap the closed box
  /// `query` (boxes_overlap), ascending. An empty query overlaps nothing. Throws
  /// std::invalid_argument if the query is not finite.
  void overlapping(const AABB& query, std::vector<std::uint32_t>& out) const;

  /// The number of boxes that overlap the closed box `query` (as overlapping() would list
  /// them), or `cap` if there are at least that many: the traversal stops there. Throws
  /// std::invalid_argument if the query is not finite.
  std::size_t count_overlapping(const AABB& query, std::size_t cap) const;

  /// Boxes counted by count_overlapping(query, cap), and how many of them `keep` accepts
  /// (called with each counted box's index, from the calling thread).
  struct OverlapCount {
    std::size_t all = 0;   ///< as count_overlapping(query, cap)
    std::size_t kept = 0;  ///< of those, the ones `keep` accepts
  };
  /// As count_overlapping(query, cap), also counting the boxes `keep` accepts; the traversal
  /// stops when `all` reaches cap. An empty `keep` accepts every box.
  OverlapCount count_overlapping(const AABB& query, std::size_t cap,
                                 const std::function<bool(std::uint32_t)>& keep) const;

  /// Every pair {i, j}, i < j, of overlapping boxes, sorted, without duplicates (Embree's
  /// rtcCollide of the tree with itself). Runs on the calling thread's TBB arena.
  std::vector<BoxPair> self_pairs() const;

  /// Which overlapping pairs self_pairs keeps, and how many at most.
  struct PairFilter {
    /// Called (from any thread) for each overlapping pair i < j; false drops it. Empty: keep all.
    std::function<bool(std::uint32_t, std::uint32_t)> keep;
    /// Most pairs kept; beyond it self_pairs stops storing and throws std::length_error.
    std::size_t max_pairs = std::numeric_limits<std::size_t>::max();
  };
  /// As self_pairs(), keeping the pairs `filter` keeps (memory follows the kept pairs).
  std::vector<BoxPair> self_pairs(const PairFilter& filter) const;

  /// The boxes, their float copies and the Embree scene (public for the callbacks in the
  /// .cpp; not part of the API). Held by pointer so that its address, which Embree keeps,
  /// survives moves of the tree.
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace loom
