// Tests of the OMPL planning core and the port check: closed-form box scenes built as meshes, planned
// against BruteForceIndex / EmbreeIndex (exact triangles) and checked against an independent
// oracle — the closed-form distance to solid axis-aligned boxes, sampled densely (spacing
// required/50) along every key-point segment. The planner's capsule checks are exact, so the
// sampled distance must never fall below radius + clearance (up to rounding).

#include "core/mesh.hpp"
#include "core/part.hpp"
#include "index/brute_force_index.hpp"
#include "index/embree_index.hpp"
#include "routing/route/path_planner.hpp"
#include "routing/route/port_check.hpp"
#include "routing/route/tube_validity.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <ompl/base/spaces/RealVectorStateSpace.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace loom {
namespace {

/// OMPL's process seed must be set before any OMPL random generator exists (the validity
/// tests below create some): set it at static initialisation.
const std::uint32_t kProcessSeed = seed_ompl_once(7);

// --- scenes -----------------------------------------------------------------------------

struct Box {
  Vec3 lo, hi;
};

/// Closed, outward-oriented 12-triangle mesh of a box.
Mesh box_mesh(const Box& b) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? b.hi.x() : b.lo.x(), (i & 2) ? b.hi.y() : b.lo.y(),
                            (i & 4) ? b.hi.z() : b.lo.z());
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  const Vec3 c = 0.5 * (b.lo + b.hi);
  for (const auto& q : quads) {
    for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      const Vec3 a = m.vertices[t[0]], bb = m.vertices[t[1]], cc = m.vertices[t[2]];
      const Vec3 n = (bb - a).cross(cc - a);
      const bool outward = n.dot((a + bb + cc) / 3.0 - c) > 0.0;
      m.triangles.push_back(outward ? std::array<std::uint32_t, 3>{std::uint32_t(t[0]), std::uint32_t(t[1]),
                                                                   std::uint32_t(t[2])}
                                    : std::array<std::uint32_t, 3>{std::uint32_t(t[0]), std::uint32_t(t[2]),
                                                                   std::uint32_t(t[1])});
    }
  }
  return m;
}

/// A scene of boxes: parts for the index, and the boxes themselves for the oracle.
struct Scene {
  std::vector<Box> boxes;
  std::vector<Part> parts() const {
    std::vector<Part> ps;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      Part p;
      p.name = "box" + std::to_string(i);
      p.mesh = box_mesh(boxes[i]);
      p.closed = true;
      ps.push_back(std::move(p));
    }
    return ps;
  }
  /// Closed-form distance from p to the nearest solid box (0 inside).
  double distance(const Vec3& p) const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& b : boxes) {
      const Vec3 d = (b.lo - p).cwiseMax(p - b.hi).cwiseMax(Vec3::Zero());
      best = std::min(best, d.norm());
    }
    return best;
  }
};

AABB cube(double lo, double hi) {
  AABB b;
  b.extend(Vec3::Constant(lo));
  b.extend(Vec3::Constant(hi));
  return b;
}

constexpr double kRadius = 2.0;
constexpr double kClearance = 1.0;
constexpr double kRequired = kRadius + kClearance;
/// Oracle sampling step along key-point segments.
constexpr double kOracleStep = kRequired / 50.0;
/// Rounding slack of the oracle comparison (scene size ~100).
constexpr double kOracleSlack = 1e-7;
/// Iteration budget of a plan that is expected to succeed.
constexpr std::uint64_t kIterations = 1000;
/// Safety cap on a plan's wall time, seconds; a budgeted plan on these scenes ends well before.
constexpr double kTimeCap = 60.0;

PlanRequest base_request(const std::string& planner = "rrtconnect") {
  PlanRequest r;
  r.radius = kRadius;
  r.clearance = kClearance;
  r.scene_box = cube(0, 100);
  r.planner = planner;
  // Runs end on their first solution (rrtconnect, rrt, lazyprm) or on this iteration budget,
  // never on the clock: the time limit is a safety cap far above what the budget needs.
  r.max_iterations = kIterations;
  r.time_limit = kTimeCap;
  r.seed = 7;
  r.start = {Vec3(10, 50, 50), Vec3::UnitX()};
  r.goal = {Vec3(90, 50, 50), -Vec3::UnitX()};
  return r;
}

/// Minimum oracle distance over dense samples of the polyline.
double oracle_min_distance(const Scene& s, const std::vector<Vec3>& pts) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double len = (pts[i] - pts[i - 1]).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(len / kOracleStep)));
    for (int k = 0; k <= n; ++k) best = std::min(best, s.distance(pts[i - 1] + (pts[i] - pts[i - 1]) * (double(k) / n)));
  }
  return best;
}

