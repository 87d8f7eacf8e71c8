#include "routing/route_pipeline.hpp"

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "index/alpha_sim.hpp"
#include "index/embree_index.hpp"
#include "routing/bend_repair.hpp"
#include "routing/cable_geometry.hpp"

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

/// Branch placement: Weiszfeld iterations for the geometric median of the neighbours.
constexpr int kWeiszfeldIterations = 100;
/// Moving a branch point clear: candidate directions per shell and shells tried, the shell
/// radius growing by the required clearance each time.
constexpr int kClearDirections = 26;
constexpr int kClearShells = 40;
/// The straight stubs at both ends of a segment take at most this share of its length.
constexpr double kStubShare = 0.4;

/// Directions on the unit sphere: the 26 neighbours of a cube cell, normalised.
std::vector<Vec3> shell_directions() {
  std::vector<Vec3> d;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) d.push_back(Vec3(x, y, z).normalized());
  return d;
}

/// A segment's key-point polyline and the curve through it.
struct SegmentGeometry {
  std::vector<Vec3> points;  ///< from-node, interior key points, to-node
  InterpolationOptions interp;
  Centerline curve;
};

/// Removes consecutive points closer than `eps`.
std::vector<Vec3> dedupe(const std::vector<Vec3>& pts, double eps) {
  std::vector<Vec3> out;
  for (const auto& p : pts)
    if (out.empty() || (p - out.back()).norm() > eps) out.push_back(p);
  if (out.size() == 1 && pts.size() > 1) out.push_back(pts.back());
  return out;
}

/// Inserts the midpoint of every polyline edge: the interpolating cubic then follows the
/// verified polyline more closely (the deviation falls roughly 4× per round).
std::vector<Vec3> densify(const std::vector<Vec3>& pts) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    out.push_back(pts[i]);
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

}  // namespace

std::vector<std::string> place_branch_points(Harness& h, const ObstacleIndex& index,
                                             const std::function<double(int branch)>& clearance_of) {
  std::vector<int> unplaced;
  for (std::size_t b = 0; b < h.branches.size(); ++b)
    if (!h.branches[b].position) unplaced.push_back(static_cast<int>(b));
  std::vector<std::string> placed;
  if (unplaced.empty()) return placed;
  // Neighbours of each branch point.
  std::map<std::string, std::vector<std::string>> nb;
  for (const auto& s : h.segments) {
    nb[s.from].push_back(s.to);
    nb[s.to].push_back(s.from);
  }
  // Start from the mean of the placed neighbours (or of all ports when none is placed).
  Vec3 port_mean = Vec3::Zero();
  for (const auto& p : h.ports) port_mean += p.position;
  if (!h.ports.empty()) port_mean /= static_cast<double>(h.ports.size());
  std::map<int, Vec3> pos;
  for (int b : unplaced) {
    Vec3 sum = Vec3::Zero();
    int n = 0;
    for (const auto& id : nb[h.branches[b].id])
      if (auto p = h.node_position(id)) sum += *p, ++n;
    pos[b] = n ? Vec3(sum / n) : port_mean;
  }
  auto position_of = [&](const std::string& id) -> Vec3 {
    if (int b = h.find_branch(id); b >= 0 && !h.branches[b].position) return pos[b];
    return *h.node_position(id);
  };
  // Weiszfeld: each unplaced point moves to the distance-weighted mean of its neighbours;
  // chains of unplaced points converge together (the sum of segment lengths is convex).
  for (int it = 0; it < kWeiszfeldIterations; ++it) {
    for (int b : unplaced) {
      Vec3 num = Vec3::Zero();
      double den = 0.0;
      for (const auto& id : nb[h.branches[b].id]) {
        const Vec3 q = position_of(id);
        const double d = std::max((q - pos[b]).norm(), 1e-9);
        num += q / d;
        den += 1.0 / d;
      }
      if (den > 0) pos[b] = num / den;
    }
  }
  // Move each clear of the obstacles: the nearest free point on growing shells.
  const auto dirs = shell_directions();
  for (int b : unplaced) {
    const double need = clearance_of(b);
    Vec3 p = pos[b];
    if (index.inside(p) || index.any_within(p, need)) {
      bool found = false;
      for (int shell = 1; shell <= kClearShells && !found; ++shell) {
        double best = std::numeric_limits<double>::infinity();
        Vec3 best_p = p;
        for (const auto& d : dirs) {
          const Vec3 q = p + d * (need * shell);
          if (index.inside(q) || index.any_within(q, need)) continue;
          // Prefer the candidate that keeps the connected segments shortest.
          double len = 0;
          for (const auto& id : nb[h.branches[b].id]) len += (position_of(id) - q).norm();
          if (len < best) best = len, best_p = q;
        }
        if (std::isfinite(best)) p = best_p, found = true;
      }
      if (!found)
        throw InputError({h.source_file, h.branches[b].line, "branch '" + h.branches[b].id + "'"},
                         "cannot place this branch point clear of the structure near its neighbours");
    }
    pos[b] = p;
    h.branches[b].position = p;
    placed.push_back(h.branches[b].id);
  }
  return placed;
}

