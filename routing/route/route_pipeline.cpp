#include "routing/route/route_pipeline.hpp"

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "index/box_tree.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/clash_check.hpp"
#include "routing/curve/bend_repair.hpp"
#include "routing/route/branch_layout.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>

namespace loom {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

/// The straight stubs at both ends of a segment may eat at most this share of the way
/// between its ends (the part of each stub that heads towards the other end).
constexpr double kStubShare = 0.5;

/// Re-plans of a segment whose bend repair failed: each with a fresh seed and twice the
/// previous budget; the first whose curve meets the bend radius is kept.
constexpr int kBendReplans = 2;

/// Slack of the port-exit checks, as a share of the tube radius (the audit's default
/// tolerance, r/100): the exit is checked not to enter the part its port sits on from this far
/// off the port; an exit on a part runs at least `required` plus twice this, so that the
/// planner starts clear of it; a keep-out zone near a port is measured from `required` plus
/// this. A port on a face leaving along the normal is exactly `required` from the face at
/// `required`: rounding must not make that face a wall.
constexpr double kAttachSlackPerRadius = 0.01;

/// A segment's key-point polyline and the curve through it.
struct SegmentGeometry {
  std::vector<Vec3> points;  ///< from-node, interior key points, to-node
  InterpolationOptions interp;
  Centerline curve;
  Vec3 a, a_stub, b_stub, b;  ///< the ends and their stub ends, as planned
  PlanRequest request;        ///< what the planner was asked (for re-planning)
};


/// Removes consecutive points closer than `eps`.
std::vector<Vec3> dedupe(const std::vector<Vec3>& pts, double eps) {
  std::vector<Vec3> out;
  for (const auto& p : pts)
    if (out.empty() || (p - out.back()).norm() > eps) out.push_back(p);
  if (out.size() == 1 && pts.size() > 1) out.push_back(pts.back());
  return out;
}

/// The key-point polyline of a segment: node, stub end, the planner's interior key points,
/// stub end, node; coincident points removed.
std::vector<Vec3> assemble(const SegmentGeometry& g, const std::vector<Vec3>& key_points, double eps) {
  std::vector<Vec3> pts{g.a, g.a_stub};
  pts.insert(pts.end(), key_points.begin(), key_points.end());
  pts.push_back(g.b_stub);
  pts.push_back(g.b);
  return dedupe(pts, eps);
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

/// A part whose surface comes within the tube's required distance of a port, and how far
/// along the port's straight exit the cable may run closer to it than that.
struct NearPart {
  int part = -1;
  double excused = 0.0;  ///< scene units along the exit from the port
};

/// The parts near a port. One the port sits on (its connector: any part but a keep-out zone,
/// DESIGN / README "Attached parts") is excused over `excused_on` — the audit does not check
/// the cable against it over the port's straight exit; a keep-out zone never is, but its
/// first `excused_near` cannot be helped (the audit reports it).
std::vector<NearPart> near_port_parts(const ObstacleIndex& index, const std::vector<AABB>& part_boxes,
                                      const std::vector<Part>& parts, const Vec3& port, double required,
                                      double excused_on, double excused_near) {
  std::vector<NearPart> near;
  for (std::size_t q = 0; q < parts.size(); ++q)
    if (part_boxes[q].inflated(required).contains(port) &&
        index.closest_on_part(port, static_cast<int>(q), required).found())
      near.push_back({static_cast<int>(q), parts[q].role == PartRole::KeepOut ? excused_near : excused_on});
  return near;
}

/// The nearest part that the straight exit port → stub_end comes within `required` of
/// (found() == false if none). A part near the port is measured only past its excused run,
/// and over that run (from `lift` off the port, where the port's own surface is left behind)
/// it must not be entered; every other part is measured over the whole exit. An exit lifted
/// off the port inside a part meets it at distance 0 there.
ClosestHit exit_obstacle(const ObstacleIndex& index, const std::vector<AABB>& part_boxes, const Vec3& port,
                         const Vec3& stub_end, const std::vector<NearPart>& near, double lift, double required) {
  ClosestHit best;
  const double len = (stub_end - port).norm();
  if (!(len > 0.0)) return best;
  const Vec3 dir = (stub_end - port) / len;
  // Lifted off the port, the exit must be outside every part (a segment that starts inside
  // a part need not touch its surface).
  const Vec3 lifted = port + std::min(lift, len) * dir;
  int inside_part = -1;
  if (index.inside(lifted, &inside_part)) {
    best.distance = 0.0;
    best.point = lifted;
    best.part = inside_part;
    return best;
  }
  AABB exit_box;
  exit_box.extend(port);
  exit_box.extend(stub_end);
  auto measure = [&](int q, double from, double to, double need) {
    if (!(to > from)) return;
    const ClosestHit hit = index.segment_closest_on_part(port + from * dir, port + to * dir, q, need);
    if (hit.found() && hit.distance <= best.distance) best = hit;
  };
  for (std::size_t q = 0; q < part_boxes.size(); ++q) {
    if (!boxes_overlap(exit_box.inflated(required), part_boxes[q])) continue;
    const int id = static_cast<int>(q);
    const auto it = std::find_if(near.begin(), near.end(), [id](const NearPart& n) { return n.part == id; });
    if (it == near.end()) {
      measure(id, 0.0, len, required);
    } else {
      const double excused = std::min(it->excused, len);
      measure(id, std::min(lift, len), excused, 0.0);  // not into it
      measure(id, excused, len, required);
    }
  }
  return best;
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

}  // namespace

RouteReport route_scene(const Scene& scene, const RouteOptions& opt) {
  const auto t_total = Clock::now();
  RouteReport rep;
  rep.routed = scene.harness;
  Harness& h = rep.routed;
  const HarnessTopology topo(h);  // ids and structure never change below, only geometry
  rep.planner = opt.planner.empty() ? scene.routing.planner : opt.planner;
  rep.seed = opt.seed >= 0 ? static_cast<unsigned>(opt.seed) : scene.routing.seed;
  const double time_limit = opt.time_limit >= 0 ? opt.time_limit : scene.routing.time_limit.value;
  rep.iterations = opt.iterations >= 0 ? static_cast<std::uint64_t>(opt.iterations)
                                       : static_cast<std::uint64_t>(scene.routing.iterations.value);
  rep.clearance = scene.routing.clearance.value;
  refuse_unauditable_cables(h);  // before the planning work it would throw away
  double part_extra = 0.0;
  for (const auto& p : scene.parts) part_extra = std::max(part_extra, p.clearance);

  // 1. Planning obstacles: α-simplified parts (they contain the originals, so a route clear
  //    of them is clear of the real parts), indexed once.
  auto t0 = Clock::now();
  std::vector<Part> planning_parts;
  const bool plan_on_other_parts = opt.planning_parts || (opt.simplify && !scene.parts.empty());
  if (opt.planning_parts) {
    planning_parts = *opt.planning_parts;
    rep.notes.push_back("planning on " + std::to_string(planning_parts.size()) + " parts given by the caller");
  } else if (opt.simplify && !scene.parts.empty()) {
    AlphaSimOptions ao;
    ao.dim_pre = scene.simplify.dim_pre.value;
    ao.detect_lost_space = true;
    ao.hausdorff = false;  // not reported by routing; the containment check and lost-space probe stay
    ao.progress = opt.progress;
    std::vector<AlphaSimResult> results;
    planning_parts = simplify_parts(scene.parts, ao, &results);
    std::size_t before = 0, after = 0;
    for (const auto& r : results) before += r.triangles_before, after += r.triangles_after;
    rep.notes.push_back("planning on α-simplified parts (dim_pre " + full_precision(ao.dim_pre) + "): " +
                        std::to_string(before) + " -> " + std::to_string(after) + " triangles");
  } else {
    planning_parts = scene.parts;
  }
  rep.timing.simplify = ms_since(t0);
  t0 = Clock::now();
  ProgressCounter indexed(opt.progress, "index", 1, "indices");
  const EmbreeIndex plan_index(planning_parts);
  indexed.finish();
  std::vector<AABB> part_boxes;
  for (std::size_t q = 0; q < planning_parts.size(); ++q) {
    const auto kept = plan_index.part_bounds(static_cast<int>(q));
    part_boxes.push_back(kept ? *kept : planning_parts[q].mesh.bounds());
  }
  rep.timing.index = ms_since(t0);

  // 2. Branch points the file leaves open, placed where the legs are short and can turn
  //    into their connectors within the bend radius; then the exit direction of every
  //    segment at every branch point (main lines smooth through their node).
  const std::vector<SegmentEnds> ends = segment_ends(topo, derived_stub_length);
  BranchPlacementOptions bpo;
  bpo.clearance_of = [&](int b) {
    double r = 0.0;
    for (int s : topo.incident_segments(h.branches[b].id)) r = std::max(r, ends[s].radius);
    return r + rep.clearance + part_extra;
  };
  for (const auto& id : place_branch_points(h, topo, plan_index, ends, bpo))
    rep.notes.push_back("branch point '" + id + "' placed by the router");
  const auto exit_dir = branch_exit_directions(h, topo, ends);
  std::map<std::string, double> breakout;
  for (const auto& br : h.branches) breakout[br.id] = breakout_length(topo, br.id);
  auto end_frame = [&](int seg, bool from_end) {
    const Segment& sg = h.segments[seg];
    EndFrame e;
    e.node = from_end ? sg.from : sg.to;
    e.position = *h.node_position(e.node);
    if (int p = h.find_port(e.node); p >= 0) {
      e.is_port = true;
      e.exit = h.ports[p].direction;
    } else {
      e.exit = exit_dir.at({seg, from_end});
    }
    return e;
  };

  // 4. Plan each segment in the patent's order.
  const AABB box = scene.bounds();
  const double eps = 1e-9 * std::max(1.0, box.diagonal());  // coincident key points
  std::map<int, SegmentGeometry> geom;
  std::set<std::string> failed_segments;
  const auto& order = topo.routing_order();
  seed_ompl_once(rep.seed);
  ProgressCounter planned(opt.progress, "plan", order.size(), "segments");
  for (std::size_t k = 0; k < order.size(); ++k, planned.add()) {
    const int s = order[k];
    Segment& seg = h.segments[s];
    SegmentRouteInfo info;
    info.segment = s;
    if (seg.bspline || !seg.path.empty()) {
      info.kept_from_input = true;
      rep.segments.push_back(info);
      continue;
    }
    const Vec3 a = *h.node_position(seg.from), b = *h.node_position(seg.to);
    const double min_bend = ends[s].min_bend_radius;
    const double radius = ends[s].radius;
    const double required = rep.clearance + part_extra + radius;
    // Each end leaves straight along its exit direction: a port along the connector axis
    // for derived_stub_length(); a branch point along its breakout direction for the
    // breakout length (shortened if something is in the way). The planner starts at the
    // stub ends.
    const EndFrame ea = end_frame(s, true), eb = end_frame(s, false);
    // The parts each port end sits on, and how far along its exit they are excused: the
    // audit's straight exit (the shortest of the cables here: derived_stub_length of each),
    // and at least `required` and the slack (a port on a face leaving along its normal is
    // exactly `required` from the face there).
    const double attach_slack = kAttachSlackPerRadius * radius;
    double excused = std::numeric_limits<double>::infinity();
    for (int c : topo.segment_cables(s))
      excused = std::min(excused, derived_stub_length(h.cables[c].radius(), h.cables[c].physical.min_bend_radius));
    excused = std::max(std::isfinite(excused) ? excused : 0.0, required + attach_slack);
    auto near_parts = [&](const EndFrame& e) {
      return e.is_port ? near_port_parts(plan_index, part_boxes, planning_parts, e.position, required, excused,
                                         required + attach_slack)
                       : std::vector<NearPart>{};
    };
    const std::vector<NearPart> on_a = near_parts(ea), on_b = near_parts(eb);
    // A port on its connector leaves it straight until clear of it: at least `required` and
    // the slack twice, so that the planner starts clear of it.
    auto stub_for = [&](const EndFrame& e, const std::vector<NearPart>& on) {
      if (!e.is_port) return free_stub(plan_index, e.position, e.exit, breakout[e.node], required);
      return on.empty() ? ends[s].port_stub : std::max(ends[s].port_stub, required + 2.0 * attach_slack);
    };
    // Stubs heading towards each other may together cover at most kStubShare of the way
    // between the ends; longer ones would cross and force the route into a hairpin. A stub
    // leaving sideways takes nothing from the way and is kept whole.
    double la = stub_for(ea, on_a), lb = stub_for(eb, on_b);
    const double span = (b - a).norm();
    if (span > 0.0) {
      const Vec3 u = (b - a) / span;
      const double eaten = la * std::max(0.0, ea.exit.dot(u)) + lb * std::max(0.0, -eb.exit.dot(u));
      if (eaten > kStubShare * span) {
        const double f = kStubShare * span / eaten;
        la *= f;
        lb *= f;
      }
    }
    const Vec3 a_stub = ea.position + la * ea.exit;
    const Vec3 b_stub = eb.position + lb * eb.exit;
    PlanRequest req;
    req.radius = radius;
    req.clearance = rep.clearance + part_extra;
    req.min_bend_radius = min_bend;
    req.stub_length = 0.0;
    req.scene_box = box;
    req.scene_box.extend(a);
    req.scene_box.extend(b);
    req.planner = rep.planner;
    req.seed = rep.seed + static_cast<unsigned>(s);
    req.time_limit = time_limit;
    req.max_iterations = rep.iterations;
    req.start = {a_stub, (b_stub - a_stub).norm() > 0 ? Vec3((b_stub - a_stub).normalized()) : Vec3::UnitX()};
    req.goal = {b_stub, (a_stub - b_stub).norm() > 0 ? Vec3((a_stub - b_stub).normalized()) : Vec3::UnitX()};
    PlanResult blocked;
    bool branch_blocked = false;
    for (const EndFrame* e : {&ea, &eb}) {
      if (!blocked.message.empty()) continue;
      if (!e->is_port) {
        // A branch point the file fixed inside a part, or so near one that the bundle
        // itself would cut it: nothing the planner can do; the harness must move it.
        int part = -1;
        const bool in = plan_index.inside(e->position, &part);
        const ClosestHit near = in ? ClosestHit{} : plan_index.closest(e->position, radius);
        if (!in && !near.found()) continue;
        branch_blocked = true;
        blocked.reason = e == &ea ? NoPathReason::StartInObstacle : NoPathReason::GoalInObstacle;
        blocked.blocked_at = e->position;
        blocked.blocking_part = in ? part : near.part;
        blocked.message = "branch point " + e->node + " at " + full_precision(e->position) +
                          (in ? " is inside part '" + planning_parts[part].name + "'"
                              : " is " + full_precision(near.distance) + " from part '" + planning_parts[near.part].name +
                                    "', less than the bundle radius " + full_precision(radius));
        continue;
      }
      int inside_part = -1;
      if (plan_index.inside(e->position, &inside_part)) {
        blocked.reason = e == &ea ? NoPathReason::StartInObstacle : NoPathReason::GoalInObstacle;
        blocked.blocked_at = e->position;
        blocked.blocking_part = inside_part;
        blocked.message = "port " + e->node + " at " + full_precision(e->position) + " is inside part '" +
                          planning_parts[inside_part].name + "'";
        continue;
      }
      const Vec3 stub_end = e == &ea ? a_stub : b_stub;
      // The connector the port sits on may touch its exit over the excused run; every other
      // part is kept `required` away from all of it, and the planner starts at its end.
      const double len = (stub_end - e->position).norm();
      const std::vector<NearPart>& on = e == &ea ? on_a : on_b;
      ClosestHit hit;
      if (plan_index.segment_within(e->position, stub_end, required))
        hit = exit_obstacle(plan_index, part_boxes, e->position, stub_end, on, attach_slack, required);
      const ClosestHit at_end = hit.found() ? ClosestHit{} : plan_index.closest(stub_end, required);
      if (hit.found() || at_end.found()) {
        const ClosestHit& w = hit.found() ? hit : at_end;
        blocked.reason = e == &ea ? NoPathReason::StartPortBlocked : NoPathReason::GoalPortBlocked;
        blocked.blocked_at = w.point;
        blocked.blocking_part = w.part;
        blocked.message = "port " + e->node + " faces a wall: its straight exit of length " + full_precision(len) +
                          (hit.found() ? " comes" : " ends") + " within " + full_precision(w.distance) +
                          " of part '" + (w.part >= 0 ? planning_parts[w.part].name : std::string("?")) +
                          "' (needs " + full_precision(required) + ")";
      }
    }
    t0 = Clock::now();
    PlanResult plan;
    if (!blocked.message.empty()) {
      plan = blocked;
    } else if ((b_stub - a_stub).norm() <= eps) {  // nothing to plan (and plan_path refuses equal ends)
      plan.status = PlanStatus::Solved;
      plan.key_points = {a_stub, b_stub};
    } else {
      plan = plan_path(plan_index, req);
      info.time_limited = plan.time_limited;
      if (!plan.solved() && part_extra > 0.0) {
        // Per-part extra clearance is applied to every part while planning (conservative);
        // if that closes every corridor, plan with the routing clearance and let the audit
        // report where a part's own extra clearance is not met.
        req.clearance = rep.clearance;
        PlanResult retry = plan_path(plan_index, req);
        info.time_limited = info.time_limited || retry.time_limited;
        if (retry.solved()) {
          plan = retry;
          rep.notes.push_back("segment " + seg.from + " -> " + seg.to +
                              ": planned with the routing clearance only (per-part extra clearance blocked it)");
        }
      }
    }
    rep.timing.plan += ms_since(t0);
    if (!plan.solved() && plan.blocking_part >= 0 && plan.blocking_part < static_cast<int>(planning_parts.size()) &&
        plan.message.find("'" + planning_parts[plan.blocking_part].name + "'") == std::string::npos)
      plan.message += " (part '" + planning_parts[plan.blocking_part].name + "')";
    info.plan = plan;
    if (!plan.solved()) {
      failed_segments.insert(seg.from + " -> " + seg.to);
      // One entry per cable: the first segment (in routing order) that stopped it.
      for (int c : topo.segment_cables(s))
        if (std::none_of(rep.unrouted.begin(), rep.unrouted.end(),
                         [&](const UnroutedCable& u) { return u.cable == h.cables[c].id; }))
          rep.unrouted.push_back({h.cables[c].id, seg.from + " -> " + seg.to,
                                  branch_blocked ? "branch_blocked" : reason_name(plan.reason), plan.message});
      rep.segments.push_back(info);
      continue;
    }
    info.planned = true;
    SegmentGeometry g;
    g.a = a;
    g.a_stub = a_stub;
    g.b_stub = b_stub;
    g.b = b;
    g.request = req;
    g.points = assemble(g, plan.key_points, eps);
    g.interp.start_tangent = ea.exit;
    g.interp.end_tangent = -eb.exit;
    geom[s] = g;
    rep.segments.push_back(info);
  }
  planned.finish();

  // 5. Splines: bend-radius repair within half the clearance margin, written into the harness.
  auto build_curve = [&](int s) {
    SegmentGeometry& g = geom[s];
    const double min_bend = ends[s].min_bend_radius;
    std::string status = "not checked";
    if (min_bend > 0.0) {
      // Round corners as far as the planning obstacles allow: try the budgets from generous
      // (a corner rounded to the full bend radius moves up to ~0.4 R) to tight, and keep the
      // first repaired curve whose samples stay clear of the (simplified) parts; the exact
      // audit that follows is the judge.
      const double radius = ends[s].radius;
      const double need = radius + 0.5 * rep.clearance;
      const double step = std::max(radius, 0.25 * rep.clearance);
      BendRepairResult chosen;
      bool have = false;
      for (double dev : {0.5 * min_bend, 0.25 * min_bend, rep.clearance, 0.5 * rep.clearance}) {
        if (!(dev > 0.0)) continue;
        BendRepairOptions bo;
        bo.min_bend_radius = min_bend;
        bo.max_deviation = dev;
        bo.interpolation = g.interp;
        BendRepairResult br = repair_bend_radius(g.points, bo);
        bool clear = true;
        for (const auto& [sa, p] : br.curve.sample_by_arc_length(step)) {
          (void)sa;
          if (plan_index.any_within(p, need) && (p - g.points.front()).norm() > need &&
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
      g.curve = chosen.curve;
      g.points = chosen.points.empty() ? g.points : chosen.points;
      status = chosen.status == BendRepairStatus::Failed ? "failed: " + chosen.reason
               : chosen.status == BendRepairStatus::AlreadySatisfied ? "satisfied"
               : chosen.status == BendRepairStatus::Faired ? "faired"
                                                           : "points inserted";
    } else {
      g.curve = Centerline::interpolate(g.points, g.interp);
    }
    Segment& seg = h.segments[s];
    seg.path.assign(g.points.begin() + 1, g.points.end() - 1);
    seg.interp = Interp::BSpline;
    seg.bspline = to_bspline(g.curve);
    for (auto& info : rep.segments)
      if (info.segment == s) info.key_points = seg.path.size(), info.bend_status = status;
  };
  t0 = Clock::now();
  for (auto& [s, g] : geom) build_curve(s);
  rep.timing.spline = ms_since(t0);

  // 5b. A segment whose corners cannot be rounded within what the obstacles allow is
  //     re-planned (another seed, twice the budget, up to kBendReplans times); the new
  //     key points are kept only if their curve meets the bend radius.
  auto info_of = [&](int s) -> SegmentRouteInfo& {
    return *std::find_if(rep.segments.begin(), rep.segments.end(), [s](const SegmentRouteInfo& i) { return i.segment == s; });
  };
  auto bend_failed = [&](int s) { return info_of(s).bend_status.rfind("failed", 0) == 0; };
  for (auto& [s, g] : geom) {
    // Stub ends that coincide leave nothing to re-plan (and plan_path refuses equal ends).
    if ((g.b_stub - g.a_stub).norm() <= eps) continue;
    for (int attempt = 1; attempt <= kBendReplans && bend_failed(s); ++attempt) {
      PlanRequest req = g.request;
      req.seed = g.request.seed + 7919u * static_cast<unsigned>(attempt);
      req.time_limit = g.request.time_limit * std::pow(2.0, attempt);
      req.max_iterations = g.request.max_iterations << attempt;  // twice the budget, as the time
      t0 = Clock::now();
      const PlanResult plan = plan_path(plan_index, req);
      rep.timing.plan += ms_since(t0);
      // Whether the re-plan is kept depends on its result: a timed-out one makes the segment
      // irreproducible either way.
      info_of(s).time_limited = info_of(s).time_limited || plan.time_limited;
      if (!plan.solved()) continue;
      const SegmentGeometry saved = g;
      const SegmentRouteInfo saved_info = info_of(s);
      g.points = assemble(g, plan.key_points, eps);
      build_curve(s);
      if (bend_failed(s)) {
        g = saved;
        build_curve(s);
        const bool timed = info_of(s).time_limited;
        info_of(s) = saved_info;
        info_of(s).time_limited = timed;
      } else {
        info_of(s).plan = plan;
        info_of(s).replans = attempt;
      }
    }
  }

  // 6. Exact audit against the real parts; repair segments whose curves clash or crowd.
  //    The exact index is built once: the planning index when planning used the exact parts.
  t0 = Clock::now();
  std::unique_ptr<EmbreeIndex> exact_owned;
  if (plan_on_other_parts) exact_owned = std::make_unique<EmbreeIndex>(scene.parts);
  AuditOptions ao;
  ao.check.threads = opt.threads;
  ao.progress = opt.progress;
  ao.index = exact_owned ? exact_owned.get() : &plan_index;
  rep.timing.index += ms_since(t0);
  Scene routed_scene;
  routed_scene.name = scene.name;
  routed_scene.units = scene.units;
  routed_scene.routing = scene.routing;
  routed_scene.has_harness = true;
  routed_scene.parts = scene.parts;
  auto audit_now = [&]() {
    routed_scene.harness = h;
    // Cables that could not be routed have no curve to audit (their segments would read
    // as straight lines between the nodes); they are reported as unrouted instead.
    auto& cables = routed_scene.harness.cables;
    cables.erase(std::remove_if(cables.begin(), cables.end(),
                                [&](const Cable& c) {
                                  return std::any_of(rep.unrouted.begin(), rep.unrouted.end(),
                                                     [&](const UnroutedCable& u) { return u.cable == c.id; });
                                }),
                 cables.end());
    return run_audit(routed_scene, ao);
  };
  t0 = Clock::now();
  rep.audit = audit_now();
  rep.timing.audit = ms_since(t0);
  t0 = Clock::now();
  for (int round = 0; round < opt.max_repair_rounds; ++round) {
    // Segments (that we routed) hit by a clash or clearance violation of any cable.
    std::set<int> bad;
    auto mark = [&](int check_index, double s_at) {
      const int c = h.find_cable(rep.audit.check_ids[check_index]);
      if (c < 0) return;
      const auto pieces = cable_pieces(topo, c);
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        const bool last = k + 1 == pieces.size();
        if (last || s_at < pieces[k + 1].s0) {
          if (geom.count(pieces[k].segment)) bad.insert(pieces[k].segment);
          return;
        }
      }
    };
    for (const auto& cl : rep.audit.result.clashes) {
      mark(cl.cable, cl.s);
      if (cl.kind != ClashKind::CableStructure && cl.other >= 0) mark(cl.other, cl.s_other);
    }
    for (const auto& v : rep.audit.result.violations)
      if (v.kind == ViolationKind::Clearance) mark(v.cable, v.s);
    if (bad.empty()) break;
    for (int s : bad) {
      geom[s].points = densify(geom[s].points);
      build_curve(s);
      for (auto& info : rep.segments)
        if (info.segment == s) info.repair_rounds = round + 1;
    }
    rep.audit = audit_now();
  }
  rep.timing.repair = ms_since(t0);
  for (const auto& f : failed_segments) rep.notes.push_back("segment " + f + " could not be routed");
  // 7. Reproducibility: say why another run with the same seed may give other routes.
  if (rep.iterations == 0)
    rep.unreproducible.push_back("no iteration budget: the planners stop on the time limit and on time-based "
                                 "convergence, so another run may give other routes (set --iterations or "
                                 "[routing] iterations)");
  else if (planner_is_threaded(rep.planner))
    rep.unreproducible.push_back("planner " + rep.planner +
                                 " grows its roadmap in a second thread: its routes are not reproducible, "
                                 "even with an iteration budget");
  if (rep.iterations > 0)
    for (const auto& info : rep.segments)
      if (info.time_limited) {
        const Segment& sg = h.segments[info.segment];
        rep.unreproducible.push_back("segment " + sg.from + " -> " + sg.to + ": the time limit (" +
                                     full_precision(time_limit) + " s per plan) ended planning before " +
                                     std::to_string(rep.iterations) +
                                     " iterations: its route is not reproducible (raise the time limit or lower "
                                     "the iterations)");
      }
  for (const auto& n : rep.unreproducible) rep.notes.push_back(n);
  rep.timing.total = ms_since(t_total);
  return rep;
}

}  // namespace loom