/// Everything a solved route must satisfy.
void expect_valid_route(const Scene& s, const PlanRequest& req, const PlanResult& r) {
  ASSERT_TRUE(r.solved()) << reason_name(r.reason) << ": " << r.message;
  ASSERT_GE(r.key_points.size(), 2u);
  EXPECT_EQ(r.key_points.front(), req.start.position);
  EXPECT_EQ(r.key_points.back(), req.goal.position);
  // Straight stubs along the exit directions.
  const double stub = r.stub_length;
  EXPECT_NEAR((r.key_points[1] - (req.start.position + stub * req.start.exit_direction.normalized())).norm(), 0.0, 1e-9);
  const auto& pen = r.key_points[r.key_points.size() - 2];
  EXPECT_NEAR((pen - (req.goal.position + stub * req.goal.exit_direction.normalized())).norm(), 0.0, 1e-9);
  const double d = oracle_min_distance(s, r.key_points);
  EXPECT_GE(d, kRequired - kOracleSlack);
  EXPECT_GE(r.min_clearance, kClearance - kOracleSlack);
  EXPECT_NEAR(r.min_clearance, d - kRadius, kOracleStep);  // the oracle samples; the index is exact
  double len = 0;
  for (std::size_t i = 1; i < r.key_points.size(); ++i) len += (r.key_points[i] - r.key_points[i - 1]).norm();
  EXPECT_NEAR(r.length, len, 1e-9 * len);
  EXPECT_GE(r.cost, r.lower_bound - 1e-9);
  EXPECT_TRUE(std::isfinite(r.cost));
  EXPECT_TRUE(std::isfinite(r.time_ms));
}

/// A box in the middle, off the straight line: the straight route is free.
Scene easy_scene() { return Scene{{{Vec3(40, 20, 40), Vec3(60, 40, 60)}}}; }
/// A block across the straight line: go around it.
Scene block_scene() { return Scene{{{Vec3(40, 30, 30), Vec3(60, 70, 70)}}}; }

/// A wall x ∈ [48, 52] sealing the planning box, with a square hole of half-width h at (y, z) = (50, 50).
Scene wall_with_hole(double h) {
  const double lo = -50, hi = 150;  // beyond the planning bounds: no way around
  return Scene{{{Vec3(48, lo, lo), Vec3(52, 50 - h, hi)},
                {Vec3(48, 50 + h, lo), Vec3(52, hi, hi)},
                {Vec3(48, 50 - h, lo), Vec3(52, 50 + h, 50 - h)},
                {Vec3(48, 50 - h, 50 + h), Vec3(52, 50 + h, hi)}}};
}

// --- validity classes -------------------------------------------------------------------

TEST(TubeValidity, CheckerAndCapsuleValidatorAgreeWithTheOracle) {
  const Scene s = block_scene();
  const BruteForceIndex index(s.parts());
  auto space = std::make_shared<ompl::base::RealVectorStateSpace>(3);
  space->setBounds(0, 100);
  auto si = std::make_shared<ompl::base::SpaceInformation>(space);
  TubeQueryCounters counters;
  configure_tube_space(si, index, kRequired, 10 * kRequired, &counters);
  // Resolution comes from the clearance, not from 1% of the extent.
  EXPECT_NEAR(si->getStateValidityCheckingResolution() * space->getMaximumExtent(), tube_resolution(kRequired), 1e-9);

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 100);
  auto* a = si->allocState();
  auto* b = si->allocState();
  auto* last = si->allocState();
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng)), q(u(rng), u(rng), u(rng));
    set_state_point(a, p);
    set_state_point(b, q);
    const double dp = s.distance(p);
    if (std::abs(dp - kRequired) > 1e-6) {
      EXPECT_EQ(si->isValid(a), dp > kRequired) << p.transpose();
      const double c = si->getStateValidityChecker()->clearance(a);
      if (dp > 0) {
        EXPECT_NEAR(c, std::min(dp, 10 * kRequired) - kRequired, 1e-9);
      }
    }
    if (!(dp > kRequired)) continue;
    // Motion: oracle samples at step h decide clear (all ≥ required + h/2) or blocked (any < required).
    const double len = (q - p).norm();
    const int n = std::max(1, int(std::ceil(len / kOracleStep)));
    double dmin = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= n; ++k) dmin = std::min(dmin, s.distance(p + (q - p) * (double(k) / n)));
    const bool clear = dmin >= kRequired + kOracleStep / 2;
    const bool blocked = dmin < kRequired;
    if (!clear && !blocked) continue;
    ++checked;
    EXPECT_EQ(si->checkMotion(a, b), clear);
    std::pair<ompl::base::State*, double> lv(last, -1.0);
    const bool ok = si->getMotionValidator()->checkMotion(a, b, lv);
    EXPECT_EQ(ok, clear);
    if (!ok) {
      // The last valid point is clear, and just before the first contact.
      EXPECT_GE(lv.second, 0.0);
      EXPECT_LT(lv.second, 1.0);
      EXPECT_GE(s.distance(state_point(last)), kRequired - 1e-9);
    }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(counters.motion_checks.load(), 0u);
  si->freeState(a);
  si->freeState(b);
  si->freeState(last);
}

