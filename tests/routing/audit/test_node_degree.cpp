// The audit at nodes of any degree: cables that meet at a 4-, 8- or 16-way node touch there
// without a clash (they share the node's breakout), a cable folding back through a node is a
// bend of the closed-form radius reach / tan(turn / 2) and not a self clash, and contacts
// away from the node are still clashes. Oracles: brute-force distances between centerline
// samples and the closed form of the arc that takes up a turn within the breakout.
#include "routing/audit/audit.hpp"

#include "core/harness_topology.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace loom {
namespace {

constexpr double kLeg = 200.0;   ///< hub to port, mm
constexpr double kDiameter = 4.0;
constexpr double kBend = 10.0;

/// N well-spread unit directions (a Fibonacci sphere).
std::vector<Vec3> spread(int n) {
  std::vector<Vec3> d;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double rho = std::sqrt(1.0 - z * z);
    d.emplace_back(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
  }
  return d;
}

/// A star: branch point H at the origin joined by a straight (polyline) segment to a port
/// P<i> at kLeg along each direction, its exit pointing at the hub; one cable per pair.
Harness star(const std::vector<Vec3>& dirs, const std::vector<std::pair<int, int>>& pairs) {
  Harness h;
  h.name = "star";
  h.source_file = "star.xml";
  h.branches.push_back({"H", Vec3::Zero(), 1});
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const std::string id = "P" + std::to_string(i);
    h.ports.push_back({id, kLeg * dirs[i], -dirs[i], 2});
    Segment s;
    s.from = "H";
    s.to = id;
    s.interp = Interp::Polyline;
    h.segments.push_back(s);
  }
  for (const auto& [a, b] : pairs) {
    Cable c;
    c.id = "C" + std::to_string(a) + "_" + std::to_string(b);
    c.ports[0] = "P" + std::to_string(a);
    c.ports[1] = "P" + std::to_string(b);
    c.physical.diameter = kDiameter;
    c.physical.min_bend_radius = kBend;
    h.cables.push_back(c);
  }
  return h;
}

AuditReport audit(const Harness& h, ClashMethod m) {
  Scene sc;
  sc.name = "star";
  sc.harness = h;
  sc.has_harness = true;
  AuditOptions o;
  o.check.method = m;
  o.check.threads = 1;
  return run_audit(sc, o);
}

/// Brute force: the smallest distance between samples of two cables' centerlines (0.05 mm apart).
double min_distance(const HarnessTopology& topo, int a, int b) {
  const auto ca = cable_centerline(topo, a), cb = cable_centerline(topo, b);
  double best = 1e300;
  const auto sa = ca->sample_by_arc_length(0.05), sb = cb->sample_by_arc_length(0.05);
  for (const auto& [s, p] : sa)
    for (const auto& [t, q] : sb) best = std::min(best, (p - q).norm());
  return best;
}

class NodeDegree : public ::testing::TestWithParam<int> {};

// Every pair of legs at least 90° apart carries a cable: at the hub all of them touch
// (they start there), and nothing is a clash, a self clash or a bend problem.
TEST_P(NodeDegree, CablesMeetingAtTheNodeAreNotClashes) {
  const int n = GetParam();
  const auto dirs = spread(n);
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (dirs[i].dot(dirs[j]) <= 0.0) pairs.emplace_back(i, j);
  ASSERT_GE(pairs.size(), 2u);
  const Harness h = star(dirs, pairs);
  const HarnessTopology topo(h);
  EXPECT_EQ(static_cast<int>(topo.incident_segments("H").size()), n);
  EXPECT_EQ(topo.nodes_by_degree().at(n), 1);
  // The oracle: cables on legs of their own come within the radii sum of each other.
  bool disjoint = false;
  for (std::size_t a = 0; a < pairs.size() && !disjoint; ++a)
    for (std::size_t b = a + 1; b < pairs.size() && !disjoint; ++b) {
      const auto [i, j] = pairs[a];
      const auto [k, l] = pairs[b];
      if (i == k || i == l || j == k || j == l) continue;
      disjoint = true;
      EXPECT_LT(min_distance(topo, static_cast<int>(a), static_cast<int>(b)), kDiameter);
    }
  EXPECT_TRUE(disjoint || n == 4);
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const AuditReport r = audit(h, m);
    EXPECT_TRUE(r.result.clashes.empty()) << clash_method_name(m) << ": " << r.result.clashes.size() << " clashes, first "
                                          << clash_kind_name(r.result.clashes[0].kind);
    EXPECT_TRUE(r.result.violations.empty()) << clash_method_name(m);
  }
}

