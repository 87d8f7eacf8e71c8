// Routing around a moving part: a 100 mm door hinged beside the straight way between two
// ports swings 30° across it. Planned around its swept envelope, the route has no
// cable-motion clash (the exact audit says so); planned around the drawn pose only, the
// same scene's route is crushed at some angle. Planner bounded by iterations.
#include "routing/route/motion_envelope.hpp"
#include "routing/route/route_pipeline.hpp"
#include "index/index_test_meshes.hpp"

#include <gtest/gtest.h>

namespace loom {
namespace {

using testmesh::box;

Scene door_scene(bool moving) {
  Scene sc;
  sc.name = "door";
  Part door;
  door.name = "door";
  door.mesh = box({150, 38, 0}, {250, 42, 100});  // along +x at rest, 38 mm beside the way
  door.closed = true;
  if (moving) {
    Motion m;
    m.kind = MotionKind::Rotate;
    m.axis_point = Vec3(150, 40, 0);
    m.axis = Vec3::UnitZ();
    m.from = -30;  // swings its tip to y = −10, across the way at y = 0
    m.to = 0;
    door.motion = m;
  }
  sc.parts.push_back(door);
  Harness& h = sc.harness;
  h.name = "W";
  h.source_file = "w.xml";
  h.ports.push_back({"A", {0, 0, 50}, {1, 0, 0}, 1});
  h.ports.push_back({"B", {400, 0, 50}, {-1, 0, 0}, 2});
  Segment s;
  s.from = "A";
  s.to = "B";
  h.segments.push_back(s);
  Cable c;
  c.id = "C1";
  c.ports[0] = "A";
  c.ports[1] = "B";
  c.physical.diameter = 4.0;
  c.physical.min_bend_radius = 20.0;
  h.cables.push_back(c);
  sc.has_harness = true;
  sc.routing.clearance = {3.0, "test"};
  sc.routing.time_limit = {30.0, "test"};
  sc.routing.iterations = {3000, "test"};
  return sc;
}

RouteReport route(const Scene& sc) {
  RouteOptions o;
  o.threads = 1;
  return route_scene(sc, o);
}

TEST(MotionRoute, PlannedAroundTheSweptEnvelopeHasNoCableMotionClash) {
  const Scene sc = door_scene(true);
  const RouteReport rep = route(sc);
  ASSERT_TRUE(rep.unrouted.empty());
  EXPECT_TRUE(rep.audit.motion.clashes.empty());
  EXPECT_GT(rep.audit.motion.poses, 0);
  bool noted = false;
  for (const auto& n : rep.notes) noted = noted || n.find("swept envelope") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(MotionRoute, PlannedAroundTheRestPoseOnlyIsCrushed) {
  const RouteReport fixed = route(door_scene(false));
  ASSERT_TRUE(fixed.unrouted.empty());
  // The straight way is clear of the drawn door: audit the same route with the motion.
  Scene moving = door_scene(true);
  moving.harness = fixed.routed;
  AuditOptions o;
  o.check.threads = 1;
  const AuditReport rep = run_audit(moving, o);
  EXPECT_TRUE(rep.result.clashes.empty());
  EXPECT_FALSE(rep.motion.clashes.empty()) << "a route planned around one pose is hit during the motion";
}

TEST(MotionRoute, EnvelopeCopiesAreAtMostTheGapApart) {
  const Scene sc = door_scene(true);
  std::vector<Part> out;
  std::vector<std::string> notes;
  const std::size_t n = append_swept_envelopes(sc.parts, 3.0, "mm", out, notes);
  // The tip is 100 mm from the axis: 30° is 52.4 mm of travel, 18 steps of ≤ 3 mm.
  EXPECT_EQ(n, 19u);
  ASSERT_EQ(out.size(), n);
  EXPECT_FALSE(out.front().motion.has_value());
  AABB box;
  extend_by_swept_envelopes(sc.parts, 3.0, box);
  EXPECT_LT(box.min.y(), -10.0);  // the tip's lowest reach, sin 30° · 100 − 40, grown by the gap
}

}  // namespace
}  // namespace loom
