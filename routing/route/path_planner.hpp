#pragma once
/// Key points of one tube route between two ports, planned with OMPL in R³ (DESIGN §6
/// "Planning", §9 OMPL 1.5.2): port → straight stub along the port's exit direction →
/// planned key points → stub → port. The state is the tube's centre point, valid at distance
/// ≥ radius + clearance from every part (routing/tube_validity.hpp); motions are exact capsule
/// checks. The objective is length plus a clearance term plus optional per-part preferences;
/// OMPL's path is simplified with that objective and reduced to key points by shortcutting
/// with the exact capsule check. Every returned polyline has been re-verified exactly.
///
/// Determinism. Each plan seeds locally, from PlanSettings::seed, the samplers of its state
/// space (also those OMPL's informed samplers allocate), the planners that own a random
/// generator (RRT*, Informed/SO RRT*, RRT#, RRT, RRTConnect, PRM, PRM*) and the path
/// simplifier; simplification runs a fixed number of rounds. So a plan is reproducible, in any
/// process and in any order of plans, whenever the planner's run ends on a deterministic
/// condition: its first solution (rrtconnect, rrt, lazyprm) or PlanSettings::max_iterations
/// (tested: rrtstar, informedrrtstar, sorrtstar, bitstar, lazyprmstar). Runs ending on the
/// wall-clock budget or on cost convergence (measured in time) may stop after a different
/// number of iterations; PlanResult::time_limited says when the time limit ended a run (the
/// termination condition tests the iteration budget before the clock, so a run whose budget
/// and time end together counts as ended by its budget). PRM and PRM* grow their roadmap in
/// a second thread: not reproducible.
/// Generators OMPL keeps internally (e.g. BIT*'s) draw from OMPL's process seed, which
/// seed_ompl_once sets once, before any OMPL generator exists, from the first plan's seed.

#include "core/geometry.hpp"
#include "index/obstacle_index.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace loom {

/// How a route should treat one part (harnesses are clamped along structure).
enum class PartPreference {
  Neutral,  ///< only the clearance term applies
  Near,     ///< routing within the clearance band of this part is cheaper
  Avoid,    ///< routing within the clearance band of this part costs extra
};

/// "neutral" | "near" | "avoid".
const char* preference_name(PartPreference p);

/// A port as the planner sees it: the cable end point and its unit exit direction (the
/// connector axis, pointing away from the connector into free space). World frame.
struct PortSpec {
  Vec3 position = Vec3::Zero();
  Vec3 exit_direction = Vec3::UnitX();  ///< normalised by the planner; must be non-zero
};

/// The route cost: ∫ rate(C(s)) ds over the centre line, with
/// rate = length_weight + clearance_weight·φ(d) + preference_weight·(Σ_avoid φ(d_p) + (1 − φ(d_near)))
///        + support_weight·σ(d_support),
/// φ(d) = clamp(1 − (d − required)/band, 0, 1): 1 at the required distance, 0 beyond
/// required + band. d is the distance to the nearest part (0 when that part is Near),
/// d_p to each Avoid part, d_near to the nearest Near part. σ(d) = clamp((d − support_reach)
/// / support_band, 0, 1): 0 where a clamp on a supporting part can hold the centre line, 1
/// from support_reach + support_band on; d_support is the distance to the nearest supporting
/// part. So an unsupported stretch costs (length_weight + support_weight) per unit length: a
/// route takes a detour along structure while it is shorter than support_weight /
/// length_weight times the unsupported length it saves. Lengths in scene units.
struct PlanObjective {
  double length_weight = 1.0;      ///< cost per unit length (> 0)
  double clearance_weight = 1.0;   ///< extra cost per unit length at the required distance (≥ 0)
  double clearance_band = 0.0;     ///< width of the clearance term (scene units); 0 = required distance
  double preference_weight = 1.0;  ///< weight of the per-part preferences (≥ 0)
  std::vector<PartPreference> part_preference;  ///< by part id; missing ids are Neutral
  double support_weight = 0.0;     ///< extra cost per unit length out of clamp reach (≥ 0; 0: off)
  double support_reach = 0.0;      ///< centre-line distance a clamp holds from a supporting part (> 0 when on)
  double support_band = 0.0;       ///< width of σ's ramp (scene units); 0 = support_reach
  /// By part id: the part can carry a clamp (structure; keep-outs cannot). Empty = all parts.
  std::vector<bool> part_supports;
};

