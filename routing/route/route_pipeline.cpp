#include "routing/route/route_pipeline.hpp"

#include "routing/route/bend_planner.hpp"
#include "routing/route/support_pull.hpp"

#include "core/stopwatch.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/clash_check.hpp"
#include "routing/audit/supports.hpp"
#include "routing/route/clamp_placement.hpp"
#include "routing/route/motion_envelope.hpp"
#include "routing/curve/bend_repair.hpp"
#include "routing/route/branch_layout.hpp"
#include "routing/route/bundle_obstacles.hpp"
#include "routing/route/class_separation.hpp"
#include "index/voxel_first_index.hpp"
#include "index/voxel_map.hpp"
#include "routing/route/port_check.hpp"
#include "routing/route/support_pull.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <set>

namespace loom {

namespace {


/// The straight stubs at both ends of a segment may eat at most this share of the way
/// between its ends (the part of each stub that heads towards the other end).
constexpr double kStubShare = 0.5;

/// Re-plans of a segment whose bend repair failed: each with a fresh seed and twice the
/// previous budget; the first whose curve meets the bend radius is kept.
constexpr int kBendReplans = 2;

/// The bend-feasible plan rounds its corners this much wider than the bend radius: the
/// cubic through the arc points bends up to ~22% tighter than the arcs where they meet a leg
/// (the curvature jumps there; test_arc_line checks the margin on random routes).
constexpr double kBendPlanMargin = 1.3;
/// Samples of a bend-feasible plan: at least this many, or the run's feasibility budget if
/// larger (the wall-clock budget may end it first).
constexpr std::uint64_t kBendPlanSamples = 20000;
/// The bend-feasible plan's seed is mixed with this, so that it differs from the planner's.
constexpr std::uint32_t kBendPlanSeedSalt = 0xB3ADu;

/// Grid budget of the voxel layer (cells; ~9 bytes each: distance, nearest part, flags).
constexpr std::size_t kVoxelLayerCells = std::size_t(16) << 20;

/// Box of every part's triangles.
AABB box_of(const std::vector<Part>& parts) {
  AABB box;
  for (const Part& p : parts) box.extend(p.mesh.bounds());
  return box;
}

/// The voxel layer's edge: `finest` (the diagonal the thinnest tube needs), coarsened in
/// steps of 10% until the grid over `box` plus its margin (max_distance and a voxel) holds at
/// most `budget` cells: a coarser map still decides the queries far from every part.
double voxel_layer_resolution(const AABB& box, double finest, double max_distance, std::size_t budget) {
  double h = finest;
  for (int step = 0; step < 200 && !box.empty(); ++step, h *= 1.1) {
    double cells = 1.0;
    for (int a = 0; a < 3; ++a) cells *= (box.max[a] - box.min[a] + 2.0 * (max_distance + h)) / h + 3.0;
    if (cells <= static_cast<double>(budget)) break;
  }
  return h;
}

/// Slack of the port-exit checks, as a share of the tube radius (the audit's default
/// tolerance, r/100): the exit is checked not to enter the part its port sits on from this far
/// off the port; an exit on a part runs at least `required` plus twice this, so that the
/// planner starts clear of it; a keep-out zone near a port is measured from `required` plus
/// this. A port on a face leaving along the normal is exactly `required` from the face at
/// `required`: rounding must not make that face a wall.
constexpr double kAttachSlackPerRadius = 0.01;

/// Share by which a routed segment may be longer than the nominal (formboard or physical)
/// length its file gives before the report says so: the harness maker cuts that length, and
/// a bundle's breakouts and sag take up a few percent.
constexpr double kNominalLengthTolerance = 0.05;

/// A segment's key-point polyline and the curve through it.
struct SegmentGeometry {
  std::vector<Vec3> points;  ///< from-node, interior key points, to-node
  InterpolationOptions interp;
  Centerline curve;
  Vec3 a, a_stub, b_stub, b;  ///< the ends and their stub ends, as planned
  PlanRequest request;        ///< what the planner was asked (for re-planning)
  std::vector<int> visible;   ///< segments whose bundles are its obstacles (see replan_bend_failures)
  /// The segments whose bundles were its obstacles when it was first planned (those routed
  /// before it): a bend-feasible plan among every bundle that fails is tried among these.
  std::vector<int> planned_among;
  /// The planned corners rounded by arcs (node to node) when they fit clear: the points used
  /// if the bend repair of `points` fails. Empty otherwise.
  std::vector<Vec3> arc_points;
};


/// The key-point polyline of a segment: node, stub end, the planner's interior key points,
/// stub end, node; coincident points removed.
std::vector<Vec3> assemble(const SegmentGeometry& g, const std::vector<Vec3>& key_points, double eps) {
  std::vector<Vec3> pts{g.a, g.a_stub};
  pts.insert(pts.end(), key_points.begin(), key_points.end());
  pts.push_back(g.b_stub);
  pts.push_back(g.b);
  return dedupe_consecutive(pts, eps);
}

/// Inserts the midpoint of every polyline edge but the two end stubs: the interpolating
/// cubic then follows the verified polyline more closely (the deviation falls roughly 4×
/// per round). The stubs stay single chords: their curve is clamped to the exit direction
/// at the node, and a short chord that fairing has turned slightly off that direction
/// would bend the curve sharply right at the node.
std::vector<Vec3> densify(const std::vector<Vec3>& pts) {
  std::vector<Vec3> out;
  const bool keep_stubs = pts.size() > 3;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    out.push_back(pts[i]);
    if (keep_stubs && (i == 0 || i + 2 == pts.size())) continue;
    out.push_back(0.5 * (pts[i] + pts[i + 1]));
  }
  out.push_back(pts.back());
  return out;
}

/// One end of a segment as the planner sees it.
struct EndFrame {
  std::string node;
  Vec3 position = Vec3::Zero();
  Vec3 exit = Vec3::UnitX();  ///< unit direction leaving the node into the segment
  bool is_port = false;
};

/// The longest straight run from `p` along `dir`, at most `len`, that keeps `required` from
/// every obstacle (halving; 0 if even a short one is blocked).
double free_stub(const ObstacleIndex& index, const Vec3& p, const Vec3& dir, double len, double required) {
  constexpr int kHalvings = 6;
  for (int i = 0; i < kHalvings && len > 0.0; ++i, len *= 0.5)
    if (!index.segment_within(p, p + len * dir, required)) return len;
  return 0.0;
}

BSplineData to_bspline(const Centerline& c) {
  return BSplineData{c.degree(), c.knots(), c.control_points()};
}

/// Refuses, before any planning, a cable that the certified audit of every route between
/// its ports would refuse: its chords are at most 2r long, so ports farther apart than
/// kMaxCertifiedChords of them (a diameter in the wrong units) need more than it takes.
/// InputError at the cable's element of the harness file.
void refuse_unauditable_cables(const Harness& h) {
  for (const Cable& c : h.cables) {
    const int a = h.find_port(c.ports[0]), b = h.find_port(c.ports[1]);
    if (a < 0 || b < 0 || !(c.radius() > 0.0)) continue;  // the topology refuses these with their own messages
    const double apart = (h.ports[static_cast<std::size_t>(b)].position - h.ports[static_cast<std::size_t>(a)].position).norm();
    const double chords = fewest_certified_chords(apart, c.radius());
    if (!(chords > kMaxCertifiedChords)) continue;
    throw InputError({h.source_file, c.line, ""},
                     "cable '" + c.id + "': its ports " + c.ports[0] + " and " + c.ports[1] + " are " +
                         full_precision(apart) + " apart, so the audit of any route between them needs at least " +
                         full_precision(std::ceil(chords)) + " chords of at most its diameter " +
                         full_precision(c.physical.diameter) + ", more than the " + full_precision(kMaxCertifiedChords) +
                         " it takes: check the diameter and the harness units");
  }
}

/// The stub ends of one segment and what its port ends may touch near the port.
struct SegmentExits {
  EndFrame ea, eb;                   ///< the from- and to-end
  std::vector<NearPart> on_a, on_b;  ///< parts near each port end (empty at a branch point)
  Vec3 a_stub, b_stub;               ///< where the planner starts and ends (world frame)
  double radius = 0.0;               ///< bundle radius
  double required = 0.0;             ///< radius + routing clearance + largest part clearance
  double attach_slack = 0.0;         ///< kAttachSlackPerRadius · radius
};

/// One run of route_scene: the scene, the options and everything the stages share. Each
/// stage is one method, called once in the order of run().
class RouteRun {
 public:
  /// Settles the planner, seed, time limit and iteration budget from `opt` and the scene.
  RouteRun(const Scene& scene, const RouteOptions& opt);
  /// Runs every stage and returns the report.
  RouteReport run();

