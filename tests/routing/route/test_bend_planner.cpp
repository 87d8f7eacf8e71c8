// Bend-feasible planning in an enclosed L-shaped corridor where the shortest way's corner
// cannot be rounded clear (its arc would cut the inner corner): the plan is bend-feasible,
// every point of the rounded route keeps the required distance (brute-force exact distances),
// it is reproducible per seed, and a U-turn in a dead end narrower than the bend needs fails
// naming the corner of the corridor it was given; on random scenes every route is feasible
// and clear by brute force. Bounded by iterations, never by time.
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/route/bend_planner.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace loom {
namespace {

constexpr double kRequired = 5.0;   // tube radius 4 + clearance 1
constexpr double kBend = 30.0;      // arc radius
constexpr double kWidth = 40.0;     // corridor width (the centre line has 30 of it)
constexpr double kTimeCap = 120.0;  // safety cap only: every plan here ends on its budget

/// An enclosed L: along +x from x = −10 to 200 (y ∈ [0, 40]), then along +y up to y = 230
/// (x ∈ [160, 200]); floor and ceiling at z = ∓20.
std::vector<Part> l_corridor() {
  using testmesh::box_part;
  return {box_part("floor", Vec3(-30, -20, -30), Vec3(220, 250, -20)),
          box_part("ceiling", Vec3(-30, -20, 20), Vec3(220, 250, 30)),
          box_part("south", Vec3(-30, -10, -20), Vec3(220, 0, 20)),
          box_part("north", Vec3(-30, kWidth, -20), Vec3(200 - kWidth, kWidth + 10, 20)),
          box_part("east", Vec3(200, -10, -20), Vec3(210, 250, 20)),
          box_part("west", Vec3(200 - kWidth - 10, kWidth, -20), Vec3(200 - kWidth, 250, 20)),
          box_part("cap-start", Vec3(-30, -10, -20), Vec3(-10, kWidth + 10, 20)),
          box_part("cap-end", Vec3(200 - kWidth - 10, 230, -20), Vec3(210, 250, 20))};
}

BendPlanRequest l_request() {
  BendPlanRequest r;
  r.start = Vec3(10, 20, 0);
  r.goal = Vec3(180, 210, 0);
  r.ends = {Vec3::UnitX(), 15.0, Vec3::UnitY(), 10.0};
  r.required = kRequired;
  r.bend_radius = kBend;
  r.bounds.extend(Vec3(-10, 0, -20));
  r.bounds.extend(Vec3(200, 230, 20));
  r.seed = 3;
  r.max_iterations = 3000;
  r.time_limit = kTimeCap;
  return r;
}

/// The shortest way's corner, 5 from both walls at the inner corner (160, 40): clear as a
/// polyline, but its arc cuts that corner.
std::vector<Vec3> hugging_hint() { return {Vec3(10, 20, 0), Vec3(166, 34, 0), Vec3(180, 210, 0)}; }

/// Least exact distance to the parts over the rounded route, sampled every 0.1 along legs and arcs.
double least_distance(const EmbreeIndex& index, const BendPlanResult& r) {
  const std::vector<Vec3>& k = r.key_points;
  double least = 1e300;
  for (std::size_t i = 0; i + 1 < k.size(); ++i) {
    const int n = std::max(1, static_cast<int>(std::ceil((k[i + 1] - k[i]).norm() / 0.1)));
    for (int j = 0; j <= n; ++j)
      least = std::min(least, index.closest(k[i] + (k[i + 1] - k[i]) * (double(j) / n), 1e3).distance);
  }
  return least;
}

TEST(BendPlanner, TheHuggingCornerCannotBeRoundedClear) {
  const EmbreeIndex index(l_corridor());
  const BendPlanRequest r = l_request();
  const std::vector<Vec3> hint = hugging_hint();
  for (std::size_t i = 0; i + 1 < hint.size(); ++i) EXPECT_FALSE(index.segment_within(hint[i], hint[i + 1], kRequired));
  EXPECT_EQ(arc_line_short_leg(hint, r.ends, kBend).leg, -1);  // the legs hold the tangents ...
  EXPECT_FALSE(arcs_fit(index, hint, r.ends, kBend, kRequired));  // ... but the arc is not clear
}

TEST(BendPlanner, PlansABendFeasibleClearRouteRoundTheCorner) {
  const EmbreeIndex index(l_corridor());
  for (const bool with_hint : {false, true}) {
    BendPlanRequest r = l_request();
    if (with_hint) r.hint = hugging_hint();
    const BendPlanResult res = plan_bend_feasible(index, r);
    ASSERT_TRUE(res.solved()) << res.message;
    EXPECT_FALSE(res.time_limited);
    EXPECT_TRUE(res.vertices.front().isApprox(r.start));
    EXPECT_TRUE(res.vertices.back().isApprox(r.goal));
    EXPECT_EQ(arc_line_short_leg(res.vertices, r.ends, kBend).leg, -1);
    EXPECT_TRUE(arcs_fit(index, res.vertices, r.ends, kBend, kRequired));
    // The chords of the rounded points deviate from the arcs by < 0.1 (π/12 steps, R = 30:
    // sagitta 0.26 at most, towards the centre, away from the outer wall).
    EXPECT_GE(least_distance(index, res), kRequired - 0.3) << "with hint " << with_hint;
    // Longer than the polyline lower bound only by what the bend costs.
    const double lower = (hugging_hint()[1] - r.start).norm() + (r.goal - hugging_hint()[1]).norm();
    EXPECT_LT(res.length, 1.1 * lower) << "with hint " << with_hint;
    EXPECT_GT(res.length, lower - 2.0 * kBend);
  }
}

TEST(BendPlanner, ReproduciblePerSeed) {
  const EmbreeIndex index(l_corridor());
  BendPlanRequest r = l_request();
  r.hint = hugging_hint();
  const BendPlanResult a = plan_bend_feasible(index, r), b = plan_bend_feasible(index, r);
  ASSERT_TRUE(a.solved());
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(BendPlanner, AUTurnInADeadEndNarrowerThanTheBendFailsNamingTheCorner) {
  // The start heads +x into a dead end 40 wide (30 for the centre line); the goal lies beside
  // it and leaves along −x: the route must turn back, which needs 2 × 30 across.
  const EmbreeIndex index(l_corridor());
  BendPlanRequest r = l_request();
  r.start = Vec3(40, 12, 0);
  r.goal = Vec3(60, 28, 0);
  r.ends = {Vec3::UnitX(), 10.0, -Vec3::UnitX(), 10.0};
  r.bounds = AABB{};
  r.bounds.extend(Vec3(-10, 0, -20));
  r.bounds.extend(Vec3(150, kWidth, 20));  // the first leg only
  r.max_iterations = 1500;
  r.hint = {r.start, Vec3(100, 12, 0), Vec3(100, 28, 0), r.goal};
  const BendPlanResult res = plan_bend_feasible(index, r);
  EXPECT_FALSE(res.solved());
  EXPECT_EQ(res.iterations, r.max_iterations);
  EXPECT_FALSE(res.time_limited);
  ASSERT_GE(res.tightest.leg, 0);
  EXPECT_GT(res.tightest.needed, res.tightest.length);
  EXPECT_NE(res.message.find("(100, 12, 0)"), std::string::npos) << res.message;
}

// Random scenes (fixed seed): 6–14 boxes between two stub ends with random headings. Every
// route returned is bend-feasible (the legs hold the tangents) and every point of its rounded
// route keeps the required distance, by brute-force exact distances; most scenes are solved.
TEST(BendPlanner, RandomScenesGiveFeasibleClearRoutesByBruteForce) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto unit = [&] {
    Vec3 d;
    do d = Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    while (d.norm() < 0.1);
    return Vec3(d.normalized());
  };
  int solved = 0;
  const int scenes = 20;
  for (int k = 0; k < scenes; ++k) {
    std::vector<Part> parts;
    const int n = 6 + static_cast<int>(u(rng) * 9);
    for (int b = 0; b < n; ++b) {
      const Vec3 lo(40 + 120 * u(rng), -60 + 120 * u(rng), -60 + 120 * u(rng));
      parts.push_back(testmesh::box_part("b" + std::to_string(b), lo, lo + Vec3(5 + 30 * u(rng), 5 + 30 * u(rng), 5 + 30 * u(rng))));
    }
    const EmbreeIndex index(parts);
    BendPlanRequest r;
    r.start = Vec3(0, 0, 0);
    r.goal = Vec3(200, 0, 0);
    r.ends = {unit(), 20.0, unit(), 20.0};
    r.required = 4.0;
    r.bend_radius = 15.0;
    r.bounds.extend(Vec3(-60, -100, -100));
    r.bounds.extend(Vec3(260, 100, 100));
    r.seed = static_cast<std::uint32_t>(k + 1);
    r.max_iterations = 3000;
    r.time_limit = kTimeCap;
    if (index.any_within(r.start, r.required) || index.any_within(r.goal, r.required)) continue;
    const BendPlanResult res = plan_bend_feasible(index, r);
    if (!res.solved()) continue;
    ++solved;
    EXPECT_EQ(arc_line_short_leg(res.vertices, r.ends, r.bend_radius).leg, -1) << "scene " << k;
    // Chords of the rounded points lie within the arcs' sagitta (R (1 − cos 7.5°) < 0.13) of them.
    EXPECT_GE(least_distance(index, res), r.required - 0.13) << "scene " << k;
  }
  EXPECT_GE(solved, scenes / 2);
}

TEST(BendPlanner, RefusesBadRequests) {
  const EmbreeIndex index(l_corridor());
  BendPlanRequest r = l_request();
  r.bend_radius = 0.0;
  EXPECT_THROW(plan_bend_feasible(index, r), std::invalid_argument);
  r = l_request();
  r.required = std::nan("");
  EXPECT_THROW(plan_bend_feasible(index, r), std::invalid_argument);
  r = l_request();
  r.goal = r.start;
  EXPECT_THROW(plan_bend_feasible(index, r), std::invalid_argument);
}

}  // namespace
}  // namespace loom
