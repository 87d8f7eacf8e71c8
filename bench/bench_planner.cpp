// Planner speed against quality: for each planner and time budget, route a fixed
// set of cables through a fixed-seed cluttered scene of boxes (EmbreeIndex) and compare each
// route's length with the best length found for that cable in the same process (all runs plus
// long baseline runs of BIT* and Informed RRT* at kBaselineBudget). Writes
// bench/results/planner.csv (every run), planner_summary.csv (per planner and budget),
// planner_<name>.dat + planner.gp (chart data and script) and planner.png (gnuplot).
//
// Usage: bench_planner [--quick]   (--quick: fewer budgets and cables, for a smoke run)

#include "box_mesh.hpp"
#include "core/mesh.hpp"
#include "core/part.hpp"
#include "index/embree_index.hpp"
#include "routing/route/path_planner.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

using loom::Vec3;

/// Scene: kBoxes random boxes in [0, kSceneSize]³ (fixed seed).
constexpr int kBoxes = 300;
constexpr double kSceneSize = 200.0;
constexpr double kRadius = 3.0;
constexpr double kClearance = 2.0;
constexpr std::uint32_t kSceneSeed = 20261121;
/// Long runs whose best length is the quality reference.
constexpr double kBaselineBudget = 5.0;

using loom::bench::box_mesh;