 private:
  void prepare_obstacles();
  void prepare_voxel_layer();
  const ObstacleIndex& planning_index() const;
  bool holds_clamp(std::size_t planning_part) const;
  void layout_branches();
  EndFrame end_frame(int seg, bool from_end) const;
  void plan_segments();
  void plan_segment(int s, const std::vector<int>& visible);
  SegmentExits segment_exits(int s) const;
  PlanRequest plan_request(int s, const SegmentExits& x) const;
  PlanResult blocked_end(const SegmentExits& x, bool& branch_blocked) const;
  PlanResult plan_with_retry(const Segment& seg, const ObstacleIndex& index, PlanRequest& req,
                             SegmentRouteInfo& info);
  std::unique_ptr<HarnessAwareIndex> obstacles_for(int s, const std::vector<int>& visible) const;
  std::vector<int> routed_now(int except) const;
  void store_info(const SegmentRouteInfo& info);
  void reorder_blocked();
  bool replan_among(int t, const std::vector<int>& visible);
  PlanResult plan_one(const ObstacleIndex& index, const PlanRequest& req, SegmentRouteInfo& info) const;
  void add_bundle_tube(int s);
  std::string blocker_name(const ObstacleIndex& index, int part, int s) const;
  int pull_to_supports(const ObstacleIndex& index, const SegmentExits& x, std::vector<Vec3>& key_points) const;
  void set_planned_points(int s, SegmentGeometry& g, const std::vector<Vec3>& key_points,
                          const ObstacleIndex& index) const;
  std::optional<ArcLineEnds> arc_line_ends(int s, const SegmentGeometry& g) const;
  bool bend_plan(int s, SegmentGeometry& g, const ObstacleIndex& index, SegmentRouteInfo& info) const;
  bool try_bend_plan(int s);
  void record_unrouted(int s, const PlanResult& plan, bool branch_blocked);
  void build_splines();
  void build_curve(int s);
  BendRepairResult round_corners(int s, const SegmentGeometry& g, const ObstacleIndex& index) const;
  void replan_bend_failures();
  SegmentRouteInfo& info_of(int s);
  bool bend_failed(int s);
  void audit_and_repair();
  AuditReport audit_now();
  std::set<int> segments_to_repair() const;
  void place_supports();
  void note_reproducibility();
  void note_nominal_lengths();

