// Harness-aware planning: the capsule obstacles of routed bundles (against a brute-force
// oracle), their cut-back near a shared node (closed form), and a hand-made harness whose two
// segments clash when each is planned among the parts only and do not when the second is
// planned among the first's bundle too (the audit is the judge); the same crossing with the
// two bundles in separated classes, planned apart by the separation; a bundle routed first
// past a branch point whose legs come later (it keeps off their breakouts); router-placed
// nodes of separated classes kept apart; and the crossing
// planned with the voxel layer in front of Embree (clean, the map deciding part of the queries).
#include "core/io/harness_xml.hpp"
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "index/triangle_distance.hpp"
#include "routing/audit/audit.hpp"
#include "routing/route/bundle_obstacles.hpp"
#include "routing/route/route_pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace loom {
namespace {

/// Brute force: distance from segment ab to the nearest capsule surface (∞ if none).
double brute_capsule_distance(const std::vector<BundleTube>& tubes, const Vec3& a, const Vec3& b) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : tubes)
    for (std::size_t i = 0; i + 1 < t.points.size(); ++i) {
      const auto r = closest_segment_segment(a, b, t.points[i], t.points[i + 1]);
      best = std::min(best, std::max(0.0, std::sqrt(r.dist2) - t.radius));
    }
  return best;
}

TEST(HarnessAware, CapsuleQueriesMatchBruteForce) {
  // Parts far away from every capsule and query, so that only the capsules answer.
  const std::vector<Part> parts{testmesh::box_part("far", Vec3(1000, 1000, 1000), Vec3(1001, 1001, 1001))};
  const EmbreeIndex embree(parts);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-50.0, 50.0), rad(0.5, 4.0);
  std::vector<BundleTube> tubes;
  for (int t = 0; t < 12; ++t) {
    BundleTube tube;
    tube.segment = 100 + t;
    tube.radius = rad(rng);
    Vec3 p(u(rng), u(rng), u(rng));
    for (int i = 0; i < 9; ++i) {
      tube.points.push_back(p);
      p += 0.2 * Vec3(u(rng), u(rng), u(rng));
    }
    tubes.push_back(tube);
  }
  const HarnessAwareIndex index(embree, tubes);
  EXPECT_EQ(index.capsule_count(), 12u * 8u);
  EXPECT_EQ(index.part_count(), 1 + 12);
  for (int q = 0; q < 400; ++q) {
    const Vec3 a(u(rng), u(rng), u(rng));
    const Vec3 b = q % 2 ? a : Vec3(a + 0.3 * Vec3(u(rng), u(rng), u(rng)));
    const double want = brute_capsule_distance(tubes, a, b);
    const ClosestHit hit = index.segment_closest(a, b, std::numeric_limits<double>::infinity(), nullptr);
    ASSERT_TRUE(hit.found());
    EXPECT_NEAR(hit.distance, want, 1e-9) << "query " << q;
    EXPECT_GE(index.bundle_segment(hit.part), 100);
    const double r = want + (q % 3 == 0 ? -1e-6 : 1e-6);
    EXPECT_EQ(index.segment_within(a, b, r), r >= want) << "query " << q;
    if (q % 2) {
      EXPECT_NEAR(index.closest(a, std::numeric_limits<double>::infinity()).distance, want, 1e-9);
      EXPECT_EQ(index.any_within(a, r), r >= want);
    }
  }
  EXPECT_EQ(index.bundle_segment(0), -1);  // a part
  EXPECT_THROW(index.part_bounds(1 + 12), std::out_of_range);
  EXPECT_THROW(index.segment_closest_on_part(Vec3::Zero(), Vec3::UnitX(), 1 + 12, 1.0, nullptr), std::out_of_range);
  ASSERT_TRUE(index.part_bounds(1).has_value());  // tube 0: its points inflated by its radius
  EXPECT_TRUE(index.part_bounds(1)->contains(tubes[0].points.front()));
}

