#pragma once
/// Routing a scene (DESIGN §3–§7): scene → indices (built once) → α-simplified
/// planning obstacles → OMPL key points per harness segment in the patent's order (bundles
/// by cable count, largest first) → unplaced branch points placed → cubic B-splines with
/// port exit tangents → bend-radius repair/fairing → exact certified audit → repair
/// (denser key points where the smooth curve clashes) → routed harness + report.

#include "core/progress.hpp"
#include "core/scene.hpp"
#include "routing/audit/audit.hpp"
#include "routing/route/path_planner.hpp"
#include "routing/route/planner_portfolio.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace loom {

/// What `loom route` was asked to do. Unset values come from the scene's [routing].
struct RouteOptions {
  std::string planner;       ///< empty: scene.routing.planner
  double time_limit = -1.0;  ///< seconds per segment; < 0: scene.routing.time_limit
  long seed = -1;            ///< < 0: scene.routing.seed
  /// Planner iterations per segment (PlanSettings::max_iterations); < 0: scene.routing.
  /// iterations; 0: none. Every plan of the run gets it: the per-part clearance retry the
  /// same, the k-th bend re-plan 2^k times it (as its time limit). With a budget, a seeded
  /// run gives the same routes every time unless the time limit ends a plan first
  /// (SegmentRouteInfo::time_limited, noted in the report) or the planner is threaded
  /// (planner_is_threaded: PRM, PRM*).
  long long iterations = -1;
  int threads = 0;           ///< audit threads (≤ 0: all cores)
  /// Plan among α-simplified obstacles (false: the exact parts). Off by default: on the
  /// bundled wing section α-SIM costs ~0.25 s (with its containment check and lost-space
  /// probe) and takes planning from ~0.46 to ~0.36 s (`loom route`; from −28% to +25% in
  /// bench/results/route.csv): Embree on the exact 147k triangles is already fast. Turn
  /// it on for scenes whose detail (threads, rivets) slows the planner more than
  /// simplifying costs.
  bool simplify = false;
  /// Planning obstacles computed by the caller (e.g. α-simplified once and reused across
  /// runs, as bench_route does); when set, `simplify` is ignored. They must contain the
  /// scene's parts for a route clear of them to be clear of the real geometry; the audit
  /// always uses the scene's exact parts.
  std::shared_ptr<const std::vector<Part>> planning_parts;
  int max_repair_rounds = 4; ///< audit → densify → re-spline rounds per segment
  /// Plan each segment among the parts and the bundles routed before it (bundle radius +
  /// clearance; cut back near the nodes they share). false: among the parts only, as
  /// before harness-aware planning (for comparisons).
  bool harness_aware = true;
  /// Answer the planner's obstacle queries a voxel distance map of the planning parts can
  /// decide from it (VoxelFirstIndex: a point or motion proven clear by the map's lower
  /// bound skips Embree; every other query is exact, so every route stays valid). Off by
  /// default: on the wing section the map decides 1.4× fewer Embree queries and planning is
  /// 1.2× faster, but building the map costs more than that saves (bench_voxel_planning):
  /// the clearance objective needs exact distances within its band, where routes run.
  bool voxel_layer = false;
  /// Progress of the stages: "simplify" (parts), "index" (planning index built), "plan"
  /// (segments), "audit" (cables, each audit round); may be empty.
  ProgressFn progress;
};

/// How one harness segment was routed.
struct SegmentRouteInfo {
  int segment = -1;
  bool planned = false;       ///< planned now (false: kept from the input, or failed)
  bool kept_from_input = false;  ///< the input already had its path or spline
  PlanResult plan;            ///< the planner's answer (when planned)
  std::size_t key_points = 0; ///< interior key points in the routed file
  int repair_rounds = 0;      ///< densification rounds after the audit
  int replans = 0;            ///< re-plans that were kept because the bend repair failed
  /// Key points inserted to bring unsupported stretches within clamp reach of structure
  /// (pull_to_structure; only when the scene sets clamp_spacing).
  int support_points = 0;
  std::string bend_status;    ///< outcome of the bend-radius repair
  /// The bend-feasible plan (routing/route/bend_planner.hpp), run when some corner of the
  /// planner's route cannot be rounded clear at the bend radius: empty if not run, else
  /// "planned" or "failed: <why>".
  std::string bend_plan;
  std::uint64_t bend_plan_samples = 0;  ///< samples the bend-feasible plan drew
  double bend_plan_ms = 0.0;            ///< its wall time (part of RouteTimings::plan)
  /// True if the time limit ended any plan of this segment (first plan, clearance retry or
  /// bend re-plan) before its iteration budget: this segment's route is not reproducible.
  bool time_limited = false;
  /// With the portfolio planner: the budgets of the plan kept and what its stages did.
  std::optional<PortfolioOutcome> portfolio;
};

/// Why a cable has no route.
struct UnroutedCable {
  std::string cable;
  std::string segment;  ///< "FROM -> TO" of the segment that failed
  std::string reason;   ///< reason_name() of the planner, or "branch_blocked"
  std::string message;  ///< human-readable, with coordinates
};

/// Time split of a route run, milliseconds.
struct RouteTimings {
  double load = 0, index = 0, simplify = 0, plan = 0, spline = 0, audit = 0, repair = 0, total = 0;
};

/// Everything `loom route` reports.
struct RouteReport {
  Harness routed;                        ///< the harness with branch positions, paths, splines
  std::vector<SegmentRouteInfo> segments;  ///< in routing order
  std::vector<UnroutedCable> unrouted;
  AuditReport audit;                     ///< the final exact audit of the routed cables
  RouteTimings timing;
  std::string planner;
  unsigned seed = 0;
  std::uint64_t iterations = 0;          ///< planner iterations per segment (0: none)
  /// Why this run may not be reproducible: one line per cause (no iteration budget, a
  /// threaded planner, each segment whose plan the time limit ended). Also in `notes`.
  std::vector<std::string> unreproducible;
  double clearance = 0.0;                ///< required clearance used
  /// Supports (the scene sets clamp_spacing): clamps placed, and the share of the routed
  /// cable length whose bundle is within clamp_reach of structure (−1: not measured).
  std::size_t clamps_placed = 0;
  double share_within_reach = -1.0;
  /// The voxel layer (RouteOptions::voxel_layer): its voxel edge (0: none); the planning
  /// obstacle queries it decided and those Embree answered (every one without the layer).
  double voxel_resolution = 0.0;
  std::size_t voxel_bytes = 0;  ///< the map's memory
  std::uint64_t voxel_decided = 0, voxel_exact = 0;
  std::vector<std::string> notes;
  /// DESIGN §4: 3 if a cable could not be routed, else 1 if clashes/violations remain, else 0.
  int exit_code() const { return !unrouted.empty() ? 3 : audit.exit_code(); }
};

/// Routes every unrouted segment of the scene's harness and audits the result.
RouteReport route_scene(const Scene& scene, const RouteOptions& opt);

}  // namespace loom
