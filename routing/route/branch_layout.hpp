#pragma once
/// Where the router puts the branch points a harness file leaves open, and in which
/// direction each harness segment leaves a branch point (at any node degree). Both are decided before
/// planning, from the harness tree, the ports' connector axes and the obstacles.

#include "core/harness.hpp"
#include "core/harness_topology.hpp"
#include "index/obstacle_index.hpp"

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace loom {

/// What shapes the layout of one harness segment at its ends (scene units).
struct SegmentEnds {
  double radius = 0.0;          ///< bundle radius D/2 of the segment
  double min_bend_radius = 0.0; ///< largest minimum bend radius of the cables it carries
  double port_stub = 0.0;       ///< straight run a port end of this segment leaves along its axis
};

/// Per-segment end requirements from the topology: radius, bend radius and the port stub
/// given by `port_stub(radius, min_bend_radius)` (the planner's derived_stub_length).
std::vector<SegmentEnds> segment_ends(const HarnessTopology& topo,
                                      const std::function<double(double, double)>& port_stub);

/// Options of branch-point placement. Lengths in scene units.
struct BranchPlacementOptions {
  /// Free distance a branch point must keep from every obstacle (bundle radius plus the
  /// required clearance); by branch index.
  std::function<double(int branch)> clearance_of;
  /// Cost, in length units per unit of length, of a missing straight run: a leg from a
  /// branch point to a port that is too short for the corner it must turn within its bend
  /// radius costs this much per millimetre missing. Large enough that bend feasibility wins
  /// over a shorter harness, small enough that the length still ranks feasible positions.
  double bend_deficit_weight = 4.0;
  /// Least distance between branch points b and o beyond the gaps below, by branch index
  /// (e.g. nodes of cable classes kept apart: their bundles and breakouts must keep the
  /// separation). Empty: none.
  std::function<double(int b, int o)> extra_gap;
};

/// Places the branch points that have no position. Each starts at the geometric median of
/// its neighbours (Weiszfeld over the tree; a port neighbour counts at the end of its exit
/// stub), is moved clear of obstacles, then refined by a compass search over clear
/// positions minimising the summed leg length plus `bend_deficit_weight` × the leg length
/// missing for each port leg to turn into its connector axis within the bend radius
/// (R·tan(θ/2) on each side of the corner, plus the breakout run at the branch).
/// Placed points keep apart from every other branch point: neighbours by the sum of their
/// breakout lengths, any two by the larger bundle diameter meeting at either and by
/// `extra_gap`; fixed branch
/// points and ports are never moved. Returns the ids placed, in branch order. Throws
/// InputError naming the branch when no clear, separated position exists near its neighbours.
std::vector<std::string> place_branch_points(Harness& h, const HarnessTopology& topo, const ObstacleIndex& index,
                                             const std::vector<SegmentEnds>& ends,
                                             const BranchPlacementOptions& opt);

/// Largest turn (radians) of the main line through a branch point that is still smoothed
/// into a straight run: two segments whose far ends lie more than this off opposite sides
/// are not a line, and each leaves towards its own far end.
constexpr double kMaxMainLineTurn = 1.0471975511965976;  // 60°

/// Unit exit direction of every segment end at a branch point, keyed by (segment index,
/// true for the segment's from-end). Each segment leaves towards its far end (a port's far
/// end counts at the end of its stub); the pair of segments that most cables pass between,
/// among pairs within kMaxMainLineTurn of a straight line, forms the main line and leaves
/// in exactly opposite directions so that cables along it run smooth through the node.
/// Segments that share cables leave at least 90° apart (no cable folds back at the node)
/// wherever the node's degree allows it: at any degree along a main line, and among free
/// legs up to six of them.
std::map<std::pair<int, bool>, Vec3> branch_exit_directions(const Harness& h, const HarnessTopology& topo,
                                                            const std::vector<SegmentEnds>& ends);

/// Turns each exit direction (from branch_exit_directions) whose run — the node's breakout
/// plus the segment's bend radius, the straight length a leg needs before it can turn — comes
/// within the segment's radius + `clearance` of a part of `index`: to the free direction
/// nearest to it among ~1000 spread over the sphere that keeps ≥ 90° from the node's other
/// exits sharing cables with it and ≥ 30° from the rest. An exit with no such direction is
/// kept (its breakout stub is then shortened where the segment is planned). A leg leaving
/// into a part has no room to turn towards its far end. Returns how many exits turned.
int free_blocked_exits(const ObstacleIndex& index, const Harness& h, const HarnessTopology& topo,
                       const std::vector<SegmentEnds>& ends, const std::map<std::string, double>& breakout,
                       double clearance, std::map<std::pair<int, bool>, Vec3>& exit_dir);

}  // namespace loom
