#include "routing/route/planner_portfolio.hpp"

#include "core/stopwatch.hpp"

#include <algorithm>
#include <cmath>

namespace loom {

namespace {

/// The feasibility scale is the planning box diagonal over this many tube clearances: a
/// box up to this wide counts as open space (scale 1).
constexpr double kScaleRequired = 20.0;
/// Largest feasibility scale: the corridor search gets at most this many times the
/// request's budget (RRT-Connect finds the wing's narrow passages within ~5 budgets).
constexpr double kMaxScale = 16.0;
/// The feasibility stage's seed is mixed with this, so that it differs from the optimiser's.
constexpr std::uint32_t kFeasibilitySeedSalt = 0x5EA51B1Eu;

}  // namespace

double portfolio_scale(const PlanRequest& request) {
  const double required = request.radius + request.clearance;
  AABB box = request.scene_box;
  box.extend(request.start.position);
  box.extend(request.goal.position);
  if (!(required > 0.0) || box.empty()) return 1.0;
  return std::clamp(box.diagonal() / (kScaleRequired * required), 1.0, kMaxScale);
}

PortfolioBudget portfolio_budget(const PlanRequest& request) {
  PortfolioBudget b;
  b.scale = portfolio_scale(request);
  b.feasibility_seconds = request.time_limit * b.scale;
  b.feasibility_iterations =
      static_cast<std::uint64_t>(std::ceil(static_cast<double>(request.max_iterations) * b.scale));
  b.optimise_seconds = request.time_limit;
  b.optimise_iterations = request.max_iterations;
  return b;
}

PortfolioOutcome plan_portfolio(const ObstacleIndex& index, const PlanRequest& request) {
  const Stopwatch t0;
  PortfolioOutcome out;
  out.budget = portfolio_budget(request);

  PlanRequest feasible = request;
  feasible.planner = "rrtconnect";
  feasible.seed = request.seed ^ kFeasibilitySeedSalt;
  feasible.time_limit = out.budget.feasibility_seconds;
  feasible.max_iterations = out.budget.feasibility_iterations;
  PlanResult first = plan_path(index, feasible);
  out.feasibility_iterations_used = first.iterations;
  if (!first.solved()) {
    first.planner = kPortfolioPlanner;
    first.time_ms = t0.ms();
    out.plan = std::move(first);
    return out;
  }
  out.corridor_found = true;
  out.feasibility_cost = first.cost;

  PlanRequest optimise = request;
  optimise.planner = "informedrrtstar";
  optimise.time_limit = out.budget.optimise_seconds;
  optimise.max_iterations = out.budget.optimise_iterations;
  // The corridor is known to exist: no thin-path diagnosis if the optimiser misses it.
  optimise.diagnosis_fraction = 0.0;
  PlanResult second = optimise.time_limit > 0.0 ? plan_path(index, optimise) : PlanResult{};
  out.optimise_iterations_used = second.iterations;

  // Keep the corridor unless the optimiser's route is cheaper under the same objective.
  const bool better = second.solved() && second.cost < first.cost;
  const bool time_limited = first.time_limited || second.time_limited;
  PlanResult kept = better ? std::move(second) : std::move(first);
  out.optimised = better;
  kept.planner = kPortfolioPlanner;
  kept.iterations = out.feasibility_iterations_used + out.optimise_iterations_used;
  kept.time_limited = time_limited;
  kept.time_ms = t0.ms();
  out.plan = std::move(kept);
  return out;
}

}  // namespace loom
