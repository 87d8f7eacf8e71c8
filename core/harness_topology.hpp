#pragma once
/// What the patent derives from the four sets: each cable's chain of segments, the
/// bundles (segments carrying more than one cable) with their diameters, and the
/// routing order (bundles by cable count, largest first, then single-cable segments).

#include "core/harness.hpp"

#include <map>
#include <string>
#include <unordered_map>
#include <vector>

namespace loom {

/// A segment traversed by a cable, with the direction of travel.
struct SegmentUse {
  int segment = -1;       ///< index into Harness::segments
  bool reversed = false;  ///< true if the cable runs to → from
};

/// Derived, validated view of a Harness. Construction throws InputError for every
/// structural fault: unknown node ids, cycles, disconnected cables, duplicate segments, a
/// given segment diameter below that of a cable the segment carries. Nodes may join any
/// number of segments (notes() names the branch points that break the patent's 3-way rule).
class HarnessTopology {
 public:
  /// Validates `h` (which must outlive this object) and derives chains and bundles.
  explicit HarnessTopology(const Harness& h);

  /// The harness this topology describes.
  const Harness& harness() const { return *h_; }
  /// Segments on the tree path from the cable's first port to its second, in order.
  const std::vector<SegmentUse>& cable_chain(int cable) const { return chains_[cable]; }
  /// Cables (indices) carried by a segment, in cable order.
  const std::vector<int>& segment_cables(int segment) const { return carried_[segment]; }
  /// True if the segment carries more than one cable (a bundle, per the patent).
  bool is_bundle(int segment) const { return carried_[segment].size() > 1; }
  /// Diameter of the segment: the file's value if given, else 1.2·√(Σ dᵢ²) for bundles,
  /// else the single cable's diameter (0 for a segment that carries nothing).
  double segment_diameter(int segment) const { return diameter_[segment]; }
  /// Indices of bundle segments.
  std::vector<int> bundles() const;
  /// The patent's routing order over segments that carry cables: bundles by cable count,
  /// largest first (ties: file order), then single-cable segments in file order.
  const std::vector<int>& routing_order() const { return order_; }
  /// Segment indices incident to a node id (port or branch point), ascending; empty for an
  /// unknown id. Its size is the node's degree.
  const std::vector<int>& incident_segments(const std::string& node) const;
  /// One line per branch point that does not join exactly 3 nodes (the patent's rule): a
  /// pass-through point (2), a dead end (0 or 1), or an N-way node; "file:line branch ..." .
  std::vector<std::string> notes() const;
  /// Number of nodes (ports and branch points) by degree (segments joined).
  std::map<int, int> nodes_by_degree() const;

 private:
  const Harness* h_;
  std::vector<std::vector<SegmentUse>> chains_;
  std::vector<std::vector<int>> carried_;
  std::vector<double> diameter_;
  std::vector<int> order_;
  std::unordered_map<std::string, std::vector<int>> incident_;
};

/// Bundle diameter rule of DESIGN §3: D = 1.2·√(Σ dᵢ²).
double bundle_diameter(const std::vector<double>& diameters);

}  // namespace loom