  const Scene& scene_;
  const RouteOptions& opt_;
  Stopwatch total_;
  RouteReport rep_;
  Harness& h_;
  const HarnessTopology topo_;  // ids and structure never change below, only geometry
  const std::vector<std::set<std::string>> classes_;  ///< cable classes of each segment
  double time_limit_ = 0.0;
  double part_extra_ = 0.0;    ///< largest per-part extra clearance
  bool plan_on_other_parts_ = false;
  std::vector<Part> planning_parts_;
  std::size_t envelope_parts_from_ = 0;  ///< planning parts from here on are posed copies of moving parts
  std::unique_ptr<EmbreeIndex> plan_index_;
  std::unique_ptr<VoxelMap> voxel_map_;          ///< distance map of the planning parts (voxel layer)
  std::unique_ptr<VoxelFirstIndex> voxel_first_; ///< plan_index_ behind the map's lower bound
  std::vector<AABB> part_boxes_;  ///< box of each planning part
  std::vector<SegmentEnds> ends_;
  std::map<std::pair<int, bool>, Vec3> exit_dir_;
  std::map<std::string, double> breakout_;
  AABB box_;
  double eps_ = 0.0;  ///< coincident key points
  std::map<int, SegmentGeometry> geom_;
  std::map<int, BundleTube> tubes_;  ///< each planned segment's bundle as an obstacle for later ones
  std::map<int, int> blocked_by_;    ///< failed segment → the segment whose bundle blocked it
  std::map<int, bool> branch_blocked_;  ///< failed segment → a branch point of it lies in a part
  std::set<std::string> failed_segments_;
  std::unique_ptr<EmbreeIndex> exact_owned_;
  Scene routed_scene_;
  AuditOptions audit_options_;
};

RouteRun::RouteRun(const Scene& scene, const RouteOptions& opt)
    : scene_(scene), opt_(opt), h_(rep_.routed = scene.harness), topo_(h_), classes_(segment_classes(topo_)) {
  rep_.planner = opt.planner.empty() ? scene.routing.planner : opt.planner;
  rep_.seed = opt.seed >= 0 ? static_cast<unsigned>(opt.seed) : scene.routing.seed;
  time_limit_ = opt.time_limit >= 0 ? opt.time_limit : scene.routing.time_limit.value;
  rep_.iterations = opt.iterations >= 0 ? static_cast<std::uint64_t>(opt.iterations)
                                        : static_cast<std::uint64_t>(scene.routing.iterations.value);
  rep_.clearance = scene.routing.clearance.value;
  for (const auto& p : scene.parts) part_extra_ = std::max(part_extra_, p.clearance);
  refuse_unauditable_cables(h_);  // before the planning work it would throw away
  // A topology-only port has no position until the scene places it (load_scene refuses the
  // scene otherwise); a harness built in code must not route it from the origin.
  for (const Port& p : h_.ports)
    if (!p.placed)
      throw InputError({h_.source_file, p.line, "port " + p.id},
                       "has no 3D position (topology only): place it in the scene's [harness.place] table");
  for (std::string& n : separation_conflicts(topo_, scene.routing, classes_)) rep_.notes.push_back(std::move(n));
}

RouteReport RouteRun::run() {
  prepare_obstacles();
  layout_branches();
  plan_segments();
  build_splines();
  replan_bend_failures();
  const VoxelFirstCounts n = voxel_first_->counts();
  rep_.voxel_decided = n.decided;
  rep_.voxel_exact = n.exact;
  audit_and_repair();
  note_nominal_lengths();
  note_reproducibility();
  rep_.timing.total = total_.ms();
  return std::move(rep_);
}

/// Planning obstacles: α-simplified parts (they contain the originals, so a route clear of
/// them is clear of the real parts), the caller's, or the exact parts; indexed once.
void RouteRun::prepare_obstacles() {
  Stopwatch t0;
  plan_on_other_parts_ = opt_.planning_parts || (opt_.simplify && !scene_.parts.empty());
  if (opt_.planning_parts) {
    planning_parts_ = *opt_.planning_parts;
    rep_.notes.push_back("planning on " + std::to_string(planning_parts_.size()) + " parts given by the caller");
  } else if (opt_.simplify && !scene_.parts.empty()) {
    AlphaSimOptions ao;
    ao.dim_pre = scene_.simplify.dim_pre.value;
    ao.extra_planes = scene_.simplify.planes;
    ao.split_blocked = scene_.simplify.split;
    ao.detect_lost_space = true;
    ao.hausdorff = false;  // not reported by routing; the containment check and lost-space probe stay
    ao.progress = opt_.progress;
    std::vector<AlphaSimResult> results;
    planning_parts_ = simplify_parts(scene_.parts, ao, &results);
    std::size_t before = 0, after = 0, split = 0, kept = 0;
    for (const auto& r : results) {
      before += r.triangles_before, after += r.triangles_after;
      split += !r.pieces.empty() && r.fallback != AlphaSimFallback::Original;
      kept += r.fallback == AlphaSimFallback::Original;
    }
    rep_.notes.push_back("planning on α-simplified parts (dim_pre " + full_precision(ao.dim_pre) + "): " +
                         std::to_string(before) + " -> " + std::to_string(after) + " triangles, " +
                         std::to_string(split) + " parts split, " + std::to_string(kept) + " kept as they are");
  } else {
    planning_parts_ = scene_.parts;
  }
  // Moving parts: their swept envelope is an obstacle too; then the planning parts are no
  // longer the exact ones the audit needs.
  envelope_parts_from_ = planning_parts_.size();
  const double gap = swept_envelope_gap(rep_.clearance, h_.smallest_diameter());
  if (append_swept_envelopes(scene_.parts, gap, unit_name(scene_.units), planning_parts_, rep_.notes) > 0)
    plan_on_other_parts_ = true;
  rep_.timing.simplify = t0.ms();
  t0.restart();
  ProgressCounter indexed(opt_.progress, "index", 1, "indices");
  plan_index_ = std::make_unique<EmbreeIndex>(planning_parts_);
  indexed.finish();
  for (std::size_t q = 0; q < planning_parts_.size(); ++q) {
    const auto kept = plan_index_->part_bounds(static_cast<int>(q));
    part_boxes_.push_back(kept ? *kept : planning_parts_[q].mesh.bounds());
  }
  prepare_voxel_layer();
  rep_.timing.index = t0.ms();
}

/// The voxel layer: a distance map of the planning parts at the resolution the thinnest
/// tube needs (half its required distance as the map's error bound), known up to the
/// required distance plus twice that bound, so that a point farther than that from every
/// part is decided without Embree. A scene too large for the map's grid budget plans on
/// Embree alone, and the notes say so.
void RouteRun::prepare_voxel_layer() {
  const double required = 0.5 * h_.smallest_diameter() + rep_.clearance + part_extra_;
  if (opt_.voxel_layer && !planning_parts_.empty() && required > 0.0) {
    VoxelOptions vo;
    vo.max_distance = 4.0 * required;  // beyond the clearance band (2 required) and the bound
    vo.resolution = voxel_layer_resolution(box_of(planning_parts_), required / std::sqrt(3.0), vo.max_distance,
                                           kVoxelLayerCells);
    vo.exact_refine = false;                    // no exact query in the build
    vo.max_cells = kVoxelLayerCells;
    vo.threads = opt_.threads;
    const Stopwatch t0;
    try {
      voxel_map_ = std::make_unique<VoxelMap>(
          planning_parts_, vo, std::shared_ptr<const ObstacleIndex>(plan_index_.get(), [](const ObstacleIndex*) {}));
      rep_.voxel_resolution = vo.resolution;
      rep_.voxel_bytes = voxel_map_->memory_bytes();
      rep_.notes.push_back("voxel layer: " + full_precision(vo.resolution) + " voxels, distances within " +
                           full_precision(voxel_map_->accuracy().abs_error) + ", " +
                           std::to_string(voxel_map_->memory_bytes() >> 20) + " MiB, built in " +
                           std::to_string(static_cast<long>(t0.ms())) + " ms (voxels and OcTree " +
                           std::to_string(static_cast<long>(1e3 * voxel_map_->stats().voxelise_seconds)) +
                           " ms, distance transform " +
                           std::to_string(static_cast<long>(1e3 * voxel_map_->stats().edt_seconds)) + " ms)");
    } catch (const InputError& e) {
      rep_.notes.push_back(std::string("no voxel layer (Embree answers every planning query): ") + e.what());
    }
  }
  voxel_first_ = std::make_unique<VoxelFirstIndex>(*plan_index_, voxel_map_.get());
}

/// Whether a planning part may hold a clamp: structure that does not move, and not a posed
/// copy of a moving part (its swept envelope).
bool RouteRun::holds_clamp(std::size_t planning_part) const {
  return planning_part < envelope_parts_from_ && holds_clamps(planning_parts_[planning_part]);
}

/// The planning parts as the planner queries them: behind the voxel layer (counted, and
/// decided by the map when there is one).
const ObstacleIndex& RouteRun::planning_index() const { return *voxel_first_; }

/// Places the branch points the file leaves open where the legs are short and can turn into
/// their connectors within the bend radius; then the exit direction of every segment at
/// every branch point (main lines smooth through their node) and each breakout length.
void RouteRun::layout_branches() {
  ends_ = segment_ends(topo_, derived_stub_length);
  BranchPlacementOptions bpo;
  bpo.clearance_of = [&](int b) {
    double r = 0.0;
    for (int s : topo_.incident_segments(h_.branches[b].id)) r = std::max(r, ends_[s].radius);
    // The node's breakout stubs leave it straight for the breakout length: a node as near a
    // part as its bundle allows has stubs that run into the part (nothing then rounds its
    // legs' corners), so it keeps the breakout too.
    return r + rep_.clearance + part_extra_ + breakout_length(topo_, h_.branches[b].id);
  };
  // Nodes of classes kept apart: each one's bundles and breakout runs keep the separation
  // from the other's, with the routing clearance between them.
  bpo.extra_gap = [&](int b, int o) {
    double gap = 0.0, rb = 0.0, ro = 0.0;
    for (int s : topo_.incident_segments(h_.branches[b].id)) {
      rb = std::max(rb, ends_[s].radius);
      for (int t : topo_.incident_segments(h_.branches[o].id)) {
        gap = std::max(gap, class_gap(scene_.routing, classes_[s], classes_[t]));
        ro = std::max(ro, ends_[t].radius);
      }
    }
    if (gap <= 0.0) return 0.0;
    return gap + rb + ro + rep_.clearance + breakout_length(topo_, h_.branches[b].id) +
           breakout_length(topo_, h_.branches[o].id);
  };
  for (const auto& id : place_branch_points(h_, topo_, *plan_index_, ends_, bpo))
    rep_.notes.push_back("branch point '" + id + "' placed by the router");
  exit_dir_ = branch_exit_directions(h_, topo_, ends_);
  for (const auto& br : h_.branches) breakout_[br.id] = breakout_length(topo_, br.id);
  const double clearance = rep_.clearance + part_extra_;
  if (const int turned = free_blocked_exits(*plan_index_, h_, topo_, ends_, breakout_, clearance, exit_dir_))
    rep_.notes.push_back(std::to_string(turned) + " branch exit(s) turned away from a part that blocked their run");
}

EndFrame RouteRun::end_frame(int seg, bool from_end) const {
  const Segment& sg = h_.segments[seg];
  EndFrame e;
  e.node = from_end ? sg.from : sg.to;
  e.position = *h_.node_position(e.node);
  if (int p = h_.find_port(e.node); p >= 0) {
    e.is_port = true;
    e.exit = h_.ports[p].direction;
  } else {
    e.exit = exit_dir_.at({seg, from_end});
  }
  return e;
}

/// Plans each segment in the patent's order (bundles by cable count, largest first).
void RouteRun::plan_segments() {
  box_ = scene_.bounds();
  extend_by_swept_envelopes(scene_.parts, swept_envelope_gap(rep_.clearance, h_.smallest_diameter()), box_);
  eps_ = 1e-9 * std::max(1.0, box_.diagonal());
  const auto& order = topo_.routing_order();
  seed_ompl_once(rep_.seed);
  ProgressCounter planned(opt_.progress, "plan", order.size(), "segments");
  for (std::size_t k = 0; k < order.size(); ++k, planned.add()) plan_segment(order[k], routed_now(order[k]));
  planned.finish();
  reorder_blocked();
}

/// Each end of segment `s` leaves straight along its exit direction: a port along the
/// connector axis for derived_stub_length(); a branch point along its breakout direction for
/// the breakout length (shortened if something is in the way). The planner starts at the
/// stub ends.
SegmentExits RouteRun::segment_exits(int s) const {
  SegmentExits x;
  x.ea = end_frame(s, true);
  x.eb = end_frame(s, false);
  x.radius = ends_[s].radius;
  x.required = rep_.clearance + part_extra_ + x.radius;
  const double required = x.required;
  // The parts each port end sits on, and how far along its exit they are excused: the
  // audit's straight exit (the shortest of the cables here: derived_stub_length of each),
  // and at least `required` and the slack (a port on a face leaving along its normal is
  // exactly `required` from the face there).
  x.attach_slack = kAttachSlackPerRadius * x.radius;
  const double attach_slack = x.attach_slack;
  double excused = std::numeric_limits<double>::infinity();
  for (int c : topo_.segment_cables(s))
    excused = std::min(excused, derived_stub_length(h_.cables[c].radius(), h_.cables[c].physical.min_bend_radius));
  excused = std::max(std::isfinite(excused) ? excused : 0.0, required + attach_slack);
  auto near_parts = [&](const EndFrame& e) {
    return e.is_port ? near_port_parts(*plan_index_, part_boxes_, planning_parts_, e.position, required, excused,
                                       required + attach_slack)
                     : std::vector<NearPart>{};
  };
  x.on_a = near_parts(x.ea);
  x.on_b = near_parts(x.eb);
  // A port on its connector leaves it straight until clear of it: at least `required` and
  // the slack twice, so that the planner starts clear of it.
  auto stub_for = [&](const EndFrame& e, const std::vector<NearPart>& on) {
    if (!e.is_port) return free_stub(*plan_index_, e.position, e.exit, breakout_.at(e.node), required);
    return on.empty() ? ends_[s].port_stub : std::max(ends_[s].port_stub, required + 2.0 * attach_slack);
  };
  // Stubs heading towards each other may together cover at most kStubShare of the way
  // between the ends; longer ones would cross and force the route into a hairpin. A stub
  // leaving sideways takes nothing from the way and is kept whole.
  double la = stub_for(x.ea, x.on_a), lb = stub_for(x.eb, x.on_b);
  const Vec3 a = x.ea.position, b = x.eb.position;
  const double span = (b - a).norm();
  if (span > 0.0) {
    const Vec3 u = (b - a) / span;
    const double eaten = la * std::max(0.0, x.ea.exit.dot(u)) + lb * std::max(0.0, -x.eb.exit.dot(u));
    if (eaten > kStubShare * span) {
      const double f = kStubShare * span / eaten;
      la *= f;
      lb *= f;
    }
  }
  x.a_stub = x.ea.position + la * x.ea.exit;
  x.b_stub = x.eb.position + lb * x.eb.exit;
  return x;
}

/// What the planner is asked for segment `s`: between the stub ends, with the routing and
/// the largest part clearance, seeded per segment.
PlanRequest RouteRun::plan_request(int s, const SegmentExits& x) const {
  const Vec3 a = x.ea.position, b = x.eb.position, a_stub = x.a_stub, b_stub = x.b_stub;
  PlanRequest req;
  req.radius = x.radius;
  req.clearance = rep_.clearance + part_extra_;
  req.min_bend_radius = ends_[s].min_bend_radius;
  req.stub_length = 0.0;
  req.scene_box = box_;
  req.scene_box.extend(a);
  req.scene_box.extend(b);
  req.planner = rep_.planner;
  req.seed = rep_.seed + static_cast<unsigned>(s);
  req.time_limit = time_limit_;
  req.max_iterations = rep_.iterations;
  if (scene_.routing.supports) {
    // Prefer ways a clamp can hold: within clamp_reach of the bundle surface from structure.
    req.objective.support_weight = scene_.routing.support_weight.value;
    req.objective.support_reach = x.radius + scene_.routing.clamp_reach.value;
    for (std::size_t q = 0; q < planning_parts_.size(); ++q) req.objective.part_supports.push_back(holds_clamp(q));
  }
  req.start = {a_stub, (b_stub - a_stub).norm() > 0 ? Vec3((b_stub - a_stub).normalized()) : Vec3::UnitX()};
  req.goal = {b_stub, (a_stub - b_stub).norm() > 0 ? Vec3((a_stub - b_stub).normalized()) : Vec3::UnitX()};
  return req;
}

/// Why an end of the segment cannot be left (message empty if both can): a branch point in
/// or too near a part (`branch_blocked` set), or a port that check_port_exit refuses.
PlanResult RouteRun::blocked_end(const SegmentExits& x, bool& branch_blocked) const {
  const EndFrame& ea = x.ea;
  const double radius = x.radius, required = x.required;
  PlanResult blocked;
  for (const EndFrame* e : {&x.ea, &x.eb}) {
    if (!blocked.message.empty()) continue;
    if (!e->is_port) {
      // A branch point the file fixed inside a part, or so near one that the bundle
      // itself would cut it: nothing the planner can do; the harness must move it.
      int part = -1;
      const bool in = plan_index_->inside(e->position, &part);
      const ClosestHit near = in ? ClosestHit{} : plan_index_->closest(e->position, radius);
      if (!in && !near.found()) continue;
      branch_blocked = true;
      blocked.reason = e == &ea ? NoPathReason::StartInObstacle : NoPathReason::GoalInObstacle;
      blocked.blocked_at = e->position;
      blocked.blocking_part = in ? part : near.part;
      blocked.message = "branch point " + e->node + " at " + full_precision(e->position) +
                        (in ? " is inside part '" + planning_parts_[part].name + "'"
                            : " is " + full_precision(near.distance) + " from part '" +
                                  planning_parts_[near.part].name + "', less than the bundle radius " +
                                  full_precision(radius));
      continue;
    }
    // The connector the port sits on may touch its exit over the excused run.
    const PortExit exit{"port " + e->node, e->position, e == &ea ? x.a_stub : x.b_stub, e == &ea,
                        e == &ea ? x.on_a : x.on_b, x.attach_slack};
    check_port_exit(*plan_index_, part_boxes_, exit, required,
                    [this](int part) { return planning_parts_[part].name; }, blocked);
  }
  return blocked;
}

/// Plans `req` among `index`; if that fails and parts ask for extra clearance, plans again
/// with the routing clearance alone (`req` keeps the clearance the kept plan used).
PlanResult RouteRun::plan_with_retry(const Segment& seg, const ObstacleIndex& index, PlanRequest& req,
                                     SegmentRouteInfo& info) {
  PlanResult plan = plan_one(index, req, info);
  info.time_limited = plan.time_limited;
  if (!plan.solved() && part_extra_ > 0.0) {
    // Per-part extra clearance is applied to every part while planning (conservative);
    // if that closes every corridor, plan with the routing clearance and let the audit
    // report where a part's own extra clearance is not met.
    req.clearance = rep_.clearance;
    PlanResult retry = plan_one(index, req, info);
    info.time_limited = info.time_limited || retry.time_limited;
    if (retry.solved()) {
      plan = retry;
      rep_.notes.push_back("segment " + seg.from + " -> " + seg.to +
                           ": planned with the routing clearance only (per-part extra clearance blocked it)");
    }
  }
  return plan;
}

/// One plan with the run's planner: the portfolio (its budgets kept in `info`) or one OMPL
/// planner.
PlanResult RouteRun::plan_one(const ObstacleIndex& index, const PlanRequest& req, SegmentRouteInfo& info) const {
  if (req.planner != kPortfolioPlanner) return plan_path(index, req);
  PortfolioOutcome out = plan_portfolio(index, req);
  PlanResult plan = out.plan;
  info.portfolio = std::move(out);
  return plan;
}

/// The segments routed so far but `except` (whose bundles the next plan avoids); none when
/// planning is not harness-aware.
std::vector<int> RouteRun::routed_now(int except) const {
  std::vector<int> out;
  if (!opt_.harness_aware) return out;
  for (const auto& kv : tubes_)
    if (kv.first != except) out.push_back(kv.first);
  return out;
}

/// The planning obstacles of segment `s`: the parts and the bundle of every segment in
/// `visible`, each cut back near a node the two share (there they meet legitimately: within
/// the audit's junction reach, twice the breakout, and at least far enough that the breakout
/// stubs leave clear of each other). Bundles of classes kept apart from the segment's are grown
/// by the separation (class_gap). The breakouts of segments still to be routed are obstacles
/// too, cut back alike.
std::unique_ptr<HarnessAwareIndex> RouteRun::obstacles_for(int s, const std::vector<int>& visible) const {
  const Segment& sg = h_.segments[s];
  const double required = ends_[s].radius + rep_.clearance + part_extra_;
  std::vector<BundleTube> tubes;
  // Segment t's run as an obstacle, cut back near a node it shares with s.
  auto add = [&](int t, const std::vector<Vec3>& points, double radius) {
    const Segment& st = h_.segments[t];
    std::vector<std::vector<Vec3>> runs{points};
    for (const std::string& n : {sg.from, sg.to}) {
      if (n != st.from && n != st.to) continue;
      const double breakout = breakout_length(topo_, n);
      const double reach = std::max(2.0 * breakout, breakout + required + radius);
      const Vec3 at = *h_.node_position(n);
      std::vector<std::vector<Vec3>> kept;
      for (const auto& r : runs)
        for (auto& piece : clip_near_node(r, at, reach)) kept.push_back(std::move(piece));
      runs = std::move(kept);
    }
    for (auto& r : runs) tubes.push_back({t, std::move(r), radius});
  };
  for (int t : visible) {
    const auto found = tubes_.find(t);
    if (t == s || found == tubes_.end()) continue;
    // A bundle of another class grows by the classes' separation: the planner then keeps the
    // routing clearance beyond it, the margin for the curve's deviation from the key points.
    add(t, found->second.points, found->second.radius + class_gap(scene_.routing, classes_[s], classes_[t]));
  }
  // The breakouts of segments not routed yet at branch points: their straight runs from the
  // node will be there (a route through a node of others' would leave their legs no start),
  // grown like bundles by the separation of their classes.
  if (opt_.harness_aware)
    for (const auto& [key, exit] : exit_dir_) {
      const int t = key.first;
      if (t == s || tubes_.count(t)) continue;
      const std::string& n = key.second ? h_.segments[t].from : h_.segments[t].to;
      const Vec3 at = *h_.node_position(n);
      add(t, {at, at + breakout_.at(n) * exit}, ends_[t].radius + class_gap(scene_.routing, classes_[s], classes_[t]));
    }
  return std::make_unique<HarnessAwareIndex>(planning_index(), tubes);
}

/// Keeps the bundle of planned segment `s` as an obstacle for the segments planned after it:
/// its curve as build_curve will make it, sampled every bundle radius, the radius grown by
/// the chord sag of that sampling at the bend radius.
void RouteRun::add_bundle_tube(int s) {
  const SegmentGeometry& g = geom_.at(s);
  const double radius = ends_[s].radius, bend = ends_[s].min_bend_radius;
  Centerline curve;
  if (bend > 0.0) {
    const auto obstacles = obstacles_for(s, g.visible);
    curve = round_corners(s, g, *obstacles).curve;
  } else {
    curve = Centerline::interpolate(g.points, g.interp);
  }
  const double step = std::max(radius, 1e-6 * std::max(1.0, box_.diagonal()));
  BundleTube tube;
  tube.segment = s;
  for (const auto& sp : curve.sample_by_arc_length(step)) tube.points.push_back(sp.second);
  tube.radius = radius + step * step / (8.0 * std::max(bend, radius));
  tubes_[s] = std::move(tube);
}

/// What blocked the plan of segment `s`, for its message: a part by name or the bundle of a
/// segment (with the separation of their classes where it grew that bundle).
std::string RouteRun::blocker_name(const ObstacleIndex& index, int part, int s) const {
  if (part >= 0 && part < static_cast<int>(planning_parts_.size())) return "part '" + planning_parts_[part].name + "'";
  const auto* aware = dynamic_cast<const HarnessAwareIndex*>(&index);
  const int t = aware ? aware->bundle_segment(part) : -1;
  if (t < 0) return "";
  if (!tubes_.count(t))
    return "the breakout of segment " + h_.segments[t].from + " -> " + h_.segments[t].to + ", routed after it";
  const double gap = class_gap(scene_.routing, classes_[s], classes_[t]);
  return "the bundle of segment " + h_.segments[t].from + " -> " + h_.segments[t].to + ", routed before it" +
         (gap > 0.0 ? ", kept " + full_precision(gap) + " away by the separation of their classes" : "");
}

/// One entry per cable through segment `s`: the first segment (in routing order) that
/// stopped it.
void RouteRun::record_unrouted(int s, const PlanResult& plan, bool branch_blocked) {
  const Segment& seg = h_.segments[s];
  failed_segments_.insert(seg.from + " -> " + seg.to);
  for (int c : topo_.segment_cables(s))
    if (std::none_of(rep_.unrouted.begin(), rep_.unrouted.end(),
                     [&](const UnroutedCable& u) { return u.cable == h_.cables[c].id; }))
      rep_.unrouted.push_back({h_.cables[c].id, seg.from + " -> " + seg.to,
                               branch_blocked ? "branch_blocked" : reason_name(plan.reason), plan.message});
}

/// Plans segment `s` (unless the input already has its path or spline) and keeps its
/// key-point polyline, or records why its cables have no route.
void RouteRun::plan_segment(int s, const std::vector<int>& visible) {
  const Segment& seg = h_.segments[s];
  SegmentRouteInfo info;
  info.segment = s;
  if (seg.bspline || !seg.path.empty()) {
    info.kept_from_input = true;
    store_info(info);
    return;
  }
  const SegmentExits x = segment_exits(s);
  PlanRequest req = plan_request(s, x);
  bool branch_blocked = false;
  const PlanResult blocked = blocked_end(x, branch_blocked);
  const Stopwatch t0;
  const auto obstacles = obstacles_for(s, visible);
  PlanResult plan;
  if (!blocked.message.empty()) {
    plan = blocked;
  } else if ((x.b_stub - x.a_stub).norm() <= eps_) {  // nothing to plan (and plan_path refuses equal ends)
    plan.status = PlanStatus::Solved;
    plan.key_points = {x.a_stub, x.b_stub};
  } else {
    plan = plan_with_retry(seg, *obstacles, req, info);
  }
  rep_.timing.plan += t0.ms();
  if (!plan.solved() && plan.blocking_part >= 0) {
    const std::string who = blocker_name(*obstacles, plan.blocking_part, s);
    if (!who.empty() && plan.message.find(who) == std::string::npos) plan.message += " (" + who + ")";
    if (const int t = obstacles->bundle_segment(plan.blocking_part); t >= 0) blocked_by_[s] = t;
  }
  info.plan = plan;
  if (!plan.solved()) {
    branch_blocked_[s] = branch_blocked;
    record_unrouted(s, plan, branch_blocked);
    store_info(info);
    return;
  }
  info.planned = true;
  if (scene_.routing.supports) info.support_points = pull_to_supports(*obstacles, x, plan.key_points);
  SegmentGeometry g;
  g.a = x.ea.position;
  g.a_stub = x.a_stub;
  g.b_stub = x.b_stub;
  g.b = x.eb.position;
  g.request = req;
  g.interp.start_tangent = x.ea.exit;
  g.interp.end_tangent = -x.eb.exit;
  g.visible = visible;
  set_planned_points(s, g, plan.key_points, *obstacles);
  geom_[s] = g;
  add_bundle_tube(s);
  store_info(info);
}

/// Sets the key-point polyline of segment `s` (node to node) from the planner's key points,
/// and g.arc_points, their corners rounded by arcs of the bend radius (with margin) when
/// those fit clear: build_curve uses them if the bend repair of the polyline fails.
void RouteRun::set_planned_points(int s, SegmentGeometry& g, const std::vector<Vec3>& key_points,
                                  const ObstacleIndex& index) const {
  g.points = assemble(g, key_points, eps_);
  g.arc_points.clear();
  const std::optional<ArcLineEnds> ends = arc_line_ends(s, g);
  if (!ends) return;
  const std::vector<Vec3> corners(g.points.begin() + 1, g.points.end() - 1);  // stub end to stub end
  const double radius = kBendPlanMargin * ends_[s].min_bend_radius;
  if (!arcs_fit(index, corners, *ends, radius, g.request.radius + g.request.clearance)) return;
  g.arc_points = {g.a};
  for (const Vec3& p : arc_line_points(corners, *ends, radius, 0.0)) g.arc_points.push_back(p);
  g.arc_points.push_back(g.b);
  g.arc_points = dedupe_consecutive(g.arc_points, eps_);
}

/// The stubs of segment `s` as an arc-line route sees them, when its cables have a bend
/// radius and both ends have a stub (without one the headings are the curve's end tangents
/// at the nodes themselves, which the bend repair handles).
std::optional<ArcLineEnds> RouteRun::arc_line_ends(int s, const SegmentGeometry& g) const {
  if (!(ends_[s].min_bend_radius > 0.0) || (g.a_stub - g.a).norm() <= eps_ || (g.b - g.b_stub).norm() <= eps_ ||
      g.points.size() < 4 || !g.interp.start_tangent || !g.interp.end_tangent)
    return std::nullopt;
  ArcLineEnds ends;
  ends.start_heading = *g.interp.start_tangent;
  ends.start_run = (g.a_stub - g.a).norm();
  ends.end_heading = *g.interp.end_tangent;
  ends.end_run = (g.b - g.b_stub).norm();
  return ends;
}

/// Plans segment `s` bend-feasibly (bend_planner) around the corridor of its current key
/// points; on success its corners, pulled to supports where the scene asks for clamps,
/// rounded by their arcs become the segment's key points (the polyline itself where a pull
/// leaves corners no arc fits; the bend repair then rounds it). The outcome is kept in `info`.
bool RouteRun::bend_plan(int s, SegmentGeometry& g, const ObstacleIndex& index, SegmentRouteInfo& info) const {
  const std::optional<ArcLineEnds> ends = arc_line_ends(s, g);
  if (!ends) return false;
  const double radius = kBendPlanMargin * ends_[s].min_bend_radius;
  const double required = g.request.radius + g.request.clearance;
  if (!((g.b_stub - g.a_stub).norm() > kBendPlanSamePoint * required)) return false;  // nothing between the stubs
  BendPlanRequest bq;
  bq.start = g.a_stub;
  bq.goal = g.b_stub;
  bq.ends = *ends;
  bq.required = required;
  bq.bend_radius = radius;
  bq.bounds = g.request.scene_box;
  for (const Vec3& p : {g.a, g.a_stub, g.b_stub, g.b}) bq.bounds.extend(p);
  bq.bounds = bq.bounds.inflated(2.0 * radius + required);
  bq.hint.assign(g.points.begin() + 1, g.points.end() - 1);
  bq.seed = g.request.seed ^ kBendPlanSeedSalt;
  const PortfolioBudget budget = portfolio_budget(g.request);
  bq.time_limit = budget.feasibility_seconds;
  bq.max_iterations = std::max(budget.feasibility_iterations, kBendPlanSamples);
  const BendPlanResult r = plan_bend_feasible(index, bq);
  info.bend_plan = r.solved() ? "planned" : "failed: " + r.message;
  info.bend_plan_samples = r.iterations;
  info.bend_plan_ms = r.time_ms;
  info.time_limited = info.time_limited || r.time_limited;
  if (!r.solved()) return false;
  std::vector<Vec3> corners = r.vertices;
  if (scene_.routing.supports) pull_to_supports(index, segment_exits(s), corners);
  set_planned_points(s, g, corners, index);
  // The arcs were checked clear; the bend repair's fairing may move the curve by up to half
  // the bend radius and would give that up. They are lost only where a support pull broke them.
  if (!g.arc_points.empty()) g.points = std::move(g.arc_points);
  g.arc_points.clear();
  return true;
}

/// Replaces the key points of segment `s`, whose bend repair failed, by a bend-feasible plan
/// around them, kept only if its curve then meets the bend radius. The plan's outcome goes
/// into the segment's route info either way. Returns whether the bend radius is met.
bool RouteRun::try_bend_plan(int s) {
  SegmentGeometry& g = geom_.at(s);
  const SegmentGeometry saved = g;
  SegmentRouteInfo& info = info_of(s);
  const bool planned = bend_plan(s, g, *obstacles_for(s, g.visible), info);
  rep_.timing.plan += info.bend_plan_ms;
  if (!planned) return false;
  build_curve(s);
  if (!bend_failed(s)) {
    if (tubes_.count(s)) add_bundle_tube(s);  // the bundles re-planned after it avoid the new route
    return true;
  }
  g = saved;
  build_curve(s);
  return false;
}

/// Records how segment `s` was routed: replaces its entry (a re-plan) or appends one.
void RouteRun::store_info(const SegmentRouteInfo& info) {
  for (auto& i : rep_.segments)
    if (i.segment == info.segment) {
      i = info;
      return;
    }
  rep_.segments.push_back(info);
}

/// Inserts key points into `key_points` (stub end to stub end) where the route runs longer
/// than clamp_spacing out of clamp reach of structure (pull_to_structure), clear of what
/// `index` holds (the parts and the bundles routed so far; bundles carry no clamp); returns
/// how many.
int RouteRun::pull_to_supports(const ObstacleIndex& index, const SegmentExits& x, std::vector<Vec3>& key_points) const {
  SupportPullSettings ps;
  ps.spacing = scene_.routing.clamp_spacing.value;
  ps.reach = x.radius + scene_.routing.clamp_reach.value;
  ps.required = x.required;
  if (!(ps.reach > ps.required)) return 0;  // no stand-off between clearance and reach to aim at
  ps.start_is_port = x.ea.is_port;
  ps.end_is_port = x.eb.is_port;
  for (std::size_t q = 0; q < planning_parts_.size(); ++q) ps.part_supports.push_back(holds_clamp(q));
  SupportPullResult pulled = pull_to_structure(index, key_points, ps);
  key_points = std::move(pulled.points);
  return pulled.inserted;
}

/// Re-plans routed segment `t` among the bundles of `visible` (its request as first
/// planned); on success its key points, bundle and route info are replaced. False (nothing
/// changed) if it finds no route.
bool RouteRun::replan_among(int t, const std::vector<int>& visible) {
  SegmentGeometry& g = geom_.at(t);
  PlanRequest req = g.request;
  SegmentRouteInfo info;
  info.segment = t;
  const Stopwatch t0;
  const auto obstacles = obstacles_for(t, visible);
  const PlanResult plan = plan_with_retry(h_.segments[t], *obstacles, req, info);
  rep_.timing.plan += t0.ms();
  if (!plan.solved()) return false;
  g.request = req;
  g.visible = visible;
  g.points = assemble(g, plan.key_points, eps_);
  info.plan = plan;
  info.planned = true;
  store_info(info);
  add_bundle_tube(t);
  return true;
}

/// Where the routing order was wrong for a segment: one blocked by the bundle of a segment
/// routed before it is planned again among every other routed bundle, and the blocker is
/// re-planned around it. Both plans are kept only if both succeed; otherwise the first plan
/// and its diagnosis stand. The unrouted cables are then recounted in routing order.
void RouteRun::reorder_blocked() {
  bool changed = false;
  for (const auto& [s, t] : std::map<int, int>(blocked_by_)) {
    if (geom_.count(s) || !geom_.count(t)) continue;
    const SegmentRouteInfo saved = info_of(s);
    std::vector<int> without_t = routed_now(s);
    without_t.erase(std::remove(without_t.begin(), without_t.end(), t), without_t.end());
    plan_segment(s, without_t);
    if (geom_.count(s) && replan_among(t, routed_now(t))) {
      changed = true;
      rep_.notes.push_back("segment " + h_.segments[s].from + " -> " + h_.segments[s].to +
                           " was blocked by the bundle of segment " + h_.segments[t].from + " -> " +
                           h_.segments[t].to + ": planned before it, which was re-planned around it");
      continue;
    }
    geom_.erase(s);
    tubes_.erase(s);
    store_info(saved);
  }
  if (!changed) return;
  rep_.unrouted.clear();
  failed_segments_.clear();
  for (const auto& info : rep_.segments)
    if (!info.planned && !info.kept_from_input) record_unrouted(info.segment, info.plan, branch_blocked_[info.segment]);
}

/// Rounds the corners of segment `s` as far as the planning obstacles allow: tries the
/// budgets from generous (a corner rounded to the full bend radius moves up to ~0.4 R) to
/// tight, and keeps the first repaired curve whose samples stay clear of the (simplified)
/// parts, else the last tried; the exact audit that follows is the judge.
BendRepairResult RouteRun::round_corners(int s, const SegmentGeometry& g, const ObstacleIndex& index) const {
  const double min_bend = ends_[s].min_bend_radius;
  const double radius = ends_[s].radius;
  const double need = radius + 0.5 * rep_.clearance;
  const double step = std::max(radius, 0.25 * rep_.clearance);
  BendRepairResult chosen;
  bool have = false;
  for (double dev : {0.5 * min_bend, 0.25 * min_bend, rep_.clearance, 0.5 * rep_.clearance}) {
    if (!(dev > 0.0)) continue;
    BendRepairOptions bo;
    bo.min_bend_radius = min_bend;
    bo.max_deviation = dev;
    bo.interpolation = g.interp;
    BendRepairResult br = repair_bend_radius(g.points, bo);
    bool clear = true;
    for (const auto& [sa, p] : br.curve.sample_by_arc_length(step)) {
      (void)sa;
      if (index.any_within(p, need) && (p - g.points.front()).norm() > need &&
          (p - g.points.back()).norm() > need) {
        clear = false;
        break;
      }
    }
    if (clear && br.status != BendRepairStatus::Failed) {
      chosen = std::move(br);
      have = true;
      break;
    }
    if (!have) chosen = std::move(br);
  }
  return chosen;
}

/// The curve of segment `s` through its key points (bend-radius repaired when the cables
/// have a bend radius), written into the harness with its status.
void RouteRun::build_curve(int s) {
  SegmentGeometry& g = geom_[s];
  std::string status = "not checked";
  if (ends_[s].min_bend_radius > 0.0) {
    BendRepairResult chosen = round_corners(s, g, *obstacles_for(s, g.visible));
    if (chosen.status == BendRepairStatus::Failed && !g.arc_points.empty()) {
      // The planned corners fit arcs of the bend radius (with margin): use those.
      g.points = std::move(g.arc_points);
      g.arc_points.clear();
      chosen = round_corners(s, g, *obstacles_for(s, g.visible));
    }
    g.curve = chosen.curve;
    g.points = chosen.points.empty() ? g.points : chosen.points;
    status = chosen.status == BendRepairStatus::Failed ? "failed: " + chosen.reason
             : chosen.status == BendRepairStatus::AlreadySatisfied ? "satisfied"
             : chosen.status == BendRepairStatus::Faired ? "faired"
                                                         : "points inserted";
  } else {
    g.curve = Centerline::interpolate(g.points, g.interp);
  }
  Segment& seg = h_.segments[s];
  seg.path.assign(g.points.begin() + 1, g.points.end() - 1);
  seg.interp = Interp::BSpline;
  seg.bspline = to_bspline(g.curve);
  for (auto& info : rep_.segments)
    if (info.segment == s) info.key_points = seg.path.size(), info.bend_status = status;
}

/// Splines of every planned segment: bend-radius repair within half the clearance margin.
void RouteRun::build_splines() {
  const Stopwatch t0;
  for (auto& [s, g] : geom_) build_curve(s);
  rep_.timing.spline = t0.ms();
}

SegmentRouteInfo& RouteRun::info_of(int s) {
  return *std::find_if(rep_.segments.begin(), rep_.segments.end(),
                       [s](const SegmentRouteInfo& i) { return i.segment == s; });
}

bool RouteRun::bend_failed(int s) { return info_of(s).bend_status.rfind("failed", 0) == 0; }

/// A segment whose corners cannot be rounded within what the obstacles allow is planned
/// bend-feasibly around its corridor (try_bend_plan); if that fails it is re-planned (another
/// seed, twice the budget, up to kBendReplans times), each re-plan planned bend-feasibly in
/// turn where its own corners cannot be rounded; new key points are kept only if their curve
/// meets the bend radius.
void RouteRun::replan_bend_failures() {
  // Every segment is planned now: what changes from here on (bend-feasible plans, re-plans,
  // the audit's densified curves) keeps clear of every other bundle, not only of those
  // routed before it (the later ones were planned around its old route).
  for (auto& [s, g] : geom_) {
    g.planned_among = g.visible;
    g.visible = routed_now(s);
  }
  for (auto& [s, g] : geom_) {
    // Stub ends that coincide leave nothing to re-plan (and plan_path refuses equal ends).
    if ((g.b_stub - g.a_stub).norm() <= eps_ || !bend_failed(s)) continue;
    try_bend_plan(s);
    for (int attempt = 1; attempt <= kBendReplans && bend_failed(s); ++attempt) {
      PlanRequest req = g.request;
      req.seed = g.request.seed + 7919u * static_cast<unsigned>(attempt);
      req.time_limit = g.request.time_limit * std::pow(2.0, attempt);
      req.max_iterations = g.request.max_iterations << attempt;  // twice the budget, as the time
      const Stopwatch t0;
      SegmentRouteInfo scratch;
      const PlanResult plan = plan_one(*obstacles_for(s, g.visible), req, scratch);
      rep_.timing.plan += t0.ms();
      // Whether the re-plan is kept depends on its result: a timed-out one makes the segment
      // irreproducible either way.
      info_of(s).time_limited = info_of(s).time_limited || plan.time_limited;
      if (!plan.solved()) continue;
      const SegmentGeometry saved = g;
      const SegmentRouteInfo saved_info = info_of(s);
      set_planned_points(s, g, plan.key_points, *obstacles_for(s, g.visible));
      info_of(s).bend_plan.clear();
      build_curve(s);
      if (bend_failed(s)) try_bend_plan(s);
      if (bend_failed(s)) {
        g = saved;
        build_curve(s);
        const bool timed = info_of(s).time_limited;
        info_of(s) = saved_info;
        info_of(s).time_limited = timed;
      } else {
        info_of(s).plan = plan;
        info_of(s).portfolio = scratch.portfolio;
        info_of(s).replans = attempt;
        if (tubes_.count(s)) add_bundle_tube(s);
      }
    }
    // Last, among the bundles routed before it only, as it was first planned: the bundles
    // planned after it went around its old route and may still leave a new one room. The
    // audit judges what it passes near; the segment keeps that view from here on.
    if (bend_failed(s) && g.planned_among.size() < g.visible.size()) {
      std::vector<int> all = std::move(g.visible);
      g.visible = g.planned_among;
      if (try_bend_plan(s))
        rep_.notes.push_back("segment " + h_.segments[s].from + " -> " + h_.segments[s].to +
                             ": bend-feasible only among the bundles routed before it; the audit judges the later ones");
      else
        g.visible = std::move(all);
    }
  }
}

/// The exact audit of the harness as routed so far. Cables that could not be routed have no
/// curve to audit (their segments would read as straight lines between the nodes); they are
/// reported as unrouted instead.
AuditReport RouteRun::audit_now() {
  routed_scene_.harness = h_;
  auto& cables = routed_scene_.harness.cables;
  cables.erase(std::remove_if(cables.begin(), cables.end(),
                              [&](const Cable& c) {
                                return std::any_of(rep_.unrouted.begin(), rep_.unrouted.end(),
                                                   [&](const UnroutedCable& u) { return u.cable == c.id; });
                              }),
               cables.end());
  return run_audit(routed_scene_, audit_options_);
}

/// Segments (that this run routed) hit by a clash or clearance violation of any cable in
/// the last audit.
std::set<int> RouteRun::segments_to_repair() const {
  std::set<int> bad;
  auto mark = [&](int check_index, double s_at) {
    const int c = h_.find_cable(rep_.audit.check_ids[check_index]);
    if (c < 0) return;
    const auto pieces = cable_pieces(topo_, c);
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      const bool last = k + 1 == pieces.size();
      if (last || s_at < pieces[k + 1].s0) {
        if (geom_.count(pieces[k].segment)) bad.insert(pieces[k].segment);
        return;
      }
    }
  };
  for (const auto& cl : rep_.audit.result.clashes) {
    mark(cl.cable, cl.s);
    if (cl.kind != ClashKind::CableStructure && cl.other >= 0) mark(cl.other, cl.s_other);
  }
  for (const auto& v : rep_.audit.result.violations)
    if (v.kind == ViolationKind::Clearance) mark(v.cable, v.s);
  for (const auto& m : rep_.audit.motion.clashes) mark(m.cable, m.s);
  return bad;
}