TEST(TubeValidity, PointDeepInsideAClosedPartIsInvalid) {
  // Far from the surface (distance > required) but inside: invalid, negative clearance.
  const Scene s{{{Vec3(0, 0, 0), Vec3(100, 100, 100)}}};
  const BruteForceIndex index(s.parts());
  auto space = std::make_shared<ompl::base::RealVectorStateSpace>(3);
  space->setBounds(-10, 110);
  auto si = std::make_shared<ompl::base::SpaceInformation>(space);
  configure_tube_space(si, index, kRequired, 100.0);
  auto* a = si->allocState();
  set_state_point(a, Vec3(50, 50, 50));
  EXPECT_FALSE(si->isValid(a));
  EXPECT_LT(si->getStateValidityChecker()->clearance(a), 0.0);
  set_state_point(a, Vec3(-5, 50, 50));
  EXPECT_TRUE(si->isValid(a));
  si->freeState(a);
}

// --- routes -----------------------------------------------------------------------------

TEST(PathPlanner, EveryPlannerNameSolvesAnEasyScene) {
  const Scene s = easy_scene();
  const BruteForceIndex index(s.parts());
  const auto names = planner_names();
  ASSERT_GE(names.size(), 6u);
  EXPECT_NO_THROW(planner_is_optimizing(PlanSettings{}.planner));  // the default is a valid name
  EXPECT_TRUE(planner_is_optimizing("bitstar"));
  EXPECT_FALSE(planner_is_optimizing("rrtconnect"));
  for (const char* required_name : {"rrtstar", "bitstar", "prmstar", "lazyprmstar", "rrtconnect", "informedrrtstar"})
    EXPECT_NE(std::find(names.begin(), names.end(), required_name), names.end()) << required_name;
  for (const auto& name : names) {
    SCOPED_TRACE(name);
    PlanRequest req = base_request(name);
    const PlanResult r = plan_path(index, req);
    expect_valid_route(s, req, r);
    EXPECT_EQ(r.planner, name);
    // The straight line is free: every planner ends within a few % of the lower bound
    // after simplification (key points: port, stub end, stub end, port).
    EXPECT_LE(r.length, 1.05 * (r.lower_bound + 2 * r.stub_length)) << name;
  }
}

TEST(PathPlanner, GoesAroundABlock) {
  const Scene s = block_scene();
  const BruteForceIndex index(s.parts());
  for (const char* name : {"rrtconnect", "rrtstar", "bitstar"}) {
    SCOPED_TRACE(name);
    PlanRequest req = base_request(name);
    const PlanResult r = plan_path(index, req);
    expect_valid_route(s, req, r);
    EXPECT_GT(r.key_points.size(), 4u);  // must bend around the block
  }
}

TEST(PathPlanner, WorksOnTheEmbreeIndex) {
  // The production index: same contract, same oracle.
  const Scene s = wall_with_hole(6.0);
  const EmbreeIndex index(s.parts());
  PlanRequest req = base_request("bitstar");
  req.start = {Vec3(20, 40, 60), Vec3::UnitX()};
  req.goal = {Vec3(80, 60, 40), -Vec3::UnitX()};
  const PlanResult r = plan_path(index, req);
  expect_valid_route(s, req, r);
  EXPECT_GT(r.motion_checks, 0u);
}

TEST(PathPlanner, RoutesThroughAHoleWiderThanTheTube) {
  const Scene s = wall_with_hole(6.0);  // free square for the centre: half-width 6 − 3 = 3
  const BruteForceIndex index(s.parts());
  for (const char* name : {"rrtconnect", "rrtstar"}) {
    SCOPED_TRACE(name);
    PlanRequest req = base_request(name);
    req.start = {Vec3(20, 30, 70), Vec3::UnitX()};
    req.goal = {Vec3(80, 70, 30), -Vec3::UnitX()};
    const PlanResult r = plan_path(index, req);
    expect_valid_route(s, req, r);
    // It crosses the wall plane inside the hole.
    bool crossed = false;
    for (std::size_t i = 1; i < r.key_points.size(); ++i) {
      const Vec3 a = r.key_points[i - 1], b = r.key_points[i];
      if ((a.x() - 50) * (b.x() - 50) <= 0 && a.x() != b.x()) {
        const Vec3 x = a + (b - a) * ((50 - a.x()) / (b.x() - a.x()));
        EXPECT_LE(std::abs(x.y() - 50), 3.0 + 1e-6);
        EXPECT_LE(std::abs(x.z() - 50), 3.0 + 1e-6);
        crossed = true;
      }
    }
    EXPECT_TRUE(crossed);
  }
}