// One leg 20° from another, a cable between them: it turns by 160° at the hub. Its two legs
// overlap next to the hub (a self contact by the rule |C(s) − C(t)| < 2r, |s − t| ≥ πr), which
// is the node's turn: one bend-radius violation at the hub of radius breakout / tan(80°).
TEST_P(NodeDegree, AFoldBackThroughTheNodeIsABendNotASelfClash) {
  const int n = GetParam();
  auto dirs = spread(n);
  const Vec3 axis = dirs[0].unitOrthogonal();
  dirs[1] = Eigen::AngleAxisd(20.0 * M_PI / 180.0, axis) * dirs[0];
  // The other legs keep 60° from both (the fold is the only close pair).
  for (int i = 2; i < n; ++i)
    if (dirs[i].dot(dirs[0]) > 0.5 || dirs[i].dot(dirs[1]) > 0.5) dirs[i] = -dirs[i];
  const Harness h = star(dirs, {{0, 1}});
  const HarnessTopology topo(h);
  // Oracle for the self contact: samples on the two legs πr apart along the cable and closer than 2r.
  const double r = 0.5 * kDiameter;
  bool self_contact = false;
  for (double t = M_PI * r / 2; t < 30.0; t += 0.1)
    self_contact = self_contact || (t * dirs[0] - t * dirs[1]).norm() < 2 * r;
  ASSERT_TRUE(self_contact);
  const double breakout = breakout_length(topo, "H");
  EXPECT_DOUBLE_EQ(breakout, kBend);
  const double expected = breakout / std::tan(0.5 * (M_PI - 20.0 * M_PI / 180.0));
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const AuditReport rep = audit(h, m);
    EXPECT_TRUE(rep.result.clashes.empty()) << clash_method_name(m) << ": "
                                            << clash_kind_name(rep.result.clashes[0].kind);
    ASSERT_EQ(rep.result.violations.size(), 1u) << clash_method_name(m);
    const Violation& v = rep.result.violations[0];
    EXPECT_EQ(v.kind, ViolationKind::BendRadius);
    EXPECT_NEAR(v.value, expected, 1e-9);
    EXPECT_NEAR(v.s, kLeg, 1e-9);
    EXPECT_LT(v.point.norm(), 1e-9);
    EXPECT_NEAR(rep.result.cables[0].min_bend_radius, expected, 1e-9);
  }
}

// Two legs 1e-12 rad less than a right angle apart (the cable turns by that much more): the turn is taken up within the
// breakout, which equals the bend radius, at exactly the limit — not a violation. 0.01° more
// is one.
TEST(NodeDegreeRightAngle, ATurnAtTheLimitWithinRoundingIsNotAViolation) {
  const Vec3 x = Vec3::UnitX();
  for (const double extra : {1e-12, 0.01 * M_PI / 180.0}) {
    const Vec3 y = Eigen::AngleAxisd(0.5 * M_PI - extra, Vec3::UnitZ()) * x;  // the cable turns by 90° + extra
    const Harness h = star({x, y, -x, -y}, {{0, 1}});
    const AuditReport rep = audit(h, ClashMethod::Certified);
    EXPECT_TRUE(rep.result.clashes.empty());
    EXPECT_EQ(rep.result.violations.size(), extra < 1e-9 ? 0u : 1u) << "extra turn " << extra;
  }
}

