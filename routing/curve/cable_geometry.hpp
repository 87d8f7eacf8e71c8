#pragma once
/// The centerline of each cable and segment of a harness: segment curves from their
/// <bspline> (exact) or from their path points (interp bspline|polyline), joined along
/// each cable's chain of segments (HarnessTopology) from its first port to its second.

#include "core/centerline.hpp"
#include "core/harness_topology.hpp"

#include <array>
#include <optional>
#include <vector>

namespace loom {

/// Straight stub length for a tube: max(min_bend_radius, 2·radius) — the tube
/// leaves the connector straight for at least its diameter, and for one bend radius so that
/// a 90° turn fits before it moves sideways. Scene units.
double derived_stub_length(double radius, double min_bend_radius);

/// The curve of one segment, from → to: its exact <bspline> if present; else the
/// interpolating cubic (interp="bspline", tangent-clamped along port exit directions at
/// port ends) or polyline through from-node, path points, to-node. nullopt if an end has
/// no position (an unplaced branch point) — the segment is not routed yet.
std::optional<Centerline> segment_centerline(const Harness& h, int segment);

/// One segment of a cable's route, oriented in the cable's direction of travel.
struct CablePiece {
  int segment = -1;     ///< index into Harness::segments
  double s0 = 0.0;      ///< arc length from the cable's first port where the piece starts
  Centerline curve;     ///< the segment's curve, traversed as the cable runs
};

/// The curve of every segment of a harness, each built once, on first use, in each
/// direction it is asked for (with its arc-length table, which copies carry). Why: a loop
/// over cables asks for a shared segment once per cable through it, and interpolating a
/// segment with many key points is the costly part (an 11-cable bundle segment with
/// 200,000 key points was interpolated 33 times for one audit and its two outputs).
/// Holds a reference to the topology; not thread-safe (one per loop).
class SegmentCurves {
 public:
  explicit SegmentCurves(const HarnessTopology& topo);
  /// segment_centerline(harness, s), traversed to → from if `backwards`; throws what it
  /// throws (and builds it again on the next call).
  const std::optional<Centerline>& segment(int s, bool backwards);
  /// cable_pieces(topo, cable) from the cached curves. A chain that does not make a curve
  /// throws InputError naming the harness file, the cable's line and the reason.
  std::vector<CablePiece> pieces(int cable);
  /// cable_centerline(topo, cable) from the cached curves; throws as pieces() does.
  std::optional<Centerline> cable(int cable);

 private:
  const HarnessTopology& topo_;
  /// [segment][backwards]: built yet, and the curve.
  std::vector<std::array<bool, 2>> built_;
  std::vector<std::array<std::optional<Centerline>, 2>> curves_;
};

/// The segment curves of a cable's chain, in order, each reversed where the cable runs
/// to → from. Empty if any segment of the chain is not routed. Bends are judged within a
/// piece: where two pieces meet at a branch point the wires splay inside the breakout.
std::vector<CablePiece> cable_pieces(const HarnessTopology& topo, int cable);

/// A cable's full centerline from its first to its second port: the segment curves of its
/// chain joined in order (reversed where the cable runs to → from) into one curve.
/// nullopt if any segment of the chain is not routed.
std::optional<Centerline> cable_centerline(const HarnessTopology& topo, int cable);

/// Length of the breakout at a node: the stretch next to it over which cables that meet
/// there run bundled before they separate. Over incident segments, the larger of the biggest
/// min bend radius of the cables carried and the segment diameter (scene units); 0 for a
/// node with no cable. The router leaves branch points straight for this long, and the
/// audit lets cables that share the node touch within this distance of it.
double breakout_length(const HarnessTopology& topo, const std::string& node);

}  // namespace loom