TEST(PathPlanner, HoleNarrowerThanTheTubeIsNoCorridor) {
  const Scene s = wall_with_hole(2.0);  // 4 wide, the tube needs 6
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request("rrtconnect");
  // The main run ends on its iteration budget; the thin-line diagnosis always runs on the
  // clock (a fraction of the time limit), so the limit here bounds it.
  req.time_limit = 0.5;
  req.diagnosis_fraction = 4.0;  // 2 s for the thin line
  const PlanResult r = plan_path(index, req);
  ASSERT_FALSE(r.solved());
  EXPECT_EQ(r.reason, NoPathReason::NoCorridor) << r.message;
  EXPECT_NE(r.message.find("within 0.5 s"), std::string::npos) << r.message;  // the budget it ran out of
  ASSERT_TRUE(r.blocked_at.has_value());
  // The narrowest passage of the thin path is in the hole (or at its rim, within the
  // required distance of the wall faces x = 48 and x = 52). The ports face each other through
  // the hole, so the diagnosis finds the thin path without a narrow-passage search.
  EXPECT_NEAR(r.blocked_at->x(), 50.0, 2.0 + kRequired);
  EXPECT_LE(std::abs(r.blocked_at->y() - 50.0), 2.0);
  EXPECT_LE(std::abs(r.blocked_at->z() - 50.0), 2.0);
  EXPECT_GE(r.blocking_part, 0);
  EXPECT_TRUE(r.key_points.empty());
}

TEST(PathPlanner, SealedWallWithoutDiagnosisIsTimeout) {
  const Scene s = wall_with_hole(2.0);
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request("rrtconnect");
  req.diagnosis_fraction = 0.0;
  const PlanResult r = plan_path(index, req);
  ASSERT_FALSE(r.solved());
  EXPECT_EQ(r.reason, NoPathReason::Timeout);
}

TEST(PathPlanner, EscapesAUShapedTrap) {
  // A cup open towards −x around the start; the goal lies behind its bottom.
  const Scene s{{{Vec3(55, 30, 30), Vec3(60, 70, 70)},   // bottom
                 {Vec3(20, 30, 30), Vec3(60, 35, 70)},   // side −y
                 {Vec3(20, 65, 30), Vec3(60, 70, 70)},   // side +y
                 {Vec3(20, 30, 30), Vec3(60, 70, 35)},   // side −z
                 {Vec3(20, 30, 65), Vec3(60, 70, 70)}}};  // side +z
  const BruteForceIndex index(s.parts());
  for (const char* name : {"rrtconnect", "rrtstar", "lazyprmstar"}) {
    SCOPED_TRACE(name);
    PlanRequest req = base_request(name);
    req.start = {Vec3(40, 50, 50), Vec3::UnitX()};  // stub towards the bottom, 4 long, still clear
    req.goal = {Vec3(85, 50, 50), Vec3::UnitX()};
    const PlanResult r = plan_path(index, req);
    expect_valid_route(s, req, r);
    double min_x = 1e9;
    for (const auto& p : r.key_points) min_x = std::min(min_x, p.x());
    EXPECT_LT(min_x, 20.0 - 0.0);  // it had to leave the cup through its mouth
  }
}

// --- expected failures ------------------------------------------------------------------

TEST(PathPlanner, StartAndGoalInsideObstacles) {
  const Scene s = block_scene();
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request();
  req.start.position = Vec3(50, 50, 50);  // inside the block
  PlanResult r = plan_path(index, req);
  EXPECT_EQ(r.reason, NoPathReason::StartInObstacle) << r.message;
  EXPECT_EQ(r.blocking_part, 0);
  ASSERT_TRUE(r.blocked_at.has_value());
  EXPECT_EQ(*r.blocked_at, req.start.position);

  req = base_request();
  req.goal.position = Vec3(50, 50, 50);
  r = plan_path(index, req);
  EXPECT_EQ(r.reason, NoPathReason::GoalInObstacle) << r.message;

  // Outside, but closer than radius + clearance: the tube at the port would clash.
  req = base_request();
  req.start = {Vec3(38, 50, 50), -Vec3::UnitX()};
  r = plan_path(index, req);
  EXPECT_EQ(r.reason, NoPathReason::StartInObstacle) << r.message;
  EXPECT_FALSE(r.solved());
}

