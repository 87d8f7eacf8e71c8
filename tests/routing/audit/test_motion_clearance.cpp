// Cable clearance over a moving part's motion against an oracle: 10⁴ evenly spaced poses,
// each with the exact brute-force distance between the cable's polyline and every moved
// triangle of the part. A hinged door (a 200 × 4 × 100 plate about the z axis, ±60°)
// passes cables placed to graze it at one angle only, to clear it, to be touched by its
// edge at one pose, and to lie inside it; a sliding block checks translations; the whole
// audit reports a cable that clears the door as drawn but is hit at 30°.
#include "routing/audit/motion_clearance.hpp"
#include "routing/audit/audit.hpp"
#include "routing/audit/report_json.hpp"
#include "index/fcl_index.hpp"
#include "index/index_test_meshes.hpp"
#include "index/triangle_distance.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace loom {
namespace {

using testmesh::box;

constexpr double kRadius = 2.0;          // cable radius
constexpr double kTolerance = 0.02;      // audit tolerance (r / 100)
constexpr int kOraclePoses = 10000;
constexpr double kDeg = M_PI / 180.0;

Part door_part() {
  Part p;
  p.name = "door";
  p.mesh = box({0, -2, 0}, {200, 2, 100});
  p.closed = true;
  Motion m;
  m.name = "hinge";
  m.kind = MotionKind::Rotate;
  m.axis_point = Vec3::Zero();
  m.axis = Vec3::UnitZ();
  m.from = -60.0;
  m.to = 60.0;
  p.motion = m;
  return p;
}

Chords polyline_chords(const std::vector<Vec3>& pts) {
  Chords c;
  double s = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i) s += (pts[i] - pts[i - 1]).norm();
    c.p.push_back(pts[i]);
    c.s.push_back(s);
  }
  return c;
}

/// A vertical cable (along z, from z = −50 to 150) at distance `rho` from the hinge axis
/// at angle `deg` about it: the door sweeps past it.
std::vector<Vec3> vertical_at(double rho, double deg) {
  const Vec3 xy(rho * std::cos(deg * kDeg), rho * std::sin(deg * kDeg), 0.0);
  return {xy + Vec3(0, 0, -50), xy + Vec3(0, 0, 40), xy + Vec3(0, 0, 150)};
}

struct OracleMin {
  double distance = 0.0;  // least centerline distance over the sampled poses (0 inside)
  double pose = 0.0;
  std::vector<double> f;  // distance at each sampled pose
  double step = 0.0;
};

/// Exact distance from the polyline to the part at pose q: every segment against every
/// moved triangle; 0 when a polyline vertex is inside the moved (closed, convex) box.
double oracle_distance(const std::vector<Vec3>& pts, const Part& p, double q) {
  const Mesh m = posed_mesh(p.mesh, *p.motion, q);
  double d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < pts.size(); ++i)
    for (const auto& t : m.triangles)
      d2 = std::min(d2, closest_segment_triangle(pts[i], pts[i + 1], m.vertices[t[0]], m.vertices[t[1]],
                                                 m.vertices[t[2]]).dist2);
  // Inside the box: its rest frame coordinates within bounds (independent of winding numbers).
  const Vec3 rest = p.motion->pose(q).inverse() * pts.front();
  const AABB b = p.mesh.bounds();
  if ((rest.array() > b.min.array()).all() && (rest.array() < b.max.array()).all()) return 0.0;
  return std::sqrt(d2);
}

OracleMin oracle(const std::vector<Vec3>& pts, const Part& p) {
  OracleMin o;
  o.distance = std::numeric_limits<double>::infinity();
  o.step = (p.motion->to - p.motion->from) / (kOraclePoses - 1);
  for (int i = 0; i < kOraclePoses; ++i) {
    const double q = p.motion->from + i * o.step;
    o.f.push_back(oracle_distance(pts, p, q));
    if (o.f.back() < o.distance) o.distance = o.f.back(), o.pose = q;
  }
  return o;
}

/// Runs motion_min_distance on the polyline and checks it against the oracle: the value
/// within the tolerance (plus the oracle's own sampling error L·step/2) and the pose one
/// where the oracle's distance is within that of its minimum.
MotionExtremum check_against_oracle(const std::vector<Vec3>& pts, const Part& p, const OracleMin& o) {
  const FclIndex fcl({p});
  const double speed = p.motion->max_point_speed(p.mesh);
  const MotionExtremum e = motion_min_distance(polyline_chords(pts), fcl, 0, p.closed, *p.motion, speed, p.mesh,
                                               0.5 * kTolerance, kRadius);
  const double oracle_err = 0.5 * speed * o.step;
  if (o.distance < kRadius) {
    // A sampled value: never below the true minimum (itself at least the oracle's less its
    // sampling error), and within the pose tolerance above it.
    EXPECT_GE(e.distance, o.distance - oracle_err - 1e-9);
    EXPECT_LE(e.distance, o.distance + 0.5 * kTolerance);
    // The reported pose: one where the oracle's distance is within the tolerance of its minimum.
    const double idx = (e.pose - p.motion->from) / o.step;
    const std::size_t lo = static_cast<std::size_t>(std::max(0.0, std::floor(idx)));
    const std::size_t hi = std::min<std::size_t>(o.f.size() - 1, lo + 1);
    EXPECT_LE(std::min(o.f[lo], o.f[hi]), o.distance + kTolerance + 2 * oracle_err) << "pose " << e.pose;
    EXPECT_NEAR(oracle_distance(pts, p, e.pose), e.distance, 1e-9);
  } else {
    EXPECT_GE(e.distance, kRadius - 0.5 * kTolerance) << "a cable the oracle clears must be proven clear";
  }
  return e;
}