// Two cables through the node on legs of their own, one leg bent to cross the other's 150 mm
// from the hub, far outside its breakout: that contact is a cable–cable clash.
TEST_P(NodeDegree, AContactAwayFromTheNodeIsStillAClash) {
  const int n = GetParam();
  std::vector<Vec3> dirs = spread(n);
  dirs[0] = Vec3::UnitX();
  dirs[1] = -Vec3::UnitX();
  dirs[2] = Vec3::UnitY();
  dirs[3] = -Vec3::UnitY();
  for (int i = 4; i < n; ++i) dirs[i] = (dirs[i] + 2.0 * Vec3::UnitZ()).normalized();
  Harness h = star(dirs, {{0, 1}, {2, 3}});
  // Leg 2 leaves the hub along +y, crosses leg 0 (the x axis) at x = 150, then reaches P2.
  h.segments[2].path = {Vec3(0, 100, 0), Vec3(150, 0, 0), Vec3(0, 100, 50)};
  h.ports[2].position = Vec3(0, kLeg, 50);
  const HarnessTopology topo(h);
  EXPECT_LT(min_distance(topo, 0, 1), 0.05);  // the sampling step of the oracle
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const AuditReport rep = audit(h, m);
    bool found = false;
    for (const auto& c : rep.result.clashes)
      found = found || (c.kind == ClashKind::CableCable && (c.point - Vec3(150, 0, 0)).norm() < 2.0 * kDiameter);
    EXPECT_TRUE(found) << clash_method_name(m);
  }
}

INSTANTIATE_TEST_SUITE_P(Ways, NodeDegree, ::testing::Values(4, 8, 16));

/// A trunk P0 → H and two legs from H: straight on to P1 along +x, and to P2 leaving H tangent
/// to it (1 mm off the axis 40 mm out) before it turns away; `back_at` > 0 makes P2's leg come
/// back to 1 mm off the axis at x = back_at. Cables P0–P1 and P0–P2 (d 4, bend 10).
Harness tangent_legs(double back_at) {
  Harness h = star({-Vec3::UnitX(), Vec3::UnitX(), Vec3(120, 80, 0).normalized()}, {{0, 1}, {0, 2}});
  h.ports[2].position = back_at > 0 ? Vec3(back_at, 80, 0) : Vec3(120, 80, 0);
  h.segments[2].path = {Vec3(40, 1, 0), Vec3(80, 20, 0)};
  if (back_at > 0) h.segments[2].path.push_back(Vec3(back_at, 1, 0));
  return h;
}

// Legs that leave a node tangent to each other (a splice on a stub laid along the trunk)
// run together until they part, 46 mm out here, beyond twice the breakout (20 mm): their
// cables touch there by design. Where the legs meet again, it is a clash.
TEST(NodeDegreeTangent, LegsLeavingTogetherTouchOnlyUntilTheyPart) {
  const Harness h = tangent_legs(0.0);
  const HarnessTopology topo(h);
  ASSERT_LT(min_distance(topo, 0, 1), 1.0);  // the oracle: they do touch
  EXPECT_LT(2.0 * breakout_length(topo, "H"), 40.0);
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const AuditReport r = audit(h, m);
    EXPECT_TRUE(r.result.clashes.empty()) << clash_method_name(m) << ": " << r.result.clashes.size() << " clashes, first at "
                                          << r.result.clashes[0].s;
  }
  const Harness back = tangent_legs(150.0);
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const AuditReport r = audit(back, m);
    bool far = false;
    for (const auto& c : r.result.clashes) far = far || (c.kind == ClashKind::CableCable && c.point.x() > 140.0);
    EXPECT_TRUE(far) << clash_method_name(m);
    for (const auto& c : r.result.clashes) EXPECT_GT(c.point.x(), 100.0) << clash_method_name(m) << " at x " << c.point.x();
  }
}

}  // namespace
}  // namespace loom