/// Everything about a route except its two ports and its time budget (shared by all the
/// queries of a RoadmapPlanner).
struct PlanSettings {
  double radius = 0.0;           ///< tube radius, scene units (> 0)
  double clearance = 0.0;        ///< required clearance to every part, scene units (≥ 0)
  double min_bend_radius = 0.0;  ///< smallest centre-line bend radius (≥ 0), sets the stub length
  double stub_length = -1.0;     ///< straight run along each exit direction; < 0 = derived_stub_length()
  AABB scene_box;                ///< box of the obstacles; planning bounds = box ∪ ports ∪ stubs + margin
  /// One of planner_names(). Default: Informed RRT*, the best length per time with BIT* in
  /// bench/results/planner_summary.csv (BIT* has a known crash in OMPL 1.5.2, DESIGN §9).
  std::string planner = "informedrrtstar";
  std::uint32_t seed = 1;        ///< random seed (see the determinism note above)
  /// > 0: also stop after this many evaluations of the termination condition (one per
  /// iteration for the tree planners; FMT/BFMT evaluate it per sample). Disables the
  /// time-based convergence test, so seeded runs are reproducible.
  std::uint64_t max_iterations = 0;
  PlanObjective objective;
  /// Stop an optimising planner when its best cost improved by less than this fraction over
  /// the last convergence_window of the budget, or came within this fraction of the
  /// straight-line lower bound (OMPL's cost threshold). 0 disables both.
  double convergence_epsilon = 0.01;
  double convergence_window = 0.25;  ///< fraction of the time budget (0, 1]
  /// When no route is found: extra time, as a fraction of the budget, spent looking for a
  /// thin path (radius kThinFraction·required) to tell "no corridor wider than the tube"
  /// from a timeout. 0 disables the diagnosis.
  double diagnosis_fraction = 0.5;
};

/// One planning query.
struct PlanRequest : PlanSettings {
  PortSpec start;            ///< first port
  PortSpec goal;             ///< second port
  double time_limit = 1.0;   ///< seconds of planning (≥ 0; 0 = check the ports only)
};

/// Outcome of a planning query.
enum class PlanStatus { Solved, NoPath };

/// Why there is no path.
enum class NoPathReason {
  None,              ///< solved
  StartInObstacle,   ///< the first port is inside a part or closer than radius + clearance
  GoalInObstacle,    ///< the second port is
  StartPortBlocked,  ///< the first port faces a wall: its straight stub is blocked
  GoalPortBlocked,   ///< the second port's stub is blocked
  NoCorridor,        ///< a thin path exists, but no corridor wider than the tube was found
  Timeout,           ///< no path within the time budget (not even a thin one, or budget 0)
  Enclosed,          ///< no thin path, and an end is sealed in a cavity (every ray from it hits a part)
  InvalidSolution,   ///< the planner's path failed the exact re-check (a bug; never returned as a route)
};

/// `pts` (world frame) without each point closer than `tol` (scene units) to the point kept
/// before it; a polyline of two or more points keeps at least its first and last.
std::vector<Vec3> dedupe_consecutive(const std::vector<Vec3>& pts, double tol);

/// "none" | "start_in_obstacle" | "goal_in_obstacle" | "start_port_blocked" |
/// "goal_port_blocked" | "no_corridor" | "timeout" | "enclosed" | "invalid_solution".
const char* reason_name(NoPathReason r);

