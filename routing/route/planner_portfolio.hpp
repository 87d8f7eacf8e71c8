#pragma once
/// The planner portfolio ("portfolio"): a fast feasibility planner (RRT-Connect) finds a
/// corridor, then the asymptotically optimal one (Informed RRT*) shortens within the budget.
/// The corridor found first is never thrown away: it is the result unless the optimiser's
/// route is cheaper under the same objective. Informed RRT* alone finds nothing in narrow
/// passages for a long time (it spends its samples improving nothing); RRT-Connect alone
/// keeps its corners.
///
/// Budgets scale with the scene: the feasibility stage gets the request's time limit and
/// iteration budget times portfolio_scale() (RRT-Connect stops at its first solution, so a
/// large budget costs only where the problem is hard); the optimising stage gets the
/// request's own budget. Both stages are seeded from the request's seed, so a plan is
/// reproducible whenever each stage ends on its iteration budget or first solution.

#include "routing/route/path_planner.hpp"

#include <cstdint>
#include <string>

namespace loom {

/// The planner name of the portfolio (accepted by plan_path and [routing] planner).
inline constexpr const char* kPortfolioPlanner = "portfolio";

/// Budgets of the two stages of one portfolio plan, as derived from the scene.
struct PortfolioBudget {
  double scale = 1.0;                      ///< portfolio_scale() of the request
  double feasibility_seconds = 0.0;        ///< RRT-Connect time limit
  std::uint64_t feasibility_iterations = 0;  ///< RRT-Connect iteration budget (0: none)
  double optimise_seconds = 0.0;           ///< Informed RRT* time limit
  std::uint64_t optimise_iterations = 0;   ///< Informed RRT* iteration budget (0: none)
};

/// What a portfolio plan did, besides its result.
struct PortfolioOutcome {
  PlanResult plan;            ///< the route kept (planner "portfolio")
  PortfolioBudget budget;     ///< the budgets used
  bool corridor_found = false;  ///< the feasibility stage found a route
  bool optimised = false;     ///< the optimiser's route was kept (cheaper than the corridor)
  double feasibility_cost = 0.0;  ///< objective value of the corridor (when found)
  std::uint64_t feasibility_iterations_used = 0;  ///< RRT-Connect iterations run
  std::uint64_t optimise_iterations_used = 0;     ///< Informed RRT* iterations run
};

/// How much harder than open space the request's scene is, for the feasibility budget:
/// the planning box diagonal over kScaleRequired tube clearances (`radius + clearance`),
/// clamped to [1, kMaxScale]. A passage a planner must find by sampling shrinks relative to
/// the space as this grows.
double portfolio_scale(const PlanRequest& request);

/// The stage budgets for `request` (see the header note).
PortfolioBudget portfolio_budget(const PlanRequest& request);

/// Plans `request` with the portfolio (request.planner is ignored). Throws as plan_path.
PortfolioOutcome plan_portfolio(const ObstacleIndex& index, const PlanRequest& request);

}  // namespace loom
