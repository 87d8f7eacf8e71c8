#pragma once
/// Byte offsets of a text to 1-based line numbers, for messages of the readers.

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace loom {

/// Maps byte offsets of a text (pugixml's offset_debug(), a scanner's position) to 1-based
/// line numbers in O(log lines); built in one pass.
class LineMap {
 public:
  /// Indexes the newlines of `text`.
  explicit LineMap(const std::string& text) {
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') newlines_.push_back(static_cast<std::ptrdiff_t>(i));
  }
  /// Number of lines of the text.
  std::size_t count() const { return newlines_.size() + 1; }
  /// The line holding byte `offset`; 0 for a negative offset (unknown).
  int line(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    return static_cast<int>(std::lower_bound(newlines_.begin(), newlines_.end(), offset) - newlines_.begin()) + 1;
  }

 private:
  std::vector<std::ptrdiff_t> newlines_;
};

}  // namespace loom