struct Run {
  std::string planner;
  double budget = 0;
  int query = 0;
  loom::PlanResult result;
};

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  std::mt19937 rng(kSceneSeed);
  std::uniform_real_distribution<double> pos(0, kSceneSize), size(5, 30);
  std::vector<loom::Part> parts;
  for (int i = 0; i < kBoxes; ++i) {
    const Vec3 c(pos(rng), pos(rng), pos(rng)), h(size(rng) / 2, size(rng) / 2, size(rng) / 2);
    loom::Part p;
    p.name = "box" + std::to_string(i);
    p.mesh = box_mesh(c - h, c + h);
    p.closed = true;
    parts.push_back(std::move(p));
  }
  const loom::EmbreeIndex index(parts);
  loom::AABB box;
  for (const auto& p : parts) box.extend(p.mesh.bounds());

  loom::PlanRequest base;
  base.radius = kRadius;
  base.clearance = kClearance;
  base.scene_box = box;
  base.objective.clearance_weight = 0.0;  // quality = length here
  base.convergence_epsilon = 0.0;         // use the whole budget: budget against quality

  // Cables: random port pairs at least half the scene apart whose ports and stubs are clear
  // (a zero-budget plan checks exactly that).
  const int n_queries = quick ? 3 : 6;
  std::vector<std::pair<loom::PortSpec, loom::PortSpec>> queries;
  std::normal_distribution<double> nd;
  while (static_cast<int>(queries.size()) < n_queries) {
    loom::PlanRequest q = base;
    q.time_limit = 0.0;
    q.start = {Vec3(pos(rng), pos(rng), pos(rng)), Vec3(nd(rng), nd(rng), nd(rng)).normalized()};
    q.goal = {Vec3(pos(rng), pos(rng), pos(rng)), Vec3(nd(rng), nd(rng), nd(rng)).normalized()};
    if ((q.goal.position - q.start.position).norm() < 0.5 * kSceneSize) continue;
    if (loom::plan_path(index, q).reason == loom::NoPathReason::Timeout) queries.emplace_back(q.start, q.goal);
  }

  const std::vector<std::string> planners = {"rrtconnect", "rrtstar", "informedrrtstar", "bitstar",
                                             "prmstar", "lazyprmstar"};
  const std::vector<double> budgets =
      quick ? std::vector<double>{0.05, 0.2} : std::vector<double>{0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0};
  std::vector<Run> runs;
  auto run_one = [&](const std::string& planner, double budget, int qi) {
    loom::PlanRequest req = base;
    req.planner = planner;
    req.time_limit = budget;
    req.seed = 1000 + qi;
    req.diagnosis_fraction = 0.0;
    req.start = queries[qi].first;
    req.goal = queries[qi].second;
    runs.push_back({planner, budget, qi, loom::plan_path(index, req)});
    const auto& r = runs.back().result;
    std::cerr << planner << " budget " << budget << " cable " << qi << ": "
              << (r.solved() ? "length " + std::to_string(r.length) : loom::reason_name(r.reason)) << " in "
              << r.time_ms << " ms\n";
  };
  for (const auto& p : planners)
    for (double b : budgets)
      for (int qi = 0; qi < n_queries; ++qi) run_one(p, b, qi);
  const std::size_t grid_runs = runs.size();
  for (const char* p : {"bitstar", "informedrrtstar"})
    for (int qi = 0; qi < n_queries; ++qi) run_one(p, quick ? 1.0 : kBaselineBudget, qi);

  std::vector<double> best(n_queries, std::numeric_limits<double>::infinity());
  for (const auto& r : runs)
    if (r.result.solved()) best[r.query] = std::min(best[r.query], r.result.length);

  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/bench/results/";
  std::ofstream csv(dir + "planner.csv");
  csv << "planner,budget_s,cable,solved,reason,length,best_length,length_ratio,key_points,time_ms,plan_ms,"
         "simplify_ms,motion_checks\n";
  struct Agg {
    int solved = 0, failed = 0;
    double ratio_sum = 0, time_sum = 0;
  };
  std::map<std::pair<std::string, double>, Agg> agg;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& run = runs[i];
    const auto& r = run.result;
    const double ratio = r.solved() ? r.length / best[run.query] : 0.0;
    csv << run.planner << "," << run.budget << "," << run.query << "," << (r.solved() ? 1 : 0) << ","
        << loom::reason_name(r.reason) << "," << (r.solved() ? r.length : 0.0) << "," << best[run.query] << ","
        << ratio << "," << r.key_points.size() << "," << r.time_ms << "," << r.plan_ms << "," << r.simplify_ms
        << "," << r.motion_checks << "\n";
    if (i >= grid_runs) continue;
    Agg& a = agg[{run.planner, run.budget}];
    if (r.solved()) {
      ++a.solved;
      a.ratio_sum += ratio;
    } else {
      ++a.failed;
    }
    a.time_sum += r.time_ms;
  }
  csv.close();

  std::ofstream sum(dir + "planner_summary.csv");
  sum << "planner,budget_s,cables,solved,failures,mean_length_ratio,mean_time_ms\n";
  for (const auto& p : planners) {
    std::ofstream f(dir + "planner_" + p + ".dat");
    for (double b : budgets) {
      const Agg& a = agg[{p, b}];
      const double mean_ratio = a.solved > 0 ? a.ratio_sum / a.solved : 0.0;
      sum << p << "," << b << "," << n_queries << "," << a.solved << "," << a.failed << "," << mean_ratio << ","
          << a.time_sum / n_queries << "\n";
      f << b << " " << (a.solved > 0 ? std::to_string(mean_ratio) : std::string("NaN")) << " " << a.failed << "\n";
    }
  }
  sum.close();

  // Chart: mean length / best against budget, and failures against budget, per planner.
  const std::string gp = dir + "planner.gp";
  std::ofstream g(gp);
  g << "set terminal pngcairo size 1200,500\nset output '" << dir << "planner.png'\n"
    << "set multiplot layout 1,2 title 'Planner speed vs quality: " << kBoxes << " boxes, " << n_queries
    << " cables, tube r=" << kRadius << " c=" << kClearance << " (fixed seeds)'\n"
    << "set logscale x\nset xlabel 'time budget (s)'\nset key top right\nset grid\n"
    << "set ylabel 'mean length / best known length (solved cables)'\nplot ";
  for (std::size_t i = 0; i < planners.size(); ++i)
    g << (i ? ", " : "") << "'" << dir << "planner_" << planners[i] << ".dat' using 1:2 with linespoints title '"
      << planners[i] << "'";
  g << "\nset ylabel 'failures (of " << n_queries << ")'\nset yrange [0:" << n_queries << "]\nplot ";
  for (std::size_t i = 0; i < planners.size(); ++i)
    g << (i ? ", " : "") << "'" << dir << "planner_" << planners[i] << ".dat' using 1:3 with linespoints title '"
      << planners[i] << "'";
  g << "\nunset multiplot\n";
  g.close();
  const int rc = std::system(("gnuplot '" + gp + "'").c_str());
  std::cout << "wrote " << dir << "planner.csv, planner_summary.csv, planner.png (gnuplot rc " << rc << ")\n";
  return rc == 0 ? 0 : 1;
}
