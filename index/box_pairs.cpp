// Broad phase over boxes: a BoxTree collided with itself, on a TBB arena of the asked size.
#include "index/box_pairs.hpp"

#include <tbb/task_arena.h>

#include <stdexcept>
#include <string>

namespace loom {

std::vector<BoxPair> overlapping_box_pairs(const std::vector<AABB>& boxes, int threads) {
  // Stricter than BoxTree: a broad phase is given the boxes of real geometry, so an unset
  // box here is a caller's bug, not a part without triangles. BoxTree rejects the rest.
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (box_is_unset(boxes[i]))
      throw std::invalid_argument("overlapping_box_pairs: box " + std::to_string(i) + " is unset (no point added)");
  std::vector<BoxPair> pairs;
  // Build and traversal both run on the arena, so `threads` bounds the whole call.
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  // BoxTree validates every box, so even one or two boxes are checked.
  arena.execute([&] { pairs = BoxTree(boxes).self_pairs(); });
  return pairs;
}

}  // namespace loom
