// Routing a generated real-shaped harness (bench/harness_gen.hpp: ≈250 wires, ≈180 segments,
// nodes of up to 16 legs) in empty space, then inside a structure (200 parts generated
// around its generated routes: brackets under the trunk, spheres, drums and rods), its branch
// points left to the router, no segment path given. For each variant (planning among the
// parts only as before, and harness-aware; each with Informed RRT* and the portfolio; the
// harness-aware portfolio in the structure): cable–cable clashes the exact
// audit finds (target 0), bend violations, total routed segment length against the
// straight-line tree through the routed nodes (target ≤ 1.3×), and the wall time with two
// audit threads (target ≤ 30 s). Fixed seeds. Writes bench/results/route_harness.csv.
//
// Usage: bench_route_harness [--quick | --structure]   (--quick: the harness-aware portfolio
// in empty space only; --structure: in the structure only)
#include "bench/harness_gen.hpp"
#include "core/stopwatch.hpp"
#include "routing/route/route_pipeline.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace loom;

constexpr unsigned kHarnessSeed = 1;
constexpr unsigned kRouteSeed = 20261128;
/// Planner iterations per segment (and the per-segment time limit as a safety cap).
constexpr long long kIterations = 400;
constexpr double kTimeLimit = 1.0;
/// Routing clearance, mm (no structure: it only shapes the planner's corridor).
constexpr double kClearance = 1.0;

/// Parts of the structure variant, and triangles per part.
constexpr int kStructureParts = 200;
constexpr int kStructureTriangles = 2000;
constexpr unsigned kStructureSeed = 7;

struct Variant {
  std::string name, planner;
  bool aware = true;
  bool structure = false;
};

/// The generated harness with its branch points and segment paths removed; with
/// `structure`, inside parts generated around its generated routes.
Scene generated_scene(bool structure) {
  bench::HarnessShape shape;
  shape.seed = kHarnessSeed;
  bench::GeneratedHarness g = bench::generate_harness(shape);
  Scene sc;
  sc.name = structure ? "generated-in-structure" : "generated-empty";
  if (structure) sc.parts = bench::harness_structure(g.harness, kStructureParts, kStructureTriangles, kStructureSeed);
  sc.harness = std::move(g.harness);
  for (auto& b : sc.harness.branches) b.position.reset();
  for (auto& s : sc.harness.segments) {
    s.path.clear();
    s.bspline.reset();
  }
  sc.has_harness = true;
  sc.routing.clearance = {kClearance, "bench"};
  sc.routing.time_limit = {kTimeLimit, "bench"};
  sc.routing.iterations = {static_cast<double>(kIterations), "bench"};
  sc.routing.seed = kRouteSeed;
  sc.simplify.dim_pre = {sc.harness.smallest_diameter(), "bench"};
  return sc;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const bool structure_only = argc > 1 && std::strcmp(argv[1], "--structure") == 0;
  const Scene empty = generated_scene(false), structured = generated_scene(true);
  int max_degree = 0;
  {
    const HarnessTopology topo(empty.harness);
    for (const auto& b : empty.harness.branches)
      max_degree = std::max(max_degree, static_cast<int>(topo.incident_segments(b.id).size()));
  }
  std::printf("generated harness: %zu wires, %zu segments, %zu branch points (max degree %d)\n",
              empty.harness.cables.size(), empty.harness.segments.size(), empty.harness.branches.size(), max_degree);
  std::vector<Variant> variants;
  if (!quick && !structure_only) {
    variants.push_back({"parts-only informedrrtstar", "informedrrtstar", false});
    variants.push_back({"harness-aware informedrrtstar", "informedrrtstar", true});
  }
  if (!structure_only) variants.push_back({"harness-aware portfolio", "portfolio", true});
  variants.push_back({"harness-aware portfolio in structure", "portfolio", true, true});

  const std::string path = std::string(LOOM_SOURCE_DIR) + "/bench/results/route_harness.csv";
  std::ofstream csv(path);
  csv << "variant,planner,harness_aware,parts,wires,segments,max_degree,routed_cables,cable_cable_clashes,all_clashes,"
         "bend_violations,routed_length_mm,straight_tree_mm,length_ratio,plan_ms,total_ms\n";
  for (const Variant& v : variants) {
    Scene scene = v.structure ? structured : empty;
    scene.routing.planner = v.planner;
    RouteOptions opt;
    opt.threads = 2;
    opt.harness_aware = v.aware;
    const Stopwatch t0;
    const RouteReport rep = route_scene(scene, opt);
    const double total_ms = t0.ms();
    std::size_t cable_cable = 0, bends = 0;
    for (const auto& c : rep.audit.result.clashes) cable_cable += c.kind == ClashKind::CableCable;
    for (const auto& x : rep.audit.result.violations) bends += x.kind == ViolationKind::BendRadius;
    double routed = 0.0, straight = 0.0;
    for (const Segment& s : rep.routed.segments) {
      const auto a = rep.routed.node_position(s.from), b = rep.routed.node_position(s.to);
      if (!a || !b || !s.bspline) continue;
      straight += (*b - *a).norm();
      routed += Centerline(s.bspline->degree, s.bspline->knots, s.bspline->control_points).length();
    }
    const std::size_t routed_cables = rep.routed.cables.size() - rep.unrouted.size();
    std::printf("%-38s %zu/%zu routed, %zu cable-cable clashes (%zu in all), %zu bend violations, length %.0f mm = "
                "%.3f x straight tree, plan %.1f s, total %.1f s\n",
                v.name.c_str(), routed_cables, rep.routed.cables.size(), cable_cable, rep.audit.result.clashes.size(),
                bends, routed, straight > 0 ? routed / straight : 0.0, rep.timing.plan / 1000.0, total_ms / 1000.0);
    for (std::size_t k = 0; k < rep.unrouted.size() && k < 5; ++k)
      std::printf("  not routed %s (%s): %s\n", rep.unrouted[k].cable.c_str(), rep.unrouted[k].segment.c_str(),
                  rep.unrouted[k].message.c_str());
    csv << v.name << "," << v.planner << "," << (v.aware ? 1 : 0) << "," << scene.parts.size() << ","
        << rep.routed.cables.size() << ","
        << rep.routed.segments.size() << "," << max_degree << "," << routed_cables << "," << cable_cable << ","
        << rep.audit.result.clashes.size() << "," << bends << "," << routed << "," << straight << ","
        << (straight > 0 ? routed / straight : 0.0) << "," << rep.timing.plan << "," << total_ms << "\n";
    csv.flush();
  }
  std::printf("wrote %s\n", path.c_str());
  return 0;
}
