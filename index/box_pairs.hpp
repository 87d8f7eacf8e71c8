// Broad phase: every pair of overlapping axis-aligned boxes, through an Embree BVH.
#pragma once

#include "core/geometry.hpp"
#include "index/box_tree.hpp"

#include <vector>

namespace loom {

/// Every pair {i, j}, i < j, of boxes that overlap as closed boxes (touching faces count),
/// sorted by (i, j), without duplicates. A box is never paired with itself. Boxes are in
/// any one frame (the pairs do not depend on it); the test that decides a pair is exact in
/// double precision, the BVH (Embree's rtcCollide over float boxes rounded outwards) only
/// proposes candidates. `threads` ≤ 0 uses every core. Throws std::invalid_argument for a
/// box with a non-finite or inverted corner (naming its index); an empty input gives no pairs.
std::vector<BoxPair> overlapping_box_pairs(const std::vector<AABB>& boxes, int threads);

}  // namespace loom