TEST(MotionClearance, GrazingFaceAtOneAngleMatchesOracle) {
  const Part door = door_part();
  // The door's end face passes 0.3 inside the cable's surface at 20° only.
  const auto pts = vertical_at(200.0 + kRadius - 0.3, 20.0);
  const OracleMin o = oracle(pts, door);
  ASSERT_LT(o.distance, kRadius);
  // Closest where an edge of the end face passes, asin(2 / R) = 0.57° either side of 20°.
  ASSERT_NEAR(std::abs(o.pose - 20.0), 0.57, 0.02);
  const MotionExtremum e = check_against_oracle(pts, door, o);
  EXPECT_NEAR(e.distance - kRadius, -0.3 - (std::hypot(200.0, 2.0) - 200.0), kTolerance);
  EXPECT_NEAR(std::abs(e.pose - 20.0), 0.57, 0.1);
  EXPECT_LT(e.poses, kOraclePoses / 10) << "branch and bound should need far fewer poses than the oracle";
}

TEST(MotionClearance, EdgeTouchingAtOnePoseIsFoundWithinOneOracleStep) {
  Part door = door_part();
  // The door's corner edge (x = 200, y = 2) reaches the centerline exactly at 17.3°: a sharp
  // minimum. The other tip edge (y = −2) would reach it 1.15° later: the motion stops before.
  door.motion->to = 18.0;
  const double rc = std::hypot(200.0, 2.0), alpha = std::atan2(2.0, 200.0) / kDeg;
  const auto pts = vertical_at(rc, 17.3 + alpha);
  const OracleMin o = oracle(pts, door);
  const MotionExtremum e = check_against_oracle(pts, door, o);
  EXPECT_LT(e.distance, kTolerance);
  EXPECT_LE(std::abs(e.pose - o.pose), o.step) << "oracle " << o.pose << ", audit " << e.pose;
  EXPECT_LE(std::abs(e.pose - 17.3), o.step);
}

TEST(MotionClearance, ClearCableIsProvenClear) {
  const Part door = door_part();
  const auto pts = vertical_at(std::hypot(200.0, 2.0) + kRadius + 0.05, 35.0);
  const OracleMin o = oracle(pts, door);
  ASSERT_GT(o.distance, kRadius);
  check_against_oracle(pts, door, o);
}

TEST(MotionClearance, CableInsideTheDoorAtOnePoseHasDistanceZero) {
  const Part door = door_part();
  // A short cable in the door's mid-plane at 25°: wholly inside the plate there.
  const Vec3 u(std::cos(25 * kDeg), std::sin(25 * kDeg), 0);
  const std::vector<Vec3> pts = {50 * u + Vec3(0, 0, 20), 150 * u + Vec3(0, 0, 80)};
  const OracleMin o = oracle(pts, door);
  ASSERT_EQ(o.distance, 0.0);
  const FclIndex fcl({door});
  const MotionExtremum e = motion_min_distance(polyline_chords(pts), fcl, 0, true, *door.motion,
                                               door.motion->max_point_speed(door.mesh), door.mesh, 0.01, kRadius);
  EXPECT_EQ(e.distance, 0.0);
  // Inside over the poses where the plate (±2 thick) holds the whole centerline.
  EXPECT_EQ(oracle_distance(pts, door, e.pose), 0.0) << "pose " << e.pose;
}

TEST(MotionClearance, SlidingBlockMatchesOracle) {
  Part block;
  block.name = "slide";
  block.mesh = box({0, 0, 0}, {40, 40, 40});
  block.closed = true;
  Motion m;
  m.kind = MotionKind::Translate;
  m.axis = Vec3(1, 1, 0).normalized();
  m.from = -10;
  m.to = 90;
  block.motion = m;
  // A cable across the slide's path, 0.4 inside the cable surface of the block's top face
  // when the block is 60 along its way; not reached at rest.
  const double z = 40 + kRadius - 0.4;
  const Vec3 c = Vec3(20, 20, 0) + 60 * m.axis;
  const std::vector<Vec3> pts = {c + Vec3(-30, 30, z), c + Vec3(30, -30, z)};
  const OracleMin o = oracle(pts, block);
  ASSERT_LT(o.distance, kRadius);
  const MotionExtremum e = check_against_oracle(pts, block, o);
  EXPECT_NEAR(e.distance - kRadius, -0.4, kTolerance);
  // A face passing under the cable: clearance is −0.4 over a range of offsets that holds 60.
  EXPECT_NEAR(oracle_distance(pts, block, e.pose) - kRadius, -0.4, kTolerance);
}

