// End-to-end routing benchmark: the bundled wing-section harness routed by every
// planner at a ladder of time budgets, on the exact parts and on α-simplified parts
// (simplified once, in the same process), against long runs at 20× the scene's budget as
// the quality reference. For each run: cables routed, total cable length / best known
// length, clashes and violations left by the exact audit, and the time split (index,
// simplify, plan, spline, audit, repair). Fixed seed. Writes bench/results/route.csv,
// route_<series>.dat, route.gp and route.png (gnuplot).
//
// Usage: bench_route [--quick] [--scene PATH]   (--quick: two planners, two budgets)
#include "core/stopwatch.hpp"
#include "core/io/scene_load.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "routing/route/route_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace loom;

constexpr unsigned kSeed = 20261121;
/// Long runs get this multiple of the scene's own per-segment budget.
constexpr double kLongRunFactor = 20.0;

struct Run {
  std::string planner;
  double budget = 0.0;
  bool simplified = false;
  bool long_run = false;
  std::size_t cables = 0, routed = 0, clashes = 0, violations = 0;
  double length = 0.0;  ///< summed over routed cables
  RouteTimings timing;
};

Run route_once(const Scene& scene, const std::string& planner, double budget,
               const std::shared_ptr<const std::vector<Part>>& planning_parts) {
  RouteOptions o;
  o.planner = planner;
  o.time_limit = budget;
  o.seed = kSeed;
  o.iterations = 0;  // the budget measured here is time: ignore the scene's iteration budget
  o.planning_parts = planning_parts;
  const RouteReport rep = route_scene(scene, o);
  Run r;
  r.planner = planner;
  r.budget = budget;
  r.simplified = planning_parts != nullptr;
  r.cables = scene.harness.cables.size();
  std::map<std::string, bool> unrouted;
  for (const auto& u : rep.unrouted) unrouted[u.cable] = true;
  r.routed = r.cables - unrouted.size();
  r.clashes = rep.audit.result.clashes.size();
  r.violations = rep.audit.result.violations.size();
  for (const auto& c : rep.audit.result.cables) r.length += c.length;
  r.timing = rep.timing;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string scene_path = std::string(LOOM_SOURCE_DIR) + "/examples/wing-section/scene.toml";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") quick = true;
    else if (a == "--scene" && i + 1 < argc) scene_path = argv[++i];
    else {
      std::cerr << "usage: bench_route [--quick] [--scene PATH]\n";
      return 2;
    }
  }
  const Scene scene = load_scene(scene_path);
  const std::vector<std::string> planners =
      quick ? std::vector<std::string>{"informedrrtstar", "rrtconnect"}
            : std::vector<std::string>{"informedrrtstar", "bitstar", "rrtstar", "prmstar", "lazyprmstar", "rrtconnect"};
  const std::vector<double> budgets = quick ? std::vector<double>{0.1, 0.5} : std::vector<double>{0.05, 0.1, 0.25, 0.5, 1.0};
  const std::vector<std::string> simplified_planners = {"informedrrtstar", "bitstar"};

  // α-SIM once: its cost is reported beside the planning time it saves.
  AlphaSimOptions ao;
  ao.dim_pre = scene.simplify.dim_pre.value;
  ao.detect_lost_space = true;
  std::vector<AlphaSimResult> sim_results;
  const Stopwatch t0;
  auto simplified = std::make_shared<const std::vector<Part>>(simplify_parts(scene.parts, ao, &sim_results));
  const double simplify_ms = t0.ms();
  std::size_t tri_before = 0, tri_after = 0;
  for (const auto& r : sim_results) tri_before += r.triangles_before, tri_after += r.triangles_after;
  std::cout << "alpha-SIM (dim_pre " << ao.dim_pre << "): " << tri_before << " -> " << tri_after << " triangles in "
            << simplify_ms << " ms\n";

  std::vector<Run> runs;
  for (const auto& p : planners)
    for (double b : budgets) {
      runs.push_back(route_once(scene, p, b, nullptr));
      const Run& r = runs.back();
      std::printf("%-16s %5.2f s  exact   %zu/%zu routed  length %.1f  clashes %zu  violations %zu  plan %.0f ms\n",
                  p.c_str(), b, r.routed, r.cables, r.length, r.clashes, r.violations, r.timing.plan);
    }
  for (const auto& p : quick ? std::vector<std::string>{"informedrrtstar"} : simplified_planners)
    for (double b : budgets) {
      runs.push_back(route_once(scene, p, b, simplified));
      const Run& r = runs.back();
      std::printf("%-16s %5.2f s  α-SIM   %zu/%zu routed  length %.1f  clashes %zu  violations %zu  plan %.0f ms\n",
                  p.c_str(), b, r.routed, r.cables, r.length, r.clashes, r.violations, r.timing.plan);
    }
  const double long_budget = kLongRunFactor * scene.routing.time_limit.value;
  if (!quick) {
    runs.push_back(route_once(scene, "informedrrtstar", long_budget, nullptr));
    runs.back().long_run = true;
    std::printf("long run informedrrtstar %.1f s: length %.1f\n", long_budget, runs.back().length);
  }
  // Quality reference: the shortest complete, clean routing of any run.
  double best = std::numeric_limits<double>::infinity();
  for (const auto& r : runs)
    if (r.routed == r.cables && r.clashes == 0 && r.violations == 0) best = std::min(best, r.length);

  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/bench/results/";
  std::ofstream csv(dir + "route.csv");
  csv << "planner,budget_s,obstacles,long_run,cables,routed,clashes,violations,length,length_ratio,index_ms,"
         "simplify_ms,plan_ms,spline_ms,audit_ms,repair_ms,total_ms\n";
  for (const auto& r : runs)
    csv << r.planner << "," << r.budget << "," << (r.simplified ? "alpha-sim" : "exact") << "," << r.long_run << ","
        << r.cables << "," << r.routed << "," << r.clashes << "," << r.violations << "," << r.length << ","
        << (std::isfinite(best) && r.routed == r.cables ? r.length / best : 0.0) << "," << r.timing.index << ","
        << (r.simplified ? simplify_ms : r.timing.simplify) << "," << r.timing.plan << "," << r.timing.spline << ","
        << r.timing.audit << "," << r.timing.repair << "," << r.timing.total << "\n";
  csv.close();

  // Chart data: per planner (and α-SIM variant), budget → length ratio, problems, plan time.
  std::vector<std::string> series;
  for (const auto& r : runs) {
    if (r.long_run) continue;
    const std::string name = r.planner + (r.simplified ? "-alphasim" : "");
    if (std::find(series.begin(), series.end(), name) == series.end()) series.push_back(name);
  }
  for (const auto& name : series) {
    std::ofstream f(dir + "route_" + name + ".dat");
    for (const auto& r : runs) {
      if (r.long_run || r.planner + (r.simplified ? "-alphasim" : "") != name) continue;
      const bool complete = r.routed == r.cables && std::isfinite(best);
      f << r.budget << " " << (complete ? std::to_string(r.length / best) : std::string("NaN")) << " "
        << (r.cables - r.routed) + r.clashes + r.violations << " " << r.timing.plan << "\n";
    }
  }
  const std::string gp = dir + "route.gp";
  std::ofstream g(gp);
  g << "set terminal pngcairo size 1500,480\nset output '" << dir << "route.png'\n"
    << "set multiplot layout 1,3 title 'Routing the wing-section harness (" << scene.harness.cables.size()
    << " cables): time budget per segment vs quality; α-SIM " << tri_before << "→" << tri_after << " triangles in "
    << static_cast<long>(simplify_ms) << " ms (seed " << kSeed << ")'\n"
    << "set logscale x\nset xrange [0.035:1.5]\nset xlabel 'time budget per segment (s)'\nset grid\n"
    << "set key top left font ',9'\n"
    << "set ylabel 'total length / best known'\nplot ";
  for (std::size_t i = 0; i < series.size(); ++i)
    g << (i ? ", " : "") << "'" << dir << "route_" << series[i] << ".dat' using 1:2 with linespoints title '"
      << series[i] << "'";
  g << "\nset ylabel 'unrouted + clashes + violations'\nset yrange [-0.5:*]\nset offsets 0,0,1,0\nplot ";
  for (std::size_t i = 0; i < series.size(); ++i)
    g << (i ? ", " : "") << "'" << dir << "route_" << series[i] << ".dat' using 1:3 with linespoints title '"
      << series[i] << "'";
  g << "\nset ylabel 'planning time (ms)'\nset autoscale y\nset offsets 0,0,0,0\nset logscale y\nplot ";
  for (std::size_t i = 0; i < series.size(); ++i)
    g << (i ? ", " : "") << "'" << dir << "route_" << series[i] << ".dat' using 1:4 with linespoints title '"
      << series[i] << "'";
  g << "\nunset multiplot\n";
  g.close();
  const int rc = std::system(("gnuplot '" + gp + "'").c_str());
  std::cout << "best clean total length " << best << "; wrote " << dir << "route.csv, route.png (gnuplot rc " << rc
            << ")\n";
  return rc == 0 ? 0 : 1;
}