RouteReport route_scene(const Scene& scene, const RouteOptions& opt) {
  const auto t_total = Clock::now();
  RouteReport rep;
  rep.routed = scene.harness;
  Harness& h = rep.routed;
  const HarnessTopology topo(h);  // ids and structure never change below, only geometry
  rep.planner = opt.planner.empty() ? scene.routing.planner : opt.planner;
  rep.seed = opt.seed >= 0 ? static_cast<unsigned>(opt.seed) : scene.routing.seed;
  const double time_limit = opt.time_limit >= 0 ? opt.time_limit : scene.routing.time_limit.value;
  rep.clearance = scene.routing.clearance.value;
  double part_extra = 0.0;
  for (const auto& p : scene.parts) part_extra = std::max(part_extra, p.clearance);
  auto progress = [&](const std::string& stage, double f) {
    if (opt.progress) opt.progress(stage, f);
  };

  // 1. Planning obstacles: α-simplified parts (they contain the originals, so a route clear
  //    of them is clear of the real parts), indexed once.
  auto t0 = Clock::now();
  std::vector<Part> planning_parts;
  if (opt.simplify && !scene.parts.empty()) {
    AlphaSimOptions ao;
    ao.dim_pre = scene.simplify.dim_pre.value;
    ao.detect_lost_space = true;
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
  const EmbreeIndex plan_index(planning_parts);
  rep.timing.index = ms_since(t0);

  // 2. Branch points the file leaves open.
  auto branch_clearance = [&](int b) {
    double r = 0.0;
    for (int s : topo.incident_segments(h.branches[b].id)) r = std::max(r, 0.5 * topo.segment_diameter(s));
    return r + rep.clearance + part_extra;
  };
  for (const auto& id : place_branch_points(h, plan_index, branch_clearance))
    rep.notes.push_back("branch point '" + id + "' placed by the router");

  // 3. Exit directions at every node. Ports: the connector axis. Branch points: the two
  //    segments with most cables passing between them form the main line, smooth through
  //    the node (opposite exit directions along the line joining their far ends); the third
  //    leaves towards its far end (cables turning into it splay inside the breakout).
  std::map<std::pair<int, bool>, Vec3> exit_dir;  // (segment, at its from-end) -> unit exit direction
  std::map<std::string, double> breakout;
  for (const auto& br : h.branches) {
    const Vec3 bp = *br.position;
    const auto inc = topo.incident_segments(br.id);
    breakout[br.id] = breakout_length(topo, br.id);
    auto far_end = [&](int seg) {
      const Segment& sg = h.segments[seg];
      return *h.node_position(sg.from == br.id ? sg.to : sg.from);
    };
    std::map<std::pair<int, int>, int> passes;
    for (std::size_t c = 0; c < h.cables.size(); ++c) {
      const auto& chain = topo.cable_chain(static_cast<int>(c));
      for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
        const Segment& sg = h.segments[chain[k].segment];
        const std::string& at = chain[k].reversed ? sg.from : sg.to;
        if (at == br.id) passes[std::minmax(chain[k].segment, chain[k + 1].segment)]++;
      }
    }
    std::pair<int, int> main{-1, -1};
    int best = -1;
    for (std::size_t i = 0; i < inc.size(); ++i)
      for (std::size_t j = i + 1; j < inc.size(); ++j) {
        const auto key = std::minmax(inc[i], inc[j]);
        const int n = passes.count(key) ? passes[key] : 0;
        if (n > best) best = n, main = key;
      }
    const Vec3 di = far_end(main.first), dj = far_end(main.second);
    Vec3 d = dj - di;
    if (d.norm() < 1e-12) d = Vec3::UnitX();
    d.normalize();
    for (int seg : inc) {
      Vec3 e;
      if (seg == main.first) e = -d;
      else if (seg == main.second) e = d;
      else {
        e = far_end(seg) - bp;
        e = e.norm() > 1e-12 ? Vec3(e.normalized()) : d;
      }
      exit_dir[{seg, h.segments[seg].from == br.id}] = e;
    }
  }
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
  std::map<int, SegmentGeometry> geom;
  std::set<std::string> failed_segments;
  const auto& order = topo.routing_order();
  seed_ompl_once(rep.seed);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const int s = order[k];
    progress("plan", static_cast<double>(k) / order.size());
    Segment& seg = h.segments[s];
    SegmentRouteInfo info;
    info.segment = s;
    if (seg.bspline || !seg.path.empty()) {
      info.kept_from_input = true;
      rep.segments.push_back(info);
      continue;
    }
    const Vec3 a = *h.node_position(seg.from), b = *h.node_position(seg.to);
    double min_bend = 0.0;
    for (int c : topo.segment_cables(s)) min_bend = std::max(min_bend, h.cables[c].physical.min_bend_radius);
    const double radius = 0.5 * topo.segment_diameter(s);
    const double required = rep.clearance + part_extra + radius;
    // Each end leaves straight along its exit direction: a port along the connector axis
    // for derived_stub_length(); a branch point along its breakout direction for the
    // breakout length (shortened if something is in the way). The planner starts at the
    // stub ends.
    const EndFrame ea = end_frame(s, true), eb = end_frame(s, false);
    const double port_stub = derived_stub_length(radius, min_bend);
    auto stub_for = [&](const EndFrame& e) {
      return e.is_port ? port_stub : free_stub(plan_index, e.position, e.exit, breakout[e.node], required);
    };
    // Stubs of the two ends together take at most kStubShare of the distance between the
    // ends; longer ones would cross and force the route into a hairpin.
    double la = stub_for(ea), lb = stub_for(eb);
    const double span = (b - a).norm();
    if (la + lb > kStubShare * span) {
      const double f = kStubShare * span / (la + lb);
      la *= f;
      lb *= f;
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
    req.start = {a_stub, (b_stub - a_stub).norm() > 0 ? Vec3((b_stub - a_stub).normalized()) : Vec3::UnitX()};
    req.goal = {b_stub, (a_stub - b_stub).norm() > 0 ? Vec3((a_stub - b_stub).normalized()) : Vec3::UnitX()};
    PlanResult blocked;
    for (const EndFrame* e : {&ea, &eb}) {
      if (!e->is_port || !blocked.message.empty()) continue;
      int inside_part = -1;
      if (plan_index.inside(e->position, &inside_part)) {
        blocked.reason = e == &ea ? NoPathReason::StartInObstacle : NoPathReason::GoalInObstacle;
        blocked.blocked_at = e->position;
        blocked.blocking_part = inside_part;
        blocked.message = "port " + e->node + " at (" + full_precision(e->position.x()) + ", " +
                          full_precision(e->position.y()) + ", " + full_precision(e->position.z()) +
                          ") is inside part '" + planning_parts[inside_part].name + "'";
        continue;
      }
      const Vec3 stub_end = e == &ea ? a_stub : b_stub;
      // The connector the port sits on may touch the first `required` of the stub.
      const double len = (stub_end - e->position).norm();
      const Vec3 from = plan_index.any_within(e->position, required) ? Vec3(e->position + std::min(required, len) * e->exit)
                                                                     : e->position;
      if (plan_index.segment_within(from, stub_end, required)) {
        double t = 0.0;
        const ClosestHit hit = plan_index.segment_closest(from, stub_end, required, &t);
        blocked.reason = e == &ea ? NoPathReason::StartPortBlocked : NoPathReason::GoalPortBlocked;
        blocked.blocked_at = hit.found() ? hit.point : stub_end;
        blocked.blocking_part = hit.part;
        blocked.message = "port " + e->node + " faces a wall: its straight exit of length " + full_precision(len) +
                          " comes within " + full_precision(hit.distance) + " of part '" +
                          (hit.part >= 0 ? planning_parts[hit.part].name : std::string("?")) + "' (needs " +
                          full_precision(required) + ")";
      }
    }
    t0 = Clock::now();
    PlanResult plan;
    if (!blocked.message.empty()) {
      plan = blocked;
    } else if ((b_stub - a_stub).norm() < 1e-9) {
      plan.status = PlanStatus::Solved;
      plan.key_points = {a_stub, b_stub};
    } else {
      plan = plan_path(plan_index, req);
      if (!plan.solved() && part_extra > 0.0) {
        // Per-part extra clearance is applied to every part while planning (conservative);
        // if that closes every corridor, plan with the routing clearance and let the audit
        // report where a part's own extra clearance is not met.
        req.clearance = rep.clearance;
        PlanResult retry = plan_path(plan_index, req);
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
      for (int c : topo.segment_cables(s))
        rep.unrouted.push_back({h.cables[c].id, seg.from + " -> " + seg.to, reason_name(plan.reason), plan.message});
      rep.segments.push_back(info);
      continue;
    }
    info.planned = true;
    SegmentGeometry g;
    g.points.push_back(a);
    g.points.push_back(a_stub);
    for (const auto& p : plan.key_points) g.points.push_back(p);
    g.points.push_back(b_stub);
    g.points.push_back(b);
    g.points = dedupe(g.points, 1e-9 * std::max(1.0, box.diagonal()));
    g.interp.start_tangent = ea.exit;
    g.interp.end_tangent = -eb.exit;
    geom[s] = g;
    rep.segments.push_back(info);
  }
  progress("plan", 1.0);

  // 5. Splines: bend-radius repair within half the clearance margin, written into the harness.
  auto build_curve = [&](int s) {
    SegmentGeometry& g = geom[s];
    double min_bend = 0.0;
    for (int c : topo.segment_cables(s)) min_bend = std::max(min_bend, h.cables[c].physical.min_bend_radius);
    std::string status = "not checked";
    if (min_bend > 0.0) {
      // Round corners as far as the planning obstacles allow: try the budgets from generous
      // (a corner rounded to the full bend radius moves up to ~0.4 R) to tight, and keep the
      // first repaired curve whose samples stay clear of the (simplified) parts; the exact
      // audit that follows is the judge.
      const double radius = 0.5 * topo.segment_diameter(s);
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

  // 6. Exact audit against the real parts; repair segments whose curves clash or crowd.
  //    The exact index is built once: the planning index when planning used the exact parts.
  t0 = Clock::now();
  std::unique_ptr<EmbreeIndex> exact_owned;
  if (opt.simplify && !scene.parts.empty()) exact_owned = std::make_unique<EmbreeIndex>(scene.parts);
  AuditOptions ao;
  ao.check.threads = opt.threads;
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
  rep.timing.total = ms_since(t_total);
  return rep;
}

}  // namespace loom
