// The planner portfolio: RRT-Connect's corridor, then Informed RRT* within the budget, never
// worse than the corridor. A narrow-passage trap (a sealing wall with a hole barely wider
// than the tube, the ports off its axis) that Informed RRT* alone does not get through on the
// same iteration budget. Plans are bounded by iterations; the time limit is a safety cap.
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/route/planner_portfolio.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace loom {
namespace {

constexpr double kRadius = 1.0, kClearance = 2.0, kRequired = kRadius + kClearance;
constexpr std::uint64_t kIterations = 1500;
constexpr double kTimeCap = 120.0;

/// A wall x ∈ [48, 52] sealing the planning box, with a square hole of half-width h at (y, z) = (50, 50).
std::vector<Part> wall_with_hole(double h) {
  const double lo = -50, hi = 150;
  return {testmesh::box_part("w1", Vec3(48, lo, lo), Vec3(52, 50 - h, hi)),
          testmesh::box_part("w2", Vec3(48, 50 + h, lo), Vec3(52, hi, hi)),
          testmesh::box_part("w3", Vec3(48, 50 - h, lo), Vec3(52, 50 + h, 50 - h)),
          testmesh::box_part("w4", Vec3(48, 50 - h, 50 + h), Vec3(52, 50 + h, hi))};
}

PlanRequest trap_request(const std::string& planner) {
  PlanRequest r;
  r.radius = kRadius;
  r.clearance = kClearance;
  r.scene_box.extend(Vec3(0, 0, 0));
  r.scene_box.extend(Vec3(100, 100, 100));
  r.planner = planner;
  r.max_iterations = kIterations;
  r.time_limit = kTimeCap;
  r.seed = 5;
  r.start = {Vec3(10, 15, 85), Vec3::UnitX()};
  r.goal = {Vec3(90, 85, 15), -Vec3::UnitX()};
  return r;
}

/// True if the polyline crosses the plane x = 50 only within the hole's free square.
bool crosses_in_hole(const std::vector<Vec3>& pts, double free_half) {
  bool crossed = false;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const Vec3 a = pts[i - 1], b = pts[i];
    if ((a.x() - 50) * (b.x() - 50) > 0 || a.x() == b.x()) continue;
    const Vec3 x = a + (b - a) * ((50 - a.x()) / (b.x() - a.x()));
    if (std::abs(x.y() - 50) > free_half + 1e-6 || std::abs(x.z() - 50) > free_half + 1e-6) return false;
    crossed = true;
  }
  return crossed;
}

TEST(PlannerPortfolio, GetsThroughANarrowPassageInformedRrtStarMisses) {
  const double h = kRequired + 3.0;  // the centre's free square has half-width 3
  const EmbreeIndex index(wall_with_hole(h));
  const PlanResult alone = plan_path(index, [] {
    PlanRequest r = trap_request("informedrrtstar");
    r.diagnosis_fraction = 0.0;
    return r;
  }());
  EXPECT_FALSE(alone.solved()) << "the trap is no trap: informed RRT* alone found a route";

  const PlanRequest req = trap_request(kPortfolioPlanner);
  const PortfolioOutcome out = plan_portfolio(index, req);
  ASSERT_TRUE(out.plan.solved()) << out.plan.message;
  EXPECT_TRUE(out.corridor_found);
  EXPECT_EQ(out.plan.planner, kPortfolioPlanner);
  EXPECT_TRUE(crosses_in_hole(out.plan.key_points, h - kRequired));
  // Never worse than the corridor it found first.
  EXPECT_LE(out.plan.cost, out.feasibility_cost + 1e-9);
  EXPECT_LE(out.feasibility_iterations_used, out.budget.feasibility_iterations);
  EXPECT_LE(out.optimise_iterations_used, out.budget.optimise_iterations);
  EXPECT_FALSE(out.plan.time_limited);
}

TEST(PlannerPortfolio, ShortensTheCorridorInOpenSpace) {
  // A block across the straight line: RRT-Connect's corridor bends around it; the optimiser's
  // route is kept only when cheaper, and the result is close to the shortest way around.
  const EmbreeIndex index({testmesh::box_part("block", Vec3(40, 30, 30), Vec3(60, 70, 70))});
  PlanRequest req = trap_request(kPortfolioPlanner);
  req.start = {Vec3(10, 50, 50), Vec3::UnitX()};
  req.goal = {Vec3(90, 50, 50), -Vec3::UnitX()};
  const PortfolioOutcome out = plan_portfolio(index, req);
  ASSERT_TRUE(out.plan.solved()) << out.plan.message;
  EXPECT_LE(out.plan.cost, out.feasibility_cost + 1e-9);
  EXPECT_EQ(out.optimised, out.plan.cost < out.feasibility_cost);
  // Around the block's nearest edge (y = 30 − required): 10 → (40, 27) → (60, 27) → 90, as a lower bound.
  const double around = 2.0 * std::hypot(30.0, 50.0 - (30.0 - kRequired)) + 20.0;
  EXPECT_GE(out.plan.length, around - 1e-6);
  EXPECT_LE(out.plan.length, 1.3 * around);
}

TEST(PlannerPortfolio, BudgetsScaleWithTheScene) {
  PlanRequest req = trap_request(kPortfolioPlanner);
  req.time_limit = 1.0;
  const PortfolioBudget small = portfolio_budget(req);
  // Diagonal of [0,100]³ with the ports inside: 100·√3 over 20 required distances of 3.
  EXPECT_NEAR(small.scale, 100.0 * std::sqrt(3.0) / (20.0 * kRequired), 1e-9);
  EXPECT_NEAR(small.feasibility_seconds, small.scale, 1e-9);
  EXPECT_EQ(small.optimise_iterations, kIterations);
  EXPECT_EQ(small.feasibility_iterations, static_cast<std::uint64_t>(std::ceil(kIterations * small.scale)));
  req.scene_box.extend(Vec3(1000, 1000, 1000));
  EXPECT_GT(portfolio_budget(req).scale, small.scale);
  req.scene_box.extend(Vec3(1e6, 1e6, 1e6));
  EXPECT_EQ(portfolio_budget(req).scale, 16.0);  // capped
  PlanRequest fat = trap_request(kPortfolioPlanner);
  fat.radius = 1e4;  // a box narrower than 20 tubes is open space
  EXPECT_EQ(portfolio_budget(fat).scale, 1.0);
}

}  // namespace
}  // namespace loom