/// Exact audit against the real parts, then rounds that densify the key points of every
/// segment whose curve clashes or crowds and audit again. The exact index is built once: the
/// planning index when planning used the exact parts.
void RouteRun::audit_and_repair() {
  Stopwatch t0;
  if (plan_on_other_parts_) exact_owned_ = std::make_unique<EmbreeIndex>(scene_.parts);
  audit_options_.check.threads = opt_.threads;
  audit_options_.progress = opt_.progress;
  audit_options_.index = exact_owned_ ? exact_owned_.get() : plan_index_.get();
  rep_.timing.index += t0.ms();
  routed_scene_.name = scene_.name;
  routed_scene_.units = scene_.units;
  routed_scene_.routing = scene_.routing;
  routed_scene_.has_harness = true;
  routed_scene_.parts = scene_.parts;
  t0.restart();
  rep_.audit = audit_now();
  rep_.timing.audit = t0.ms();
  t0.restart();
  for (int round = 0; round < opt_.max_repair_rounds; ++round) {
    const std::set<int> bad = segments_to_repair();
    if (bad.empty()) break;
    for (int s : bad) {
      geom_[s].points = densify(geom_[s].points);
      geom_[s].arc_points.clear();
      build_curve(s);
      // Denser key points leave the bend repair shorter legs: plan the corners bend-feasibly
      // around them where it fails.
      if (bend_failed(s)) try_bend_plan(s);
      for (auto& info : rep_.segments)
        if (info.segment == s) info.repair_rounds = round + 1;
    }
    rep_.audit = audit_now();
  }
  rep_.timing.repair = t0.ms();
  for (const auto& f : failed_segments_) rep_.notes.push_back("segment " + f + " could not be routed");
  if (scene_.routing.supports && audit_options_.index) place_supports();
}

