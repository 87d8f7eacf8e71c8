// Segregation audit: a power and a signal cable forced through one 30 mm hole in a wall
// (each bends from 100 mm off the axis to 5 mm off it at the hole, mirrored), and two
// cables of separated classes sharing a bundle segment. Oracles: brute-force distances
// between dense centreline samples and the closed form of the stretch closer than required.
#include "routing/audit/audit.hpp"
#include "routing/audit/report_json.hpp"
#include "common/support_fixtures.hpp"
#include "core/harness_topology.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

namespace loom {
namespace {

constexpr double kDiameter = 2.0;

/// Cable `id` from (0, y, 0) through (500, y_hole, 0) to (1000, y, 0), a polyline.
void add_cable(Harness& h, const std::string& id, double y, double y_hole, const std::string& cls) {
  h.ports.push_back({id + ".a", {0, y, 0}, {1, 0, 0}, 1});
  h.ports.push_back({id + ".b", {1000, y, 0}, {-1, 0, 0}, 2});
  Segment s;
  s.from = id + ".a";
  s.to = id + ".b";
  s.interp = Interp::Polyline;
  s.path = {{500, y_hole, 0}};
  h.segments.push_back(s);
  Cable c;
  c.id = id;
  c.ports[0] = s.from;
  c.ports[1] = s.to;
  c.physical.diameter = kDiameter;
  c.physical.cable_class = cls;
  h.cables.push_back(c);
}

AuditReport audit(const Harness& h, double separation, std::vector<Part> parts = {}) {
  Scene sc;
  sc.name = "hole";
  sc.harness = h;
  sc.has_harness = true;
  sc.parts = std::move(parts);
  sc.routing.clearance = {0.5, "test"};
  if (separation > 0.0) sc.routing.separation[{"power", "signal"}] = separation;
  AuditOptions o;
  o.check.threads = 1;
  return run_audit(sc, o);
}

Harness through_hole(const std::string& cls1, const std::string& cls2) {
  Harness h;
  h.name = "hole";
  h.source_file = "hole.xml";
  add_cable(h, "P", -100, -5, cls1);
  add_cable(h, "S", 100, 5, cls2);
  return h;
}

TEST(Segregation, TwoClassesForcedThroughOneHole) {
  // A wall at x = 500 with a 30 mm square hole: the cables pass it 10 mm apart.
  const std::vector<Part> wall = {test::box_part("wall-low", {495, -200, -50}, {505, -15, 50}),
                                  test::box_part("wall-high", {495, 15, -50}, {505, 200, 50})};
  const Harness h = through_hole("power", "signal");
  const AuditReport rep = audit(h, 50.0, wall);
  EXPECT_TRUE(rep.result.clashes.empty());
  ASSERT_EQ(rep.segregation.size(), 1u);
  const SegregationFinding& f = rep.segregation[0];
  EXPECT_EQ(rep.check_ids[static_cast<std::size_t>(f.cable)], "P");
  EXPECT_EQ(rep.check_ids[static_cast<std::size_t>(f.other)], "S");
  EXPECT_NEAR(f.distance, 10.0 - kDiameter, 1e-6);  // at the hole
  EXPECT_DOUBLE_EQ(f.required, 50.0);
  const double leg = std::hypot(500.0, 95.0);
  EXPECT_NEAR(f.s, leg, 1e-6);
  EXPECT_NEAR(f.s_other, leg, 1e-6);
  EXPECT_NEAR((f.point - Vec3(500, 0, 0)).norm(), 0.0, 1e-6);
  EXPECT_EQ(rep.exit_code(), 1);

  // Brute force over samples 1 mm apart (the gap grows by 0.38 per mm along x near the
  // hole): the reported closest approach is no farther, and within that of it.
  HarnessTopology topo(h);
  const auto pc = cable_centerline(topo, 0), sc = cable_centerline(topo, 1);
  double best = 1e300;
  const auto qs = sc->sample_by_arc_length(1.0);
  for (const auto& [s, p] : pc->sample_by_arc_length(1.0))
    for (const auto& [t, q] : qs) best = std::min(best, (p - q).norm() - kDiameter);
  EXPECT_LE(f.distance, best + 1e-9);
  EXPECT_NEAR(best, f.distance, 0.4);

  const auto j = audit_report_json(rep);
  int seen = 0;
  for (const auto& v : j["violations"])
    if (v["kind"] == "segregation") {
      ++seen;
      EXPECT_EQ(v["other"], "S");
      EXPECT_NEAR(v["distance"].get<double>(), 8.0, 1e-6);
      EXPECT_EQ(v["required"], 50.0);
    }
  EXPECT_EQ(seen, 1);
}

TEST(Segregation, OnlySeparatedClassesCloserThanRequired) {
  EXPECT_TRUE(audit(through_hole("power", "power"), 50.0).segregation.empty());  // no separation given
  EXPECT_TRUE(audit(through_hole("power", ""), 50.0).segregation.empty());       // no class
  EXPECT_TRUE(audit(through_hole("power", "signal"), 7.9).segregation.empty());  // 8 mm apart
  EXPECT_EQ(audit(through_hole("power", "signal"), 8.1).segregation.size(), 1u);
  EXPECT_TRUE(audit(through_hole("power", "signal"), 0.0).segregation.empty());  // no table
}

TEST(Segregation, SharedBundleSegmentIsAViolation) {
  // Y harness: A and A2 join at branch J, the trunk J → B carries both cables.
  Harness h;
  h.name = "y";
  h.source_file = "y.xml";
  h.ports.push_back({"A", {0, -200, 0}, {1, 0, 0}, 1});
  h.ports.push_back({"A2", {0, 200, 0}, {1, 0, 0}, 2});
  h.ports.push_back({"B", {1000, 0, 0}, {-1, 0, 0}, 3});
  h.branches.push_back({"J", Vec3(400, 0, 0), 4});
  for (const char* to : {"A", "A2", "B"}) {
    Segment s;
    s.from = "J";
    s.to = to;
    s.interp = Interp::Polyline;
    h.segments.push_back(s);
  }
  for (const auto& [id, from, cls] : {std::tuple{"P", "A", "power"}, std::tuple{"S", "A2", "signal"}}) {
    Cable c;
    c.id = id;
    c.ports[0] = from;
    c.ports[1] = "B";
    c.physical.diameter = kDiameter;
    c.physical.cable_class = cls;
    h.cables.push_back(c);
  }
  const AuditReport rep = audit(h, 50.0);
  ASSERT_FALSE(rep.segregation.empty());
  int shared = 0;
  for (const SegregationFinding& f : rep.segregation)
    if (f.segment >= 0) {
      ++shared;
      EXPECT_EQ(rep.segment_names[static_cast<std::size_t>(f.segment)], "J/B");
      EXPECT_DOUBLE_EQ(f.distance, 0.0);
    } else {
      // Beside the trunk the legs converge on J: within 50 + 2 mm of each other only near it.
      EXPECT_LE((f.point - Vec3(400, 0, 0)).norm(), 200.0);
    }
  EXPECT_EQ(shared, 1);
}

}  // namespace
}  // namespace loom
