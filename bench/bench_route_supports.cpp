// The price of support: the wing section with its harness in three cable classes
// (examples/wing-classes) routed with supports at several clamp spacings and clamp reaches,
// with the planner's support term on and off, and with its branch points left to the router.
// For each run: cables routed, clashes, bend and clearance violations, unsupported spans,
// segregation findings, clamps placed, the share of cable length within clamp reach of
// structure, total routed length (against the run with no spacing to keep, in the same
// process) and planning time. Fixed seed and iteration budget; two audit threads.
// Writes bench/results/route_supports.csv and route_supports.png.
//
// Usage: bench_route_supports            (every variant)
//        bench_route_supports VARIANT    (that variant and the one without spacing; no files)
//        bench_route_supports --chart    (redraws the chart from the CSV)
#include "core/io/scene_load.hpp"
#include "core/centerline.hpp"
#include "routing/route/route_pipeline.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace loom;

/// "No spacing to keep": a spacing longer than any cable, so no support is pulled or
/// required, while the share within reach is still measured.
constexpr double kNoSpacing = 1e6;

struct Variant {
  std::string name;
  double spacing = 450.0;  ///< clamp_spacing, mm
  double reach = 25.0;     ///< clamp_reach, mm
  double weight = 0.0;     ///< support_weight
  bool free_branches = false;  ///< branch points left to the router
};

/// Total length of the routed segment curves, mm.
double routed_length(const Harness& h) {
  double total = 0.0;
  for (const Segment& s : h.segments)
    if (s.bspline) total += Centerline(s.bspline->degree, s.bspline->knots, s.bspline->control_points).length();
  return total;
}

void chart(const std::string& dir) {
  std::ostringstream gp;
  gp << "set datafile separator ','\nset terminal pngcairo size 1200,450\nset output '" << dir
     << "route_supports.png'\nset multiplot layout 1,2 title 'Wing section, three cable classes: the price of "
        "support'\nset key top left\nset grid\n"
        "set xlabel 'clamp spacing (mm; reach 25 mm)'\nset ylabel 'length / length without spacing'\n"
        "set y2label 'share within reach (%)'\nset ytics nomirror\nset y2tics\nset logscale x\n"
        "set yrange [0.9:1.2]\nset y2range [0:100]\n"
        "plot '"
     << dir << "route_supports.csv' every ::1 using ($3 == 1 && $4 == 25 && $5 == 0 && $6 == 0 ? $2 : 1/0):15 "
        "with linespoints title 'length', '' every ::1 using ($3 == 1 && $4 == 25 && $5 == 0 && $6 == 0 ? $2 : 1/0):($13 "
        "* 100) axes x1y2 with linespoints title 'share within reach'\n"
        "set xlabel 'clamp reach (mm; spacing 450 mm)'\nset ylabel 'planning time (s)'\nunset logscale x\n"
        "set yrange [0:*]\n"
        "plot '"
     << dir << "route_supports.csv' every ::1 using ($2 == 450 && $5 == 0 && $6 == 0 ? $4 : 1/0):($16 / 1000) smooth unique with "
        "linespoints title 'plan time', '' every ::1 using ($2 == 450 && $5 == 0 && $6 == 0 ? $4 : 1/0):($13 * 100) axes "
        "x1y2 smooth unique with linespoints title 'share within reach'\nunset multiplot\n";
  const std::string cmd = "gnuplot <<'EOF'\n" + gp.str() + "EOF\n";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed (chart not drawn)\n");
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/bench/results/";
  const std::string only = argc > 1 && std::string(argv[1]) != "--chart" ? argv[1] : "";
  if (argc > 1 && std::string(argv[1]) == "--chart") {
    chart(dir);
    return 0;
  }
  const Scene base = load_scene(std::string(LOOM_SOURCE_DIR) + "/examples/wing-classes/scene.toml");
  std::vector<Variant> variants = {{"no spacing", kNoSpacing}};
  for (double s : {150.0, 300.0, 450.0, 610.0}) variants.push_back({"spacing", s});
  for (double r : {10.0, 50.0, 100.0}) variants.push_back({"reach", 450.0, r});
  variants.push_back({"support term 1", 450.0, 25.0, 1.0});
  variants.push_back({"branch points to the router", 450.0, 25.0, 0.0, true});

  std::ofstream csv(only.empty() ? dir + "route_supports.csv" : "/dev/null");
  csv << "variant,clamp_spacing_mm,clamp_spacing_set,clamp_reach_mm,support_weight,free_branches,routed,cables,"
         "clashes,violations,unsupported_spans,segregation,share_within_reach,clamps,length_ratio,plan_ms,length_mm\n";
  double base_length = 0.0;
  for (const Variant& v : variants) {
    if (!only.empty() && v.name != only && v.name != "no spacing") continue;
    Scene sc = base;
    sc.routing.supports = true;
    sc.routing.clamp_spacing = {v.spacing, "bench"};
    sc.routing.clamp_reach = {v.reach, "bench"};
    sc.routing.support_weight = {v.weight, "bench"};
    if (v.free_branches)
      for (auto& b : sc.harness.branches) b.position.reset();
    RouteOptions opt;
    opt.threads = 2;
    const RouteReport rep = route_scene(sc, opt);
    const double length = routed_length(rep.routed);
    if (base_length == 0.0) base_length = length;
    const std::size_t routed = rep.routed.cables.size() - rep.unrouted.size();
    const double ratio = length / base_length;
    std::printf("%-28s spacing %7.0f reach %5.0f weight %.0f: %zu/%zu routed, %zu clashes, %zu violations, %zu "
                "unsupported spans, %zu segregation, %zu clamps, %.1f%% within reach, length %.0f mm (%.3fx), "
                "plan %.2f s\n",
                v.name.c_str(), v.spacing, v.reach, v.weight, routed, rep.routed.cables.size(),
                rep.audit.result.clashes.size(), rep.audit.result.violations.size(), rep.audit.supports.spans.size(),
                rep.audit.segregation.size(), rep.clamps_placed, 100.0 * rep.share_within_reach, length, ratio,
                rep.timing.plan / 1000.0);
    for (std::size_t k = 0; k < rep.unrouted.size() && k < 3; ++k)
      std::printf("  not routed %s (%s): %s\n", rep.unrouted[k].cable.c_str(), rep.unrouted[k].segment.c_str(),
                  rep.unrouted[k].message.c_str());
    csv << v.name << ',' << v.spacing << ',' << (v.spacing < kNoSpacing ? 1 : 0) << ',' << v.reach << ',' << v.weight
        << ',' << (v.free_branches ? 1 : 0) << ',' << routed << ',' << rep.routed.cables.size() << ','
        << rep.audit.result.clashes.size() << ',' << rep.audit.result.violations.size() << ','
        << rep.audit.supports.spans.size() << ',' << rep.audit.segregation.size() << ',' << rep.share_within_reach
        << ',' << rep.clamps_placed << ',' << ratio << ',' << rep.timing.plan << ',' << length << '\n';
    csv.flush();
  }
  csv.close();
  if (!only.empty()) return 0;
  chart(dir);
  std::printf("wrote %sroute_supports.csv and route_supports.png\n", dir.c_str());
  return 0;
}