TEST(HarnessAware, ClipNearNodeCutsTheBallOut) {
  // The x axis from −10 to 10 through a ball of radius 3 at the origin: two runs, cut on the sphere.
  const std::vector<Vec3> line{Vec3(-10, 0, 0), Vec3(-1, 0, 0), Vec3(10, 0, 0)};
  const auto runs = clip_near_node(line, Vec3::Zero(), 3.0);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_NEAR((runs[0].front() - Vec3(-10, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((runs[0].back() - Vec3(-3, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((runs[1].front() - Vec3(3, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((runs[1].back() - Vec3(10, 0, 0)).norm(), 0.0, 1e-12);
  // A leg leaving the node: only the run beyond the ball stays; one wholly inside vanishes.
  const auto leg = clip_near_node({Vec3::Zero(), Vec3(0, 5, 0)}, Vec3::Zero(), 3.0);
  ASSERT_EQ(leg.size(), 1u);
  EXPECT_NEAR((leg[0].front() - Vec3(0, 3, 0)).norm(), 0.0, 1e-12);
  EXPECT_TRUE(clip_near_node({Vec3::Zero(), Vec3(0, 2, 0)}, Vec3::Zero(), 3.0).empty());
}

std::string port_xml(const std::string& id, const Vec3& at, const Vec3& dir) {
  auto f = [](double v) { return std::to_string(v); };
  return "<port id=\"" + id + "\" x=\"" + f(at.x()) + "\" y=\"" + f(at.y()) + "\" z=\"" + f(at.z()) + "\" dx=\"" +
         f(dir.x()) + "\" dy=\"" + f(dir.y()) + "\" dz=\"" + f(dir.z()) + "\"/>\n";
}

/// A 4 mm cable between two ports; `cls` (if not empty) is its class.
std::string cable_xml(const std::string& id, const std::string& p1, const std::string& p2, const std::string& cls = "") {
  return "<cable id=\"" + id + "\"><electrical><port id=\"" + p1 + "\"/><port id=\"" + p2 +
         "\"/></electrical><physical type=\"T\" color=\"red\" diameter=\"4\" min_bend_radius=\"10\"" +
         (cls.empty() ? std::string() : " class=\"" + cls + "\"") + "/></cable>\n";
}

/// Two bundles crossing in empty space: A1–A2 along x (two cables, so it is routed first),
/// B1–B2 along y, straight lines meeting at the origin; a slab far below bounds the scene.
/// `b1` moves the first port of B; `a_class` and `b_class` are the classes of A's and B's cables.
Scene crossing_scene(const Vec3& b1 = Vec3(0, -100, 0), const std::string& a_class = "", const std::string& b_class = "") {
  std::string x = "<harness name=\"H\" units=\"mm\"><attributes>\n";
  x += cable_xml("C1", "A1", "A2", a_class) + cable_xml("C2", "A1", "A2", a_class) + cable_xml("C3", "B1", "B2", b_class);
  x += "</attributes><structure>\n";
  x += port_xml("A1", Vec3(-100, 0, 0), Vec3::UnitX()) + port_xml("A2", Vec3(100, 0, 0), -Vec3::UnitX());
  x += port_xml("B1", b1, Vec3::UnitY()) + port_xml("B2", Vec3(0, 100, 0), -Vec3::UnitY());
  x += "<segment from=\"A1\" to=\"A2\"/>\n<segment from=\"B1\" to=\"B2\"/>\n</structure></harness>\n";
  Scene sc;
  sc.name = "crossing";
  sc.parts.push_back(testmesh::box_part("slab", Vec3(-120, -120, -60), Vec3(120, 120, -50)));
  sc.harness = parse_harness_xml(x, "crossing.xml");
  sc.has_harness = true;
  sc.routing.clearance = {2.0, "test"};
  sc.routing.time_limit = {30.0, "test"};
  sc.routing.iterations = {3000, "test"};
  sc.routing.planner = "informedrrtstar";
  sc.routing.seed = 3;
  sc.simplify.dim_pre = {4.0, "test"};
  return sc;
}

std::size_t cable_cable_clashes(const RouteReport& rep) {
  std::size_t n = 0;
  for (const auto& c : rep.audit.result.clashes) n += c.kind == ClashKind::CableCable;
  return n;
}

TEST(HarnessAware, SecondSegmentGoesAroundTheFirst) {
  const Scene sc = crossing_scene();
  RouteOptions opt;
  opt.threads = 2;
  opt.harness_aware = false;  // among the parts only: both straight, crossing at the origin
  const RouteReport blind = route_scene(sc, opt);
  ASSERT_TRUE(blind.unrouted.empty());
  EXPECT_GT(cable_cable_clashes(blind), 0u);
  opt.harness_aware = true;
  const RouteReport aware = route_scene(sc, opt);
  ASSERT_TRUE(aware.unrouted.empty());
  EXPECT_EQ(cable_cable_clashes(aware), 0u);
  EXPECT_EQ(aware.audit.result.clashes.size(), 0u);
  EXPECT_EQ(aware.exit_code(), 0);
}

TEST(HarnessAware, ABlockedSegmentIsPlannedFirstAndItsBlockerAroundIt) {
  // B1 sits right beside where A's straight bundle runs, its exit through it: planned after
  // A, B cannot leave its port. Planned before A (A then re-planned around B) both route.
  const Scene sc = crossing_scene(Vec3(0, -3, 0));
  RouteOptions opt;
  opt.threads = 2;
  const RouteReport rep = route_scene(sc, opt);
  EXPECT_TRUE(rep.unrouted.empty()) << (rep.unrouted.empty() ? "" : rep.unrouted.front().message);
  bool noted = false;
  for (const auto& n : rep.notes)
    noted = noted || n.find("segment B1 -> B2 was blocked by the bundle of segment A1 -> A2") != std::string::npos;
  EXPECT_TRUE(noted);
  EXPECT_EQ(cable_cable_clashes(rep), 0u);
}

TEST(HarnessAware, SeparatedClassesArePlannedApart) {
  // A (power) and B (signal) cross: among A's bundle B keeps the routing clearance only,
  // closer than a 30 mm separation; with the separation in the scene B is planned around A's
  // bundle grown by it, and the segregation audit of the route finds nothing.
  constexpr double kSeparation = 30.0;
  Scene sc = crossing_scene(Vec3(0, -100, 0), "power", "signal");
  RouteOptions opt;
  opt.threads = 2;
  const RouteReport near = route_scene(sc, opt);
  ASSERT_TRUE(near.unrouted.empty());
  Scene judged = sc;
  judged.harness = near.routed;
  judged.routing.separation[{"power", "signal"}] = kSeparation;
  AuditOptions ao;
  ao.check.threads = 2;
  EXPECT_FALSE(run_audit(judged, ao).segregation.empty());

  sc.routing.separation[{"power", "signal"}] = kSeparation;
  const RouteReport apart = route_scene(sc, opt);
  ASSERT_TRUE(apart.unrouted.empty()) << apart.unrouted.front().message;
  EXPECT_TRUE(apart.audit.segregation.empty())
      << "closest " << apart.audit.segregation.front().distance << " at " << full_precision(apart.audit.segregation.front().point);
  EXPECT_TRUE(apart.audit.result.clashes.empty());
}

// A bundle routed first (A1–A2, three cables) whose straight way runs through a branch point
// fixed by the file (N, legs still to be routed, fewer cables): it keeps off N's breakouts,
// so N's legs start clear of it and every cable is routed without a contact.
TEST(HarnessAware, AnEarlierBundleKeepsOffTheBreakoutsOfANodeStillToBeRouted) {
  std::string x = "<harness name=\"H\" units=\"mm\"><attributes>\n";
  x += cable_xml("C1", "A1", "A2") + cable_xml("C2", "A1", "A2") + cable_xml("C3", "A1", "A2");
  x += cable_xml("C4", "B1", "B2") + cable_xml("C5", "B1", "B3");
  x += "</attributes><structure>\n";
  x += port_xml("A1", Vec3(-100, 0, 0), Vec3::UnitX()) + port_xml("A2", Vec3(100, 0, 0), -Vec3::UnitX());
  x += port_xml("B1", Vec3(0, -100, 0), Vec3::UnitY()) + port_xml("B2", Vec3(0, 100, 0), -Vec3::UnitY());
  x += port_xml("B3", Vec3(0, 0, 100), -Vec3::UnitZ());
  x += "<segment from=\"A1\" to=\"A2\"/>\n";
  x += "<branch id=\"N\" x=\"0\" y=\"0\" z=\"0\"><segment to=\"B1\"/><segment to=\"B2\"/><segment to=\"B3\"/></branch>\n";
  x += "</structure></harness>\n";
  Scene sc = crossing_scene();
  sc.harness = parse_harness_xml(x, "node.xml");
  RouteOptions opt;
  opt.threads = 2;
  const RouteReport rep = route_scene(sc, opt);
  EXPECT_TRUE(rep.unrouted.empty()) << (rep.unrouted.empty() ? "" : rep.unrouted.front().message);
  EXPECT_EQ(cable_cable_clashes(rep), 0u);
  // A1–A2's curve keeps its radius, N's bundle radius and the clearance from N.
  const HarnessTopology topo(rep.routed);
  const auto& segs = rep.routed.segments;
  const int ia = static_cast<int>(std::find_if(segs.begin(), segs.end(),
                                               [](const Segment& g) { return g.from == "A1" && g.to == "A2"; }) -
                                  segs.begin());
  ASSERT_LT(ia, static_cast<int>(segs.size()));
  const Segment& a = rep.routed.segments[static_cast<std::size_t>(ia)];
  ASSERT_TRUE(a.bspline.has_value());
  const Centerline c(a.bspline->degree, a.bspline->knots, a.bspline->control_points);
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [s, p] : c.sample_by_arc_length(0.5)) nearest = std::min(nearest, p.norm());
  double leg_radius = 0.0;
  for (int t : topo.incident_segments("N")) leg_radius = std::max(leg_radius, topo.segment_diameter(t) / 2.0);
  EXPECT_GT(nearest, topo.segment_diameter(ia) / 2.0 + leg_radius + sc.routing.clearance.value - 1e-6);
}

// Two Y harnesses, power and data, each with its branch point left to the router: six
// ports 100 mm around the z axis, 60° apart, the data ports 15 mm above the power ports, so
// the geometric medians of the two nodes lie on the axis 15 mm apart. The nodes were kept
// only a bundle diameter apart, inside the separation of their classes, and the legs of the
// node routed second could not start beside the bundles of the first. Nodes of separated
// classes now keep the separation plus their bundles and breakouts apart.
TEST(HarnessAware, RouterPlacedNodesOfSeparatedClassesKeepTheSeparation) {
  constexpr double kSeparation = 20.0;
  std::string x = "<harness name=\"H\" units=\"mm\"><attributes>\n";
  x += cable_xml("P1", "A1", "A2", "power") + cable_xml("P2", "A1", "A3", "power");
  x += cable_xml("D1", "B1", "B2", "data") + cable_xml("D2", "B1", "B3", "data");
  x += "</attributes><structure>\n";
  for (int k = 0; k < 6; ++k) {
    const double a = k * M_PI / 3.0;
    const Vec3 out(std::cos(a), std::sin(a), 0.0);
    const bool power = k % 2 == 0;
    x += port_xml((power ? "A" : "B") + std::to_string(k / 2 + 1), 100.0 * out + Vec3(0, 0, power ? 0.0 : 15.0), -out);
  }
  x += "<branch id=\"NP\"><segment to=\"A1\"/><segment to=\"A2\"/><segment to=\"A3\"/></branch>\n";
  x += "<branch id=\"ND\"><segment to=\"B1\"/><segment to=\"B2\"/><segment to=\"B3\"/></branch>\n";
  x += "</structure></harness>\n";
  Scene sc = crossing_scene();
  sc.harness = parse_harness_xml(x, "two-y.xml");
  sc.routing.separation[{"data", "power"}] = kSeparation;
  RouteOptions opt;
  opt.threads = 2;
  const RouteReport rep = route_scene(sc, opt);
  EXPECT_TRUE(rep.unrouted.empty()) << (rep.unrouted.empty() ? "" : rep.unrouted.front().message);
  EXPECT_TRUE(rep.audit.result.clashes.empty());
  EXPECT_TRUE(rep.audit.segregation.empty())
      << "closest " << rep.audit.segregation.front().distance << " at " << full_precision(rep.audit.segregation.front().point);
  const auto np = rep.routed.node_position("NP"), nd = rep.routed.node_position("ND");
  ASSERT_TRUE(np && nd);
  EXPECT_GT((*np - *nd).norm(), kSeparation + 2.0 + 2.0 + sc.routing.clearance.value)
      << full_precision(*np) << " and " << full_precision(*nd);
}

TEST(HarnessAware, VoxelLayerDecidesQueriesAndKeepsTheRouteClean) {
  const Scene sc = crossing_scene();
  RouteOptions opt;
  opt.threads = 2;
  const RouteReport plain = route_scene(sc, opt);
  EXPECT_EQ(plain.voxel_resolution, 0.0);
  EXPECT_EQ(plain.voxel_decided, 0u);
  EXPECT_GT(plain.voxel_exact, 0u);
  opt.voxel_layer = true;
  const RouteReport layered = route_scene(sc, opt);
  ASSERT_TRUE(layered.unrouted.empty());
  EXPECT_GT(layered.voxel_resolution, 0.0);
  EXPECT_GT(layered.voxel_decided, 0u);
  EXPECT_TRUE(layered.audit.result.clashes.empty());
  EXPECT_EQ(layered.exit_code(), plain.exit_code());
}

}  // namespace
}  // namespace loom