/// The key points of a route and what they cost.
struct PlanResult {
  PlanStatus status = PlanStatus::NoPath;
  NoPathReason reason = NoPathReason::Timeout;
  std::string message;               ///< human-readable explanation (with coordinates)
  std::optional<Vec3> blocked_at;    ///< where it was blocked (surface point / narrowest passage)
  int blocking_part = -1;            ///< part that blocked it, -1 if unknown
  /// Polyline from the first port to the second (world frame): port, stub end, interior key
  /// points, stub end, port. Empty unless Solved.
  std::vector<Vec3> key_points;
  double length = 0.0;          ///< polyline length, scene units
  double min_clearance = 0.0;   ///< min over the polyline of distance to parts − radius (DESIGN §5)
  double cost = 0.0;            ///< objective value of the polyline
  double lower_bound = 0.0;     ///< length_weight · port-to-port stub-end distance (no route is cheaper)
  double stub_length = 0.0;     ///< stub length used, scene units
  std::string planner;          ///< planner name used
  std::size_t raw_states = 0;   ///< states of the planner's path before simplification
  double time_ms = 0.0;         ///< total wall time of the query
  double plan_ms = 0.0;         ///< time inside the OMPL planner
  double simplify_ms = 0.0;     ///< time simplifying and reducing to key points
  double diagnose_ms = 0.0;     ///< time spent diagnosing a failure
  std::uint64_t motion_checks = 0;  ///< exact capsule checks made by the planner
  /// Evaluations of the termination condition by the planner run (at most max_iterations
  /// when that is set).
  std::uint64_t iterations = 0;
  /// True if the wall-clock time limit stopped the planner run (or the thin-path diagnosis
  /// after a failure) before its iteration budget, first solution or cost threshold did:
  /// such a plan is not reproducible, another run may stop after a different number of
  /// iterations.
  bool time_limited = false;
  /// True if status == Solved.
  bool solved() const { return status == PlanStatus::Solved; }
};

/// The planner names accepted by PlanSettings::planner, sorted (routing_planner_names()
/// without "portfolio", which route_scene runs through plan_portfolio).
std::vector<std::string> planner_names();
/// True if the named planner optimises the objective (runs until convergence/budget).
/// Throws std::invalid_argument for an unknown name.
bool planner_is_optimizing(const std::string& name);

/// True if the named planner grows its roadmap in a second thread (PRM, PRM*): its runs are
/// not reproducible, not even with max_iterations (the threads share the iteration count).
/// Throws std::invalid_argument for an unknown name.
bool planner_is_threaded(const std::string& name);

/// Sets OMPL's process-wide seed (ompl::RNG::setSeed) and its log level once, before any OMPL
/// random generator exists; later calls change nothing. Returns the seed in effect. OMPL's
/// own messages are limited to errors unless LOOM_OMPL_LOG is set in the environment.
std::uint32_t seed_ompl_once(std::uint32_t seed);

/// Plans one route. Throws std::invalid_argument for bad settings (non-positive radius,
/// negative clearance or time, zero exit direction, unknown planner name listing the valid
/// ones, coincident ports); expected failures are PlanStatus::NoPath with a reason.
PlanResult plan_path(const ObstacleIndex& index, const PlanRequest& request);

/// A multi-query roadmap (PRM*, LazyPRM*, PRM, LazyPRM) for many routes of one tube size in
/// one scene: the roadmap is kept between queries (OMPL clearQuery, not clear), so later
/// queries reuse the free-space graph built by earlier ones.
class RoadmapPlanner {
 public:
  /// `index` must outlive the planner. settings.planner must be a multi-query planner; the
  /// planning bounds are fixed here from settings.scene_box + margin (it must not be empty;
  /// ports outside the bounds are reported as StartInObstacle / GoalInObstacle with a message
  /// saying so). Throws std::invalid_argument as plan_path does.
  RoadmapPlanner(const ObstacleIndex& index, const PlanSettings& settings);
  ~RoadmapPlanner();
  RoadmapPlanner(const RoadmapPlanner&) = delete;
  RoadmapPlanner& operator=(const RoadmapPlanner&) = delete;

  /// Plans one route, growing and reusing the roadmap. Not thread-safe (one query at a time).
  PlanResult plan(const PortSpec& start, const PortSpec& goal, double time_limit);
  /// Number of roadmap vertices kept so far.
  std::size_t roadmap_vertices() const;
  /// True if `name` is a multi-query planner usable here.
  static bool supports(const std::string& name);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace loom