/// Replaces the clamps an earlier run placed by clamps along the final curves
/// (place_clamps), and audits the supports again with them (the rest of the audit does not
/// depend on clamps).
void RouteRun::place_supports() {
  const Stopwatch t0;
  const double spacing = scene_.routing.clamp_spacing.value, reach = scene_.routing.clamp_reach.value;
  h_.clamps.erase(std::remove_if(h_.clamps.begin(), h_.clamps.end(), [](const Clamp& c) { return c.placed; }),
                  h_.clamps.end());
  const ClampPlacement placed = place_clamps(h_, scene_.parts, *audit_options_.index, spacing, reach);
  h_.clamps.insert(h_.clamps.end(), placed.clamps.begin(), placed.clamps.end());
  rep_.clamps_placed = placed.clamps.size();
  rep_.share_within_reach = placed.share_within_reach();
  routed_scene_.harness.clamps = h_.clamps;  // audit_now keeps every segment, so indices hold
  rep_.audit.supports = audit_supports(routed_scene_.harness, scene_.parts, *audit_options_.index, spacing, reach, true);
  rep_.timing.audit += t0.ms();
}

/// Says why another run with the same seed may give other routes (RouteReport::unreproducible,
/// also appended to the notes).
void RouteRun::note_reproducibility() {
  if (rep_.iterations == 0)
    rep_.unreproducible.push_back("no iteration budget: the planners stop on the time limit and on time-based "
                                  "convergence, so another run may give other routes (set --iterations or "
                                  "[routing] iterations)");
  else if (rep_.planner != kPortfolioPlanner && planner_is_threaded(rep_.planner))
    rep_.unreproducible.push_back("planner " + rep_.planner +
                                  " grows its roadmap in a second thread: its routes are not reproducible, "
                                  "even with an iteration budget");
  if (rep_.iterations > 0)
    for (const auto& info : rep_.segments)
      if (info.time_limited) {
        const Segment& sg = h_.segments[info.segment];
        rep_.unreproducible.push_back("segment " + sg.from + " -> " + sg.to + ": the time limit (" +
                                      full_precision(time_limit_) + " s per plan) ended planning before " +
                                      std::to_string(rep_.iterations) +
                                      " iterations: its route is not reproducible (raise the time limit or lower "
                                      "the iterations)");
      }
  for (const auto& n : rep_.unreproducible) rep_.notes.push_back(n);
}