// A port on the face of its connector (box 0): the connector is excused over the given run
// of the exit only; a wall (box 1) ahead is measured over the whole exit. Distances are
// closed-form (Scene::distance of one box).
TEST(PortCheck, ConnectorIsExcusedOverItsRunOnly) {
  const Scene s{{{Vec3(0, 0, 0), Vec3(10, 10, 10)}, {Vec3(30, 0, 0), Vec3(31, 10, 10)}}};
  const std::vector<Part> parts = s.parts();
  const BruteForceIndex index(parts);
  std::vector<AABB> boxes;
  for (const Part& p : parts) boxes.push_back(p.mesh.bounds());
  const double required = 2.0;
  const Vec3 port(10.5, 5, 5);  // half a unit off the face: clearly outside
  const auto name = [&](int q) { return parts[q].name; };
  const std::vector<NearPart> near = near_port_parts(index, boxes, parts, port, required, 4.0, required);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_EQ(near[0].part, 0);
  EXPECT_EQ(near[0].excused, 4.0);

  PlanResult r;
  EXPECT_TRUE(check_port_exit(index, boxes, PortExit{"port P", port, Vec3(20, 5, 5), true, near, 0.02}, required,
                              name, r))
      << r.message;

  // Nothing excused: the port itself is on a part.
  r = PlanResult{};
  EXPECT_FALSE(check_port_exit(index, boxes, PortExit{"port P", port, Vec3(20, 5, 5), true, {}, 0.0}, required,
                               name, r));
  EXPECT_EQ(r.reason, NoPathReason::StartInObstacle);
  EXPECT_EQ(r.message, "port P at (10.5, 5, 5) is 0.5 from part 'box0', closer than radius + clearance = 2");

  // Excused over 1 only: at 1 along the exit the connector is 1.5 away, less than required.
  r = PlanResult{};
  EXPECT_FALSE(check_port_exit(index, boxes, PortExit{"port P", port, Vec3(20, 5, 5), false, {{0, 1.0}}, 0.02},
                               required, name, r));
  EXPECT_EQ(r.reason, NoPathReason::GoalPortBlocked);
  EXPECT_EQ(r.blocking_part, 0);
  ASSERT_TRUE(r.blocked_at.has_value());
  EXPECT_NEAR(s.distance(Vec3(11.5, 5, 5)), 1.5, 1e-12);
  EXPECT_NEAR((*r.blocked_at - Vec3(10, 5, 5)).norm(), 0.0, 1e-9);  // the face point nearest x = 11.5

  // An exit that ends 1 short of the wall.
  r = PlanResult{};
  EXPECT_FALSE(check_port_exit(index, boxes, PortExit{"port P", port, Vec3(29, 5, 5), true, near, 0.02}, required,
                               name, r));
  EXPECT_EQ(r.reason, NoPathReason::StartPortBlocked);
  EXPECT_EQ(r.blocking_part, 1);
  EXPECT_EQ(r.message,
            "port P at (10.5, 5, 5) faces a wall: its straight exit of length 18.5 comes within 1 of part 'box1' "
            "(needs 2)");
}

TEST(PathPlanner, PortFacingAWallIsReported) {
  const Scene s{{{Vec3(3, 0, 0), Vec3(5, 100, 100)}}};
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request();
  req.start = {Vec3(10, 50, 50), -Vec3::UnitX()};  // stub of 4 ends at x = 6; the tube reaches x = 3
  PlanResult r = plan_path(index, req);
  EXPECT_EQ(r.reason, NoPathReason::StartPortBlocked) << r.message;
  EXPECT_EQ(r.message.rfind("start port at (10, 50, 50) faces a wall: its straight exit of length 4 comes within 1 of "
                            "part 0",
                            0),
            0u)
      << r.message;
  ASSERT_TRUE(r.blocked_at.has_value());
  EXPECT_NEAR(r.blocked_at->x(), 5.0, 1e-9);  // on the wall's face, in front of the port
  EXPECT_NEAR(r.blocked_at->y(), 50.0, 1e-9);
  EXPECT_NEAR(r.blocked_at->z(), 50.0, 1e-9);

  req = base_request();
  req.goal = {Vec3(10, 80, 50), -Vec3::UnitX()};
  r = plan_path(index, req);
  EXPECT_EQ(r.reason, NoPathReason::GoalPortBlocked) << r.message;

  // Turned away from the wall, the same port is fine.
  req = base_request();
  req.start = {Vec3(10, 50, 50), Vec3::UnitX()};
  r = plan_path(index, req);
  expect_valid_route(s, req, r);
}

TEST(PathPlanner, ZeroTimeBudgetChecksPortsOnly) {
  const Scene s = easy_scene();
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request("rrtstar");
  req.time_limit = 0.0;
  PlanResult r = plan_path(index, req);
  EXPECT_FALSE(r.solved());
  EXPECT_EQ(r.reason, NoPathReason::Timeout);
  EXPECT_TRUE(r.key_points.empty());
  // Port problems are still reported precisely with a zero budget.
  req.start.position = Vec3(50, 30, 50);
  r = plan_path(index, req);
  EXPECT_EQ(r.reason, NoPathReason::StartInObstacle);
}

TEST(PathPlanner, BadInputThrows) {
  const Scene s = easy_scene();
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request("no-such-planner");
  try {
    plan_path(index, req);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rrtstar"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no-such-planner"), std::string::npos) << e.what();
  }
  EXPECT_THROW(planner_is_optimizing("nope"), std::invalid_argument);
  req = base_request();
  req.radius = 0;
  EXPECT_THROW(plan_path(index, req), std::invalid_argument);
  req = base_request();
  req.start.exit_direction = Vec3::Zero();
  EXPECT_THROW(plan_path(index, req), std::invalid_argument);
  req = base_request();
  req.goal.position = req.start.position;
  EXPECT_THROW(plan_path(index, req), std::invalid_argument);
  req = base_request();
  req.time_limit = -1;
  EXPECT_THROW(plan_path(index, req), std::invalid_argument);
  req = base_request();
  req.start.position.x() = std::nan("");
  EXPECT_THROW(plan_path(index, req), std::invalid_argument);
}