/// A one-cable harness along the polyline `pts`, diameter 2r.
Harness one_cable(const std::vector<Vec3>& pts) {
  Harness h;
  h.name = "W";
  h.source_file = "w.xml";
  h.ports.push_back({"A", pts.front(), (pts[1] - pts[0]).normalized(), 1});
  h.ports.push_back({"B", pts.back(), (pts[pts.size() - 2] - pts.back()).normalized(), 2});
  Segment s;
  s.from = "A";
  s.to = "B";
  s.interp = Interp::Polyline;
  s.path.assign(pts.begin() + 1, pts.end() - 1);
  h.segments.push_back(s);
  Cable c;
  c.id = "C1";
  c.ports[0] = "A";
  c.ports[1] = "B";
  c.physical.diameter = 2 * kRadius;
  h.cables.push_back(c);
  return h;
}

AuditReport audit(const std::vector<Part>& parts, const Harness& h) {
  Scene sc;
  sc.name = "hinge";
  sc.parts = parts;
  sc.harness = h;
  sc.has_harness = true;
  sc.routing.clearance = {0.5, "test"};
  AuditOptions o;
  o.check.threads = 1;
  o.check.tolerance = kTolerance;
  return run_audit(sc, o);
}

TEST(MotionAudit, ClearAsDrawnButHitAt30DegreesIsACableMotionClash) {
  const Part door = door_part();
  const auto pts = vertical_at(150.0, 30.0);  // through the door's path, 75 mm from it as drawn
  const AuditReport rep = audit({door}, one_cable(pts));
  EXPECT_TRUE(rep.result.clashes.empty()) << "the rest pose is clear: the static audit finds nothing";
  ASSERT_EQ(rep.motion.clashes.size(), 1u);
  const MotionClash& m = rep.motion.clashes[0];
  EXPECT_NEAR(m.clearance, -kRadius, kTolerance);
  // The plate (±2 thick) crosses the centerline for poses within asin(2/150) of 30°.
  EXPECT_NEAR(m.pose, 30.0, std::asin(2.0 / 150.0) / kDeg + 1e-6);
  EXPECT_NEAR(m.point.z(), 50.0, 50.0 + 1e-9);  // on the stretch the door's height covers
  EXPECT_EQ(rep.exit_code(), 1);
  const auto j = audit_report_json(rep);
  bool found = false;
  for (const auto& c : j["clashes"])
    if (c["kind"] == "cable-motion") {
      found = true;
      EXPECT_EQ(c["part"], "door");
      EXPECT_EQ(c["pose_unit"], "deg");
      EXPECT_NEAR(c["pose"].get<double>(), m.pose, 1e-12);
    }
  EXPECT_TRUE(found);
  EXPECT_TRUE(j.contains("motion"));
}

TEST(MotionAudit, CableOutsideTheSweepIsClean) {
  const Part door = door_part();
  const AuditReport rep = audit({door}, one_cable(vertical_at(150.0, 90.0)));
  EXPECT_TRUE(rep.motion.clashes.empty());
  EXPECT_EQ(rep.exit_code(), 0);
  EXPECT_GT(rep.motion.poses, 0) << "the cable is within the door's swept cylinder: it must be checked";
}

TEST(MotionAudit, CableOutsideTheSweptCylinderCostsNoPose) {
  const Part door = door_part();
  // 250 mm from the hinge: beyond the door's reach (200.01) by more than the radius.
  const AuditReport rep = audit({door}, one_cable(vertical_at(250.0, 10.0)));
  EXPECT_TRUE(rep.motion.clashes.empty());
  EXPECT_EQ(rep.motion.poses, 0);
  // 203 mm: within the cylinder by a hair, so checked, and clear.
  const AuditReport near = audit({door}, one_cable(vertical_at(std::hypot(200.0, 2.0) + kRadius - 0.5, 70.0)));
  EXPECT_TRUE(near.motion.clashes.empty());
  EXPECT_GT(near.motion.poses, 0);
}

TEST(MotionAudit, InterpenetratingMovingPartsAreWarnedByName) {
  Part a = door_part();
  Part b = door_part();
  b.name = "flap";
  b.mesh = box({100, -5, 40}, {120, 5, 60});  // through the door plate
  Part c = door_part();
  c.name = "apart";
  c.mesh = box({100, 10, 40}, {120, 20, 60});
  const AuditReport rep = audit({a, b, c}, one_cable(vertical_at(150.0, 90.0)));
  int warned = 0;
  for (const auto& n : rep.notes)
    if (n.find("warning: moving parts") != std::string::npos) {
      ++warned;
      EXPECT_NE(n.find("'door' and 'flap'"), std::string::npos) << n;
    }
  EXPECT_EQ(warned, 1);
}

}  // namespace
}  // namespace loom
