// `loom route SCENE ...`: plan, spline, audit and repair every cable; write routed.xml,
// report.json, cables.ply, view.html and render.png (--render-size WxH). Progress bars on
// stderr when it is a terminal.
#include "app/motion_summary.hpp"
#include "app/support_summary.hpp"
#include "app/commands.hpp"
#include "app/option_checks.hpp"

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/output_set.hpp"
#include "core/io/scene_load.hpp"
#include "core/scene.hpp"
#include "app/progress_bar.hpp"
#include "routing/curve/cable_limit.hpp"
#include "routing/view/render.hpp"
#include "core/io/json_text.hpp"
#include "routing/route/route_report.hpp"
#include "routing/view/view_html.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <set>

namespace loom::app {

namespace {

/// One line on the portfolio planner's budgets (scaled with the scene) and what they bought.
void print_portfolio_budgets(const RouteReport& rep) {
  std::size_t planned = 0, optimised = 0;
  double scale_lo = 0.0, scale_hi = 0.0, corridor_s = 0.0, optimise_s = 0.0;
  for (const auto& info : rep.segments) {
    if (!info.portfolio) continue;
    const PortfolioBudget& b = info.portfolio->budget;
    scale_lo = planned ? std::min(scale_lo, b.scale) : b.scale;
    scale_hi = planned ? std::max(scale_hi, b.scale) : b.scale;
    corridor_s = std::max(corridor_s, b.feasibility_seconds);
    optimise_s = std::max(optimise_s, b.optimise_seconds);
    ++planned;
    optimised += info.portfolio->optimised;
  }
  if (planned == 0) return;
  std::printf("  portfolio: corridor budget %.3g-%.3gx (up to %.3g s), optimiser %.3g s; %zu of %zu segments "
              "shortened by informed RRT*\n",
              scale_lo, scale_hi, corridor_s, optimise_s, optimised, planned);
}

/// One line on the segments planned bend-feasibly where the bend repair failed, and one per
/// segment where no bend-feasible route was found (its message names the corner).
void print_bend_plans(const RouteReport& rep, const std::vector<Segment>& segments) {
  std::size_t tried = 0, planned = 0;
  double ms = 0.0;
  for (const auto& info : rep.segments) {
    if (info.bend_plan.empty()) continue;
    ++tried;
    planned += info.bend_plan == "planned";
    ms += info.bend_plan_ms;
  }
  if (tried == 0) return;
  std::printf("  bend-feasible plans: %zu of %zu segments whose bend repair failed, %.0f ms\n", planned, tried, ms);
  for (const auto& info : rep.segments) {
    const auto k = static_cast<std::size_t>(info.segment);
    if (info.bend_plan.empty() || info.bend_plan == "planned" || info.segment < 0 || k >= segments.size()) continue;
    std::printf("  segment %s -> %s: bend-feasible plan %s\n", segments[k].from.c_str(), segments[k].to.c_str(),
                info.bend_plan.c_str());
  }
}

void print_summary(const RouteReport& rep, const std::filesystem::path& out) {
  const auto& a = rep.audit;
  std::set<std::string> unrouted;
  for (const auto& u : rep.unrouted) unrouted.insert(u.cable);
  const std::string budget = rep.iterations > 0 ? ", " + std::to_string(rep.iterations) + " iterations" : "";
  std::printf("route %s: %zu/%zu cables routed (%s, seed %u%s), clearance %.4g %s\n", a.scene.c_str(),
              rep.routed.cables.size() - unrouted.size(), rep.routed.cables.size(), rep.planner.c_str(), rep.seed,
              budget.c_str(), rep.clearance, a.units.c_str());
  std::printf("  time: load %.0f ms, simplify %.0f ms, index %.0f ms, plan %.0f ms, spline %.0f ms, audit %.0f ms, "
              "repair %.0f ms, total %.0f ms\n",
              rep.timing.load, rep.timing.simplify, rep.timing.index, rep.timing.plan, rep.timing.spline,
              rep.timing.audit, rep.timing.repair, rep.timing.total + rep.timing.load);
  std::printf("  audit (%s, exact triangles): %zu clashes, %zu violations\n", clash_method_name(a.method),
              a.result.clashes.size() + a.motion.clashes.size(), a.result.violations.size() + a.supports.spans.size() + a.segregation.size());
  if (rep.voxel_resolution > 0.0)
    std::printf("  voxel layer: %.4g %s voxels; %llu planning queries decided by the map, %llu by Embree\n",
                rep.voxel_resolution, a.units.c_str(), static_cast<unsigned long long>(rep.voxel_decided),
                static_cast<unsigned long long>(rep.voxel_exact));
  if (rep.share_within_reach >= 0.0)
    std::printf("  supports: %zu clamps placed, %.1f%% of the cable length within reach of structure, "
                "%zu unsupported spans\n",
                rep.clamps_placed, 100.0 * rep.share_within_reach, a.supports.spans.size());
  print_support_findings(a, 10);
  print_portfolio_budgets(rep);
  print_bend_plans(rep, rep.routed.segments);
  print_motion_clashes(a, 10);
  for (const auto& u : rep.unrouted)
    std::printf("  NOT ROUTED %s (segment %s): %s — %s\n", u.cable.c_str(), u.segment.c_str(), u.reason.c_str(),
                u.message.c_str());
  std::size_t shown = 0;
  for (const auto& c : a.result.clashes) {
    if (++shown > 10) break;
    const std::string with = c.kind == ClashKind::CableStructure ? a.part_names[c.part]
                             : c.kind == ClashKind::CableCable  ? a.check_ids[c.other]
                                                                : std::string("itself");
    std::printf("  clash %s %s with %s at s=%.1f: clearance %.3f\n", clash_kind_name(c.kind),
                a.check_ids[c.cable].c_str(), with.c_str(), c.s, c.clearance);
  }
  for (const auto& v : a.result.violations) {
    if (++shown > 20) break;
    std::printf("  %s %s at s=%.1f: %.3f (limit %.3f)\n", violation_kind_name(v.kind), a.check_ids[v.cable].c_str(),
                v.s, v.value, v.limit);
  }
  // Without a budget every run differs: said once in report.json; the rest is worth a line.
  for (const auto& n : rep.unreproducible)
    if (rep.iterations > 0) std::printf("  not reproducible: %s\n", n.c_str());
  std::printf("  wrote %s/{routed.xml, report.json, cables.ply%s}\n", out.string().c_str(),
              rep.routed.kbl ? ", routed.kbl" : "");
}

}  // namespace

void add_iterations_option(CLI::App& cmd, long long& iterations) {
  cmd.add_option("--iterations", iterations,
                 "Planner iterations per segment (default: scene [routing], else none). With it, the same "
                 "--seed gives the same routed.xml, unless the time limit ends a plan first (reported) or the "
                 "planner is prm/prmstar (threaded: never reproducible). Bend re-plans get 2x, 4x")
      ->check(whole_number(1, kMaxPlanIterations));
}

int run_route(const std::string& scene_path, const RouteCommandOptions& o) {
  RenderOptions render;  // a bad size is a usage error: no output directory is made
  if (!o.render_size.empty()) parse_render_size(o.render_size, "--render-size", render);
  auto targets = route_output_files(o.out);
  for (auto& p : view_output_files(o.out)) targets.push_back(std::move(p));
  OutputSet outputs(o.out, targets);  // every target checked before any work; all replaced together
  ProgressBar bar(stderr, o.quiet || o.json);
  render.progress = bar.fn();
  SceneLoadOptions lo;
  lo.progress = bar.fn();
  SceneLoadReport lr;
  Scene scene = load_scene(scene_path, lo, &lr);
  if (!scene.has_harness) throw InputError({scene_path, 0, "[harness]"}, "the scene has no harness to route");
  RouteOptions ro;
  ro.planner = o.planner;
  ro.time_limit = o.time_limit;
  ro.seed = o.seed;
  ro.iterations = o.iterations;
  ro.threads = o.threads;
  ro.simplify = o.simplify;
  ro.voxel_layer = o.voxel_layer;
  ro.progress = bar.fn();
  RouteReport rep = route_scene(scene, ro);
  rep.timing.load = lr.load_ms;
  rep.audit.load_ms = lr.load_ms;
  for (const auto& n : lr.notes) rep.notes.push_back(n);
  // Tube resolution: a tenth of the smallest cable radius is finer than any viewer needs.
  const double chord = 0.1 * 0.5 * scene.harness.smallest_diameter();
  naming_cable_errors(rep.routed, [&] {  // a tube refused names its cable's element
    write_route_outputs(rep, outputs.staging(), chord > 0 ? chord : 0.01);
    return write_view_outputs(outputs.staging(), scene, rep.routed, route_report_json(rep), render);  // view.html, render.png
  });
  outputs.commit();
  if (o.json) std::cout << json_text(route_report_json(rep), 2) << "\n";
  else if (!o.quiet) print_summary(rep, o.out);
  return rep.exit_code();
}

void add_route_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("route", "Route every cable of a scene's harness, then audit it against the exact geometry");
  auto scene = std::make_shared<std::string>();
  auto o = std::make_shared<RouteCommandOptions>();
  o->render_size = default_render_size();
  cmd->add_option("SCENE", *scene, "Scene file (TOML)")->required();
  cmd->add_option("--out", o->out, "Output directory (routed.xml, report.json, cables.ply)")->check(non_empty_path())->capture_default_str();
  cmd->add_option("--planner", o->planner, "OMPL planner (rrtconnect, rrtstar, bitstar, prmstar, lazyprmstar, ...)");
  // Checked here: the options' "use the scene's" values (< 0) must not swallow a bad one.
  cmd->add_option("--time-limit", o->time_limit, "Planning seconds per segment (default: scene [routing])")
      ->check(finite_number(0.0, true));
  cmd->add_option("--seed", o->seed, "Random seed (default: scene [routing])")
      ->check(whole_number(0, std::numeric_limits<std::uint32_t>::max()));
  add_iterations_option(*cmd, o->iterations);
  cmd->add_option("--threads", o->threads, "Audit threads (default: all cores)")
      ->check(whole_number(1, kMaxThreads));
  cmd->add_option("--render-size", o->render_size, "Size of render.png, WIDTHxHEIGHT")->capture_default_str();
  cmd->add_flag("--simplify", o->simplify, "Plan among α-simplified parts instead of the exact ones (α-SIM, DESIGN §6)");
  cmd->add_flag("--voxel-layer", o->voxel_layer,
                "Answer the planning queries a voxel distance map proves from it, the rest with Embree (same routes "
                "validity; pays where planning, not the map's build, dominates)");
  cmd->add_flag("--json", o->json, "Print the report as JSON");
  cmd->add_flag("--quiet", o->quiet, "Print nothing (exit status only)");
  cmd->callback([scene, o, &exit_code]() { exit_code = run_route(*scene, *o); });
}

}  // namespace loom::app