TEST(PathPlanner, NoObstaclesAtAll) {
  const Scene s{};
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request("rrtstar");
  req.scene_box = AABB{};  // no obstacles: bounds from the ports
  const PlanResult r = plan_path(index, req);
  ASSERT_TRUE(r.solved()) << r.message;
  EXPECT_TRUE(std::isfinite(r.min_clearance));
  EXPECT_NEAR(r.length, 80.0, 1e-6);  // straight: port, stub ends, port are collinear
}

TEST(PathPlanner, ProcessSeedIsSetOnce) {
  EXPECT_EQ(kProcessSeed, 7u);
  EXPECT_EQ(seed_ompl_once(99), 7u);  // later calls change nothing
}

TEST(PathPlanner, DerivedStubLength) {
  EXPECT_DOUBLE_EQ(derived_stub_length(2.0, 0.0), 4.0);
  EXPECT_DOUBLE_EQ(derived_stub_length(2.0, 15.0), 15.0);
  const Scene s = easy_scene();
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request();
  req.min_bend_radius = 12.0;
  const PlanResult r = plan_path(index, req);
  expect_valid_route(s, req, r);
  EXPECT_DOUBLE_EQ(r.stub_length, 12.0);
}

TEST(PathPlanner, OptimisingPlannersStopOnConvergence) {
  // The cost threshold (1% above the straight-line bound) or the convergence window (no 1%
  // gain in 5% of the budget) ends the run, not the 20 s limit: on the easy scene the
  // threshold, on the block scene (bound unreachable) the convergence window. The planner
  // reports which condition ended the run (time_limited), so no clock is read here.
  for (const Scene& s : {easy_scene(), block_scene()}) {
    const BruteForceIndex index(s.parts());
    for (const char* name : {"informedrrtstar", "bitstar"}) {
      SCOPED_TRACE(name);
      PlanRequest req = base_request(name);
      req.max_iterations = 0;  // an iteration budget disables the convergence test
      req.time_limit = 20.0;
      req.convergence_window = 0.05;
      const PlanResult r = plan_path(index, req);
      expect_valid_route(s, req, r);
      EXPECT_FALSE(r.time_limited);
      EXPECT_GT(r.iterations, 0u);
    }
  }
}

// --- determinism ------------------------------------------------------------------------

TEST(PathPlanner, SameSeedSameKeyPoints) {
  const Scene s = block_scene();
  const BruteForceIndex index(s.parts());
  struct Case {
    const char* planner;
    std::uint64_t iterations;
  };
  // rrtconnect ends at its first solution; the optimising ones on an iteration count.
  for (const Case c : {Case{"rrtconnect", 0}, Case{"rrt", 0}, Case{"lazyprm", 0}, Case{"rrtstar", 400},
                       Case{"informedrrtstar", 400}, Case{"sorrtstar", 400}, Case{"bitstar", 400},
                       Case{"lazyprmstar", 400}}) {
    SCOPED_TRACE(c.planner);
    PlanRequest req = base_request(c.planner);
    req.time_limit = 20.0;  // never reached: termination is deterministic
    req.max_iterations = c.iterations;
    req.seed = 42;
    const PlanResult a = plan_path(index, req);
    const PlanResult b = plan_path(index, req);
    ASSERT_TRUE(a.solved()) << a.message;
    ASSERT_TRUE(b.solved()) << b.message;
    EXPECT_EQ(a.key_points, b.key_points);
    EXPECT_EQ(a.raw_states, b.raw_states);
  }
}

// --- objective ----------------------------------------------------------------------------

TEST(PathPlanner, PartPreferenceChoosesTheSide) {
  // A pillar split into two halves (part 0: y < 50, part 1: y > 50), sealed in z: the route
  // passes on the −y or the +y side, equally long; the preference for part 1 decides.
  const Scene s{{{Vec3(40, 40, -50), Vec3(60, 50, 150)}, {Vec3(40, 50, -50), Vec3(60, 60, 150)}}};
  const BruteForceIndex index(s.parts());
  auto mean_y = [](const PlanResult& r) {
    double y = 0;
    for (const auto& p : r.key_points) y += p.y();
    return y / r.key_points.size();
  };
  for (const PartPreference pref : {PartPreference::Avoid, PartPreference::Near}) {
    SCOPED_TRACE(preference_name(pref));
    PlanRequest req = base_request("rrtstar");
    req.objective.clearance_weight = 0.0;
    req.objective.preference_weight = 5.0;
    req.objective.clearance_band = 10.0;
    req.objective.part_preference = {PartPreference::Neutral, pref};
    req.max_iterations = 800;
    req.time_limit = 20.0;
    const PlanResult r = plan_path(index, req);
    expect_valid_route(s, req, r);
    if (pref == PartPreference::Avoid)
      EXPECT_LT(mean_y(r), 50.0);
    else
      EXPECT_GT(mean_y(r), 50.0);
  }
}

