// The audit pipeline: scene → index → checks → AuditReport (DESIGN §4).
#include "routing/audit/audit.hpp"

#include "routing/audit/audit_shard.hpp"

#include "core/io/mesh_read.hpp"
#include "core/stopwatch.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/scene_load.hpp"
#include "index/box_tree.hpp"
#include "index/brute_force_index.hpp"
#include "index/embree_index.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

namespace loom {

namespace {


/// Node ids at the ends of a segment use, in the cable's direction of travel.
std::pair<std::string, std::string> use_nodes(const Harness& h, const SegmentUse& u) {
  const Segment& s = h.segments[static_cast<std::size_t>(u.segment)];
  return u.reversed ? std::make_pair(s.to, s.from) : std::make_pair(s.from, s.to);
}

/// The cable's turn at each node between two of its pieces (NodeTurn): the angle between
/// the tangent arriving at the node and the one leaving it, taken up within the node's
/// breakout, or within the shorter of the two pieces where that is shorter.
std::vector<NodeTurn> node_turns(const HarnessTopology& topo, std::size_t cable, const std::vector<CablePiece>& pieces) {
  const Harness& h = topo.harness();
  const auto& chain = topo.cable_chain(static_cast<int>(cable));
  std::vector<NodeTurn> out;
  for (std::size_t k = 0; k + 1 < pieces.size() && k + 1 < chain.size(); ++k) {
    const Centerline& a = pieces[k].curve;
    const Centerline& b = pieces[k + 1].curve;
    Vec3 da[2], db[2];
    a.evaluate(a.u_max(), 1, da, true);
    b.evaluate(b.u_min(), 1, db);
    NodeTurn t;
    t.node = use_nodes(h, chain[k]).second;
    t.s = pieces[k + 1].s0;
    t.point = db[0];
    // A zero tangent (a degenerate end) has no direction: no turn is judged there.
    t.turn = da[1].norm() > 0.0 && db[1].norm() > 0.0 ? std::atan2(da[1].cross(db[1]).norm(), da[1].dot(db[1])) : 0.0;
    const double reach = std::min({breakout_length(topo, t.node), a.length(), b.length()});
    const double half_tan = std::tan(0.5 * t.turn);
    t.radius = half_tan > 0.0 ? reach / half_tan : std::numeric_limits<double>::infinity();
    out.push_back(t);
  }
  return out;
}

/// Step of the walk that finds where two bundles leaving a node part, in their radii sum.
constexpr double kRunTogetherStep = 0.25;
/// Most steps of that walk along one segment (a longer segment is walked in longer steps).
constexpr int kRunTogetherMaxSteps = 4000;

/// How far from the node the bundles of two of its segments run together before they part:
/// the Euclidean distance from the node of the first point of one segment's curve that lies
/// at least the sum of their radii from the other's (either way round, the larger). Why: a
/// file may let segments leave a node tangent to each other (a splice on a stub laid along
/// the trunk), and their cables then touch for as long as the bundles do, by design; where
/// the segments part and meet again, that contact is beyond this distance and a clash.
double run_together_radius(const HarnessTopology& topo, SegmentCurves& curves, const std::string& node) {
  const Harness& h = topo.harness();
  const auto& inc = topo.incident_segments(node);
  const auto at = h.node_position(node);
  if (!at) return 0.0;
  // Each segment's curve from the node outwards, as points a fixed step apart.
  auto samples = [&](int s, double step) {
    std::vector<Vec3> pts;
    const bool backwards = h.segments[static_cast<std::size_t>(s)].to == node;
    const auto& c = curves.segment(s, backwards);
    if (!c) return pts;
    const double len = c->length();
    step = std::max(step, len / kRunTogetherMaxSteps);
    for (double t = 0.0; t < len; t += step) pts.push_back(c->position(c->parameter_at_length(t)));
    pts.push_back(c->position(c->u_max()));
    return pts;
  };
  double out = 0.0;
  for (std::size_t i = 0; i < inc.size(); ++i)
    for (std::size_t j = i + 1; j < inc.size(); ++j) {
      const int a = inc[i], b = inc[j];
      if (topo.segment_cables(a).empty() || topo.segment_cables(b).empty()) continue;
      const double reach = 0.5 * (topo.segment_diameter(a) + topo.segment_diameter(b));
      const auto pa = samples(a, kRunTogetherStep * reach), pb = samples(b, kRunTogetherStep * reach);
      for (const auto& [p, q] : {std::pair(&pa, &pb), std::pair(&pb, &pa)}) {
        // A segment that never parts from the other runs with it to its end.
        double parted = p->empty() ? 0.0 : (p->back() - *at).norm();
        for (const Vec3& x : *p) {
          double d = std::numeric_limits<double>::infinity();
          for (std::size_t k = 0; k + 1 < q->size(); ++k) {
            const Vec3 e = (*q)[k + 1] - (*q)[k];
            const double t = e.squaredNorm() > 0.0 ? std::clamp((x - (*q)[k]).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
            d = std::min(d, (x - (*q)[k] - t * e).norm());
          }
          if (d >= reach) {
            parted = (x - *at).norm();
            break;
          }
        }
        out = std::max(out, parted);
      }
    }
  return out;
}

/// The supports audit of a scene (clamps always; unsupported spans when the scene sets
/// clamp_spacing), through the audit's index or, for the brute-force baseline, over every
/// triangle.
/// A shard (`spans` false) measures its clamps only: spans follow from the merged clamps.
void audit_harness_supports(const Scene& scene, const ObstacleIndex* index, bool spans, AuditReport& rep) {
  const RoutingSettings& r = scene.routing;
  rep.supports_checked = r.supports;
  if (!r.supports && scene.harness.clamps.empty()) return;
  std::unique_ptr<BruteForceIndex> brute;
  if (!index) index = (brute = std::make_unique<BruteForceIndex>(scene.parts)).get();
  rep.supports = audit_supports(scene.harness, scene.parts, *index, r.clamp_spacing.value, r.clamp_reach.value,
                                r.supports && spans);
  rep.notes.insert(rep.notes.end(), rep.supports.notes.begin(), rep.supports.notes.end());
}

/// Relative widening of the port's query box over the largest per-part reach (rounding only).
constexpr double kReachRoundingRel = 1e-12;

}  // namespace

std::vector<std::string> attach_ports(const Harness& h, const std::vector<Part>& parts, double routing_clearance,
                                      std::vector<CableInput>& inputs, const ObstacleIndex* index) {
  // Part boxes once per audit (from the index when it keeps them: no pass over every
  // triangle), and the part containing each port once per port (many cables share a port).
  std::vector<AABB> boxes(parts.size());
  double max_part_clearance = 0.0;
  for (std::size_t q = 0; q < parts.size(); ++q) {
    const auto kept = index ? index->part_bounds(static_cast<int>(q)) : std::nullopt;
    boxes[q] = kept ? *kept : parts[q].mesh.bounds();
    max_part_clearance = std::max(max_part_clearance, parts[q].clearance);
  }
  // The parts near a port through a BVH over their boxes, not a pass over every part per
  // cable end (assemblies have thousands of parts, harnesses thousands of cable ends).
  const BoxTree part_tree(boxes);
  std::vector<std::uint32_t> near_port;
  std::map<int, std::vector<int>> containing;  // port -> the closed parts holding it, when asked
  auto port_inside = [&](int port, int part) {
    auto it = containing.find(port);
    if (it == containing.end()) {
      it = containing.emplace(port, std::vector<int>{}).first;
      index->inside_parts(h.ports[port].position, it->second);  // only asked with an index
    }
    return std::find(it->second.begin(), it->second.end(), part) != it->second.end();
  };
  std::set<std::pair<std::string, std::string>> said;
  std::vector<std::string> notes;
  for (CableInput& in : inputs) {
    const int c = h.find_cable(in.id);
    if (c < 0) continue;
    const double len = in.curve.length();
    // The port's straight exit (what the router gives it), at most half the cable.
    const double exit = std::min(derived_stub_length(in.radius, in.min_bend_radius), 0.5 * len);
    for (int end = 0; end < 2; ++end) {
      const int p = h.find_port(h.cables[c].ports[end]);
      if (p < 0) continue;
      const Vec3 at = h.ports[p].position;
      if (!at.allFinite()) continue;  // an unplaced port sits on no part
      AABB port_box;
      port_box.extend(at);
      // A little wider than any part's reach, so that rounding cannot drop a box the exact
      // test below keeps.
      const double max_reach = (in.radius + routing_clearance + max_part_clearance) * (1.0 + kReachRoundingRel) +
                               kReachRoundingRel * at.cwiseAbs().maxCoeff();
      part_tree.overlapping(port_box.inflated(max_reach), near_port);
      for (const std::uint32_t q : near_port) {
        if (parts[q].role == PartRole::KeepOut) continue;  // never excused
        const double reach = in.radius + routing_clearance + parts[q].clearance;
        if (!boxes[q].inflated(reach).contains(at)) continue;
        // The port's depth inside the part (0 outside or on it; `reach` for deeper): the
        // checker excuses the centerline inside the part only where the part holds the port.
        bool inside = false;
        ClosestHit nearest;
        if (index) {
          inside = port_inside(p, static_cast<int>(q));
          nearest = index->closest_on_part(at, static_cast<int>(q), reach);
        } else {  // the brute-force baseline has no index: measure this one part directly
          const BruteForceIndex one({parts[q]});
          inside = one.inside(at);
          nearest = one.closest(at, reach);
        }
        if (!inside && !nearest.found()) continue;
        const double depth = inside ? (nearest.found() ? nearest.distance : reach) : 0.0;
        in.attachments.push_back({static_cast<int>(q), end == 0 ? 0.0 : len - exit, end == 0 ? exit : len,
                                  h.ports[p].id, depth});
        if (said.insert({h.ports[p].id, parts[q].name}).second)
          notes.push_back("port " + h.ports[p].id + " sits on part '" + parts[q].name +
                          "': cables are not checked against it over their straight exit from the port");
      }
    }
  }
  return notes;
}

std::vector<CableInput> audit_cable_inputs(const Harness& h, std::vector<AuditCable>& cables) {
  HarnessTopology topo(h);
  SegmentCurves curves(topo);
  std::vector<CableInput> out;
  std::map<std::string, double> junction_radius;  // per node, once
  cables.clear();
  for (std::size_t c = 0; c < h.cables.size(); ++c) {
    AuditCable ac;
    ac.id = h.cables[c].id;
    // A route that does not make a curve throws InputError naming the file and cable.
    std::optional<Centerline> curve = curves.cable(static_cast<int>(c));
    if (!curve) {
      ac.routed = false;
      ac.reason = "a segment of its route has an unplaced end (branch point without position)";
      cables.push_back(ac);
      continue;
    }
    CableInput in;
    in.id = h.cables[c].id;
    in.curve = std::move(*curve);
    in.radius = h.cables[c].radius();
    in.min_bend_radius = h.cables[c].physical.min_bend_radius;
    double s = 0.0;
    const auto& chain = topo.cable_chain(static_cast<int>(c));
    for (std::size_t k = 0; k < chain.size(); ++k) {
      const SegmentUse& u = chain[k];
      const auto& seg = curves.segment(u.segment, false);
      const double len = seg ? seg->length() : 0.0;
      // Only bundle segments excuse contacts (a single-cable segment is never shared).
      if (topo.is_bundle(u.segment)) in.segments.push_back({u.segment, s, s + len});
      s += len;
      const auto nodes = use_nodes(h, u);
      for (const std::string& n : {nodes.first, nodes.second}) {
        if (std::any_of(in.junctions.begin(), in.junctions.end(), [&](const CableJunction& j) { return j.node == n; }))
          continue;
        const auto pos = h.node_position(n);
        if (!pos) continue;
        auto known = junction_radius.find(n);
        if (known == junction_radius.end()) {
          double rad = 0.0;
          for (int inc : topo.incident_segments(n)) rad = std::max(rad, topo.segment_diameter(inc));
          // At a branch point cables run bundled along the breakout before they separate
          // (the router leaves it straight for breakout_length); allow contact over twice
          // that, the run-out of two tubes diverging at their minimum bend radius.
          if (h.find_branch(n) >= 0) rad = std::max(rad, 2.0 * breakout_length(topo, n));
          known = junction_radius.emplace(n, std::max(rad, run_together_radius(topo, curves, n))).first;
        }
        const double rad = known->second;
        // Every node but the two ends of the chain is one the cable passes through.
        const bool passes = !(k == 0 && n == nodes.first) && !(k + 1 == chain.size() && n == nodes.second);
        in.junctions.push_back({n, *pos, rad, passes});
      }
    }
    auto pieces = curves.pieces(static_cast<int>(c));
    in.node_turns = node_turns(topo, c, pieces);
    for (auto& piece : pieces) in.bend_pieces.emplace_back(piece.s0, std::move(piece.curve));
    ac.routed = true;
    ac.check_index = static_cast<int>(out.size());
    cables.push_back(ac);
    out.push_back(std::move(in));
  }
  return out;
}

AuditReport run_audit(const Scene& scene, const AuditOptions& opt) {
  AuditReport rep;
  rep.scene = scene.name;
  rep.units = unit_name(scene.units);
  rep.method = opt.check.method;
  rep.use_index = opt.check.use_index;
  rep.triangles = scene.triangle_count();
  for (const auto& p : scene.parts) {
    rep.part_names.push_back(p.name);
    rep.part_keep_out.push_back(p.role == PartRole::KeepOut);
  }
  rep.scanned_parts = scanned_part_bounds(scene.parts);
  std::vector<CableInput> inputs;
  if (scene.has_harness) inputs = audit_cable_inputs(scene.harness, rep.cables);
  else rep.notes.push_back("the scene has no harness: nothing to audit");
  for (const auto& c : inputs) rep.check_ids.push_back(c.id);
  for (const auto& c : rep.cables)
    if (!c.routed) rep.notes.push_back("cable '" + c.id + "' not checked: " + c.reason);

  ClashRequest req = opt.check;
  req.routing_clearance = scene.routing.clearance.value;
  // A shard checks the cables against its own parts; the passes that need no part run once.
  const bool cable_passes = !opt.shard || opt.shard->cable_passes;
  req.check_cable_cable = req.check_cable_cable && cable_passes;
  req.check_self = req.check_self && cable_passes;
  req.check_bend = req.check_bend && cable_passes;
  if (!req.progress) req.progress = opt.progress;
  std::unique_ptr<ObstacleIndex> owned;
  const ObstacleIndex* index = nullptr;
  if (req.use_index || req.method == ClashMethod::Certified) {
    if (opt.index) {
      index = opt.index;
    } else {
      ProgressCounter built(opt.progress, "index", 1, "indices");
      const Stopwatch t0;
      owned = std::make_unique<EmbreeIndex>(scene.parts);
      rep.index_ms = t0.ms();
      built.finish();
      index = owned.get();
    }
    rep.index_name = index->name();
    rep.index_accuracy = index->accuracy().description;
  } else {
    rep.index_name = "none";
    rep.index_accuracy = "brute force over every triangle (double precision)";
  }
  for (const Segment& s : scene.harness.segments) rep.segment_names.push_back(s.from + "/" + s.to);
  if (scene.has_harness)
    for (auto& n : attach_ports(scene.harness, scene.parts, req.routing_clearance, inputs, index)) rep.notes.push_back(n);
  const Stopwatch t1;
  // A cable whose audit would pass a limit is refused at its element of the harness file.
  rep.result = naming_cable_errors(scene.harness, [&] { return check_clashes(inputs, scene.parts, index, req); });
  if (scene.has_harness) audit_harness_supports(scene, index, !opt.shard, rep);
  if (scene.has_harness && cable_passes && !scene.routing.separation.empty())
    rep.segregation = check_segregation(inputs, [&](int a, int b) {
      const auto& cables = scene.harness.cables;
      const auto cls = [&](int i) -> const std::string& {
        return cables[static_cast<std::size_t>(scene.harness.find_cable(inputs[static_cast<std::size_t>(i)].id))]
            .physical.cable_class;
      };
      return scene.routing.separation_between(cls(a), cls(b));
    });
  // Moving parts are certified at the audit's tolerance; the discrete method has none of
  // its own, so they take the derived default.
  const double motion_tol = rep.result.tolerance > 0.0 ? rep.result.tolerance : default_clash_tolerance(inputs);
  rep.motion = naming_cable_errors(scene.harness, [&] {
    return check_motion_clearance(inputs, scene.parts, motion_tol, req.threads);
  });
  rep.check_ms = t1.ms();
  rep.notes.insert(rep.notes.end(), rep.result.notes.begin(), rep.result.notes.end());
  for (const std::string& pair : moving_parts_interpenetrating(scene.parts))
    rep.notes.push_back("warning: moving parts " + pair + " interpenetrate in their rest poses");
  rep.notes.insert(rep.notes.end(), rep.motion.notes.begin(), rep.motion.notes.end());
  if (opt.shard) globalise_part_ids(rep, opt.shard->part_ids);
  return rep;
}

namespace {

/// "file:line" of a harness element, for messages that point at a second file.
std::string file_line(const Harness& h, int line) {
  return h.source_file + (line > 0 ? ":" + std::to_string(line) : std::string());
}

/// The two ports of a cable as an unordered pair (either end may come first in a file).
std::pair<std::string, std::string> port_pair(const Cable& c) {
  return std::minmax(c.ports[0], c.ports[1]);
}

/// Refuses a requested certified tolerance at or above the thinnest cable's radius: a
/// certified audit may miss contacts shallower than the tolerance, and at r a centerline
/// lying on a part's surface (clearance −r) is one of them.
void check_requested_tolerance(const Harness& h, const ClashRequest& req) {
  if (req.method != ClashMethod::Certified || !(req.tolerance > 0.0) || h.cables.empty()) return;
  const auto thinnest = std::min_element(h.cables.begin(), h.cables.end(), [](const Cable& a, const Cable& b) {
    return a.radius() < b.radius();
  });
  if (req.tolerance < thinnest->radius()) return;
  throw InputError({"", 0, "--tolerance"},
                   full_precision(req.tolerance) + " is not below the radius " + full_precision(thinnest->radius()) +
                       " of the thinnest cable '" + thinnest->id +
                       "': a certified audit to it could miss that cable lying on a part's surface; give a "
                       "tolerance below the radius (default: radius / 100)");
}

}  // namespace

void check_routes_match(const Harness& designed, const Harness& routes) {
  const std::string& file = routes.source_file;
  for (const Cable& c : routes.cables) {
    const SourceLocation where{file, c.line, "cable '" + c.id + "'"};
    const int d = designed.find_cable(c.id);
    if (d < 0)
      throw InputError(where, "not a cable of the scene's harness " + designed.source_file +
                                  " (routes for another harness?)");
    const Cable& want = designed.cables[static_cast<std::size_t>(d)];
    const std::string scene_says = " in the scene's harness (" + file_line(designed, want.line) + ")";
    if (port_pair(c) != port_pair(want))
      throw InputError(where, "joins ports " + c.ports[0] + " and " + c.ports[1] + ", but " + want.ports[0] + " and " +
                                  want.ports[1] + scene_says);
    if (c.physical.diameter != want.physical.diameter)
      throw InputError(where, "diameter " + full_precision(c.physical.diameter) + ", but " +
                                  full_precision(want.physical.diameter) + scene_says);
    if (c.physical.cable_class != want.physical.cable_class)
      throw InputError(where, "class '" + c.physical.cable_class + "', but '" + want.physical.cable_class + "'" +
                                  scene_says);
    if (c.physical.min_bend_radius != want.physical.min_bend_radius)
      throw InputError(where, "min_bend_radius " + full_precision(c.physical.min_bend_radius) + ", but " +
                                  full_precision(want.physical.min_bend_radius) + scene_says);
  }
  for (const Cable& want : designed.cables)
    if (routes.find_cable(want.id) < 0)
      throw InputError({file, 0, "harness '" + routes.name + "'"},
                       "has no cable '" + want.id + "' of the scene's harness (" + file_line(designed, want.line) +
                           "): it would go unchecked");
}

void apply_matching_routes(Scene& scene, const std::filesystem::path& routes) {
  std::optional<Harness> designed;
  if (scene.has_harness) designed = std::move(scene.harness);
  apply_routes(scene, routes);
  if (!designed) return;
  check_routes_match(*designed, scene.harness);
  // Routes of a harness read from KBL, with its segments between the same nodes, can be
  // written back into that file (routed.kbl).
  const auto& a = designed->segments;
  const auto& b = scene.harness.segments;
  bool same = designed->kbl && a.size() == b.size();
  for (std::size_t k = 0; same && k < a.size(); ++k) same = a[k].from == b[k].from && a[k].to == b[k].to;
  if (same) scene.harness.kbl = designed->kbl;
}

TessellationByNeed refine_for_audit(Scene& scene, const AuditOptions& opt, CadShapeStore* cad_shapes) {
  if (!scene.tessellation.by_need) return {};
  std::vector<AuditCable> ignored;
  const std::vector<CableInput> inputs =
      scene.has_harness ? audit_cable_inputs(scene.harness, ignored) : std::vector<CableInput>{};
  const double tol = opt.check.tolerance > 0.0 ? opt.check.tolerance : default_clash_tolerance(inputs);
  return tessellate_by_need(scene, inputs, tol, cad_shapes);
}

Scene load_audit_scene(const std::filesystem::path& scene_file, const AuditOptions& opt, const SceneLoadOptions& load,
                       SceneLoadReport* report) {
  Scene scene = load_scene(scene_file, load, report);
  if (opt.routes) apply_matching_routes(scene, *opt.routes);
  if (scene.has_harness) check_requested_tolerance(scene.harness, opt.check);
  return scene;
}

AuditReport audit_scene_file(const std::filesystem::path& scene_file, const AuditOptions& opt, Scene* loaded) {
  const Stopwatch t0;
  SceneLoadReport load_rep;
  SceneLoadOptions load_opt;
  load_opt.progress = opt.progress;
  load_opt.tessellate_by_need = true;
  Scene scene;
  TessellationByNeed tess;
  {
    // The coarse pass's transferred CAD files, meshed again where cables come near (kept
    // only for the scenes that ask for tessellation by need, freed once refined).
    CadShapeStore cad_shapes;
    load_opt.cad_shapes = &cad_shapes;
    scene = load_audit_scene(scene_file, opt, load_opt, &load_rep);
    tess = refine_for_audit(scene, opt, &cad_shapes);
  }
  const double load_ms = t0.ms();
  AuditReport rep = run_audit(scene, opt);
  rep.load_ms = load_ms;
  rep.tessellation = tess;
  if (tess.used) rep.notes.push_back(tessellation_note(tess));
  rep.notes.insert(rep.notes.begin(), load_rep.notes.begin(), load_rep.notes.end());
  if (loaded) *loaded = std::move(scene);
  return rep;
}

}  // namespace loom