/// Compares each routed segment with the nominal length its file gives: a note for every
/// one longer by more than kNominalLengthTolerance, and one for the totals.
void RouteRun::note_nominal_lengths() {
  const char* u = unit_name(scene_.units);
  auto fixed1 = [](double v) {  // lengths and percentages to 0.1: what a cut length needs
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.1f", v);
    return std::string(buf);
  };
  auto over = [&](double len, double nom) { return (len >= nom ? "+" : "") + fixed1(100.0 * (len - nom) / nom) + "%"; };
  const std::string tol = fixed1(100.0 * kNominalLengthTolerance) + "%";
  double routed = 0.0, nominal = 0.0;
  int compared = 0, longer = 0;
  for (const Segment& sg : h_.segments) {
    if (!sg.nominal_length || !sg.bspline) continue;
    const double len = Centerline(sg.bspline->degree, sg.bspline->knots, sg.bspline->control_points).length();
    routed += len;
    nominal += *sg.nominal_length;
    ++compared;
    if (len <= (1.0 + kNominalLengthTolerance) * *sg.nominal_length) continue;
    ++longer;
    rep_.notes.push_back("segment " + sg.from + " -> " + sg.to + ": routed " + fixed1(len) + " " + u + ", nominal " +
                         fixed1(*sg.nominal_length) + " " + u + " (" + over(len, *sg.nominal_length) +
                         ", beyond the " + tol + " tolerance)");
  }
  if (compared)
    rep_.notes.push_back("nominal lengths: " + std::to_string(compared) + " segments routed " + fixed1(routed) + " " + u +
                         " in total against " + fixed1(nominal) + " " + u + " nominal (" + over(routed, nominal) + "); " +
                         std::to_string(longer) + " longer than nominal by more than " + tol);
}

}  // namespace

RouteReport route_scene(const Scene& scene, const RouteOptions& opt) { return RouteRun(scene, opt).run(); }

}  // namespace loom