TEST(PathPlanner, ClearanceTermKeepsTheRouteAway) {
  // Same pillar: with a strong clearance term the route keeps farther from it than without.
  const Scene s = block_scene();
  const BruteForceIndex index(s.parts());
  PlanRequest req = base_request("rrtstar");
  req.max_iterations = 800;
  req.time_limit = 20.0;
  req.objective.clearance_weight = 0.0;
  const PlanResult tight = plan_path(index, req);
  req.objective.clearance_weight = 4.0;
  req.objective.clearance_band = 10.0;
  const PlanResult loose = plan_path(index, req);
  expect_valid_route(s, req, tight);
  expect_valid_route(s, req, loose);
  EXPECT_GT(loose.min_clearance, tight.min_clearance + 1.0);
  EXPECT_GT(loose.length, tight.length);
}

TEST(PathPlanner, SupportTermBringsTheRouteWithinReachOfStructure) {
  // A floor slab 40 below the straight way (centre line 50 − 10 above its top): without the
  // support term nothing of the route is within reach 12 of the slab; with it an
  // out-of-reach stretch costs 5× its length, so the route dips to the slab. The best dip
  // (down 28, along, up 28 between stub ends 80 apart) has about 0.46 of its length within
  // reach. Oracle: closed-form distances, sampled every 0.1; the planner's key points sit on
  // the ramp's foot, so "within reach" is read with 1 of slack.
  const Scene s{{{Vec3(0, 0, 0), Vec3(100, 100, 10)}}};
  const BruteForceIndex index(s.parts());
  constexpr double kReach = 12.0;
  auto share_within_reach = [&](const PlanResult& r) {
    double in = 0.0, all = 0.0;
    for (std::size_t i = 1; i < r.key_points.size(); ++i) {
      const Vec3 a = r.key_points[i - 1], b = r.key_points[i];
      const int n = std::max(1, static_cast<int>((b - a).norm() / 0.1));
      for (int k = 0; k < n; ++k) {
        const double ds = (b - a).norm() / n;
        all += ds;
        if (s.distance(a + (b - a) * ((k + 0.5) / n)) <= kReach + 1.0) in += ds;
      }
    }
    return in / all;
  };
  PlanRequest req = base_request("informedrrtstar");
  req.max_iterations = 1500;
  const PlanResult floating = plan_path(index, req);
  req.objective.support_weight = 4.0;
  req.objective.support_reach = kReach;
  req.objective.support_band = 4.0;
  const PlanResult supported = plan_path(index, req);
  expect_valid_route(s, req, floating);
  expect_valid_route(s, req, supported);
  EXPECT_LT(share_within_reach(floating), 0.05);
  EXPECT_GT(share_within_reach(supported), 0.4);
  EXPECT_GT(supported.length, floating.length + 30.0);  // the price of support: the dip
  // A part that cannot carry a clamp attracts nothing: the route floats as before.
  req.objective.part_supports = {false};
  EXPECT_LT(share_within_reach(plan_path(index, req)), 0.05);
}

// --- multi-query roadmap ------------------------------------------------------------------

TEST(RoadmapPlanner, ReusesTheRoadmapAcrossQueries) {
  const Scene s = block_scene();
  const BruteForceIndex index(s.parts());
  for (const char* name : {"lazyprmstar", "prmstar"}) {
    SCOPED_TRACE(name);
    PlanSettings set = base_request(name);
    RoadmapPlanner rp(index, set);
    EXPECT_EQ(rp.roadmap_vertices(), 0u);
    const std::vector<std::pair<PortSpec, PortSpec>> queries = {
        {{Vec3(10, 50, 50), Vec3::UnitX()}, {Vec3(90, 50, 50), -Vec3::UnitX()}},
        {{Vec3(10, 20, 20), Vec3::UnitX()}, {Vec3(90, 80, 80), -Vec3::UnitX()}},
        {{Vec3(50, 10, 50), Vec3::UnitY()}, {Vec3(50, 90, 50), -Vec3::UnitY()}}};
    std::size_t before = 0;
    for (const auto& q : queries) {
      PlanRequest req = base_request(name);
      req.start = q.first;
      req.goal = q.second;
      const PlanResult r = rp.plan(q.first, q.second, kTimeCap);
      expect_valid_route(s, req, r);
      const std::size_t now = rp.roadmap_vertices();
      EXPECT_GE(now, before);  // kept, not cleared
      before = now;
    }
    EXPECT_GT(before, 10u);
  }
  PlanSettings bad = base_request("rrtstar");
  EXPECT_THROW(RoadmapPlanner(index, bad), std::invalid_argument);
  EXPECT_TRUE(RoadmapPlanner::supports("lazyprmstar"));
  EXPECT_FALSE(RoadmapPlanner::supports("rrtconnect"));
}

// --- properties ---------------------------------------------------------------------------

/// Random boxes in [0, 100]³ from a seed.
Scene random_scene(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> c(5, 95), h(2, 12);
  Scene s;
  for (int i = 0; i < n; ++i) {
    const Vec3 ctr(c(rng), c(rng), c(rng)), half(h(rng), h(rng), h(rng));
    s.boxes.push_back({ctr - half, ctr + half});
  }
  return s;
}

RC_GTEST_PROP(PathPlannerProperty, PortClassificationMatchesTheOracle, ()) {
  // Zero budget: the outcome is decided by the port and stub checks alone; compare with the
  // closed-form oracle (dense samples decide only when unambiguous).
  const auto scene_seed = *rc::gen::inRange<std::uint32_t>(0, 1000000);
  std::mt19937 rng(scene_seed);
  const Scene s = random_scene(rng, 6);
  const BruteForceIndex index(s.parts());
  std::uniform_real_distribution<double> u(0, 100), off(0, 3 * kRequired);
  std::normal_distribution<double> nd;
  // Half of the ports sit just off a box face (inside, too close, or with the stub hitting
  // the box), the others anywhere.
  auto port = [&]() {
    PortSpec p{Vec3(u(rng), u(rng), u(rng)), Vec3(nd(rng), nd(rng), nd(rng))};
    if (*rc::gen::arbitrary<bool>()) {
      const Box& b = s.boxes[*rc::gen::inRange<std::size_t>(0, s.boxes.size())];
      const int axis = *rc::gen::inRange(0, 3);
      const bool high = *rc::gen::arbitrary<bool>();
      std::uniform_real_distribution<double> across(0, 1);
      for (int k = 0; k < 3; ++k) p.position[k] = b.lo[k] + across(rng) * (b.hi[k] - b.lo[k]);
      p.position[axis] = high ? b.hi[axis] + off(rng) : b.lo[axis] - off(rng);
    }
    return p;
  };
  PlanRequest req = base_request();
  req.time_limit = 0.0;
  req.start = port();
  req.goal = port();
  RC_PRE(req.start.exit_direction.norm() > 1e-3 && req.goal.exit_direction.norm() > 1e-3);
  const PlanResult r = plan_path(index, req);

  auto classify = [&](const PortSpec& p) -> int {  // 0 clear, 1 port bad, 2 stub bad, -1 ambiguous
    const double dp = s.distance(p.position);
    if (dp < kRequired) return 1;
    if (dp < kRequired + 1e-6) return -1;
    const Vec3 e = p.position + r.stub_length * p.exit_direction.normalized();
    const int n = int(std::ceil(r.stub_length / kOracleStep));
    double dmin = dp;
    for (int k = 0; k <= n; ++k) dmin = std::min(dmin, s.distance(p.position + (e - p.position) * (double(k) / n)));
    if (dmin < kRequired) return 2;
    if (dmin < kRequired + kOracleStep / 2) return -1;
    return 0;
  };
  const int cs = classify(req.start);
  const int cg = classify(req.goal);
  RC_PRE(cs >= 0 && cg >= 0);
  NoPathReason expected = NoPathReason::Timeout;
  if (cs == 1)
    expected = NoPathReason::StartInObstacle;
  else if (cs == 2)
    expected = NoPathReason::StartPortBlocked;
  else if (cg == 1)
    expected = NoPathReason::GoalInObstacle;
  else if (cg == 2)
    expected = NoPathReason::GoalPortBlocked;
  RC_TAG(reason_name(expected));
  RC_ASSERT(r.reason == expected);
  RC_ASSERT(!r.solved());
  RC_ASSERT(std::isfinite(r.time_ms));
}

TEST(PathPlannerProperty, RandomScenesGiveVerifiedRoutesOrPreciseReasons) {
  std::mt19937 rng(2024);
  int solved = 0;
  for (int trial = 0; trial < 12; ++trial) {
    SCOPED_TRACE(trial);
    const Scene s = random_scene(rng, 8);
    const BruteForceIndex index(s.parts());
    std::uniform_real_distribution<double> u(0, 100);
    std::normal_distribution<double> nd;
    PlanRequest req = base_request(trial % 2 ? "rrtconnect" : "bitstar");
    req.seed = 100 + trial;
    // Ports whose own checks pass (a zero-budget plan checks exactly that).
    do {
      req.time_limit = 0.0;
      req.start = {Vec3(u(rng), u(rng), u(rng)), Vec3(nd(rng), nd(rng), nd(rng)).normalized()};
      req.goal = {Vec3(u(rng), u(rng), u(rng)), Vec3(nd(rng), nd(rng), nd(rng)).normalized()};
    } while (plan_path(index, req).reason != NoPathReason::Timeout);
    EXPECT_GE(s.distance(req.start.position), kRequired - 1e-9);
    EXPECT_GE(s.distance(req.goal.position), kRequired - 1e-9);
    req.time_limit = kTimeCap;
    // The thin-line diagnosis runs on the clock (a fraction of the time limit); without it an
    // unsolved plan ends on its iteration budget and is reported as a timeout.
    req.diagnosis_fraction = 0.0;
    const PlanResult r = plan_path(index, req);
    if (r.solved()) {
      ++solved;
      expect_valid_route(s, req, r);
    } else {
      // Enclosed ports are possible in random clutter; never an unverified route.
      EXPECT_EQ(r.reason, NoPathReason::Timeout) << r.message;
      EXPECT_FALSE(r.time_limited);
      EXPECT_TRUE(r.key_points.empty());
    }
  }
  EXPECT_GE(solved, 8);
}

}  // namespace
}  // namespace loom
