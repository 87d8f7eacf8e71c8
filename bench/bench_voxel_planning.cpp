// The voxel layer in planning: each scene routed with Embree answering every planning query
// (exact-only) and with the voxel distance map in front of it (voxel-first), runs
// interleaved, best of REPS. Scenes: the bundled wing section (147k triangles), the same
// wing tessellated finer (1.07M triangles: linear deflection 0.004 mm, 2.5°), and the
// building-scan example (OctoMap's scan of a building floor as 714k voxel-face triangles).
// Per variant: planning time (wall; planning is one thread), the index stage (Embree + the
// map), the obstacle queries Embree answered and those the map decided, the map's bytes
// against Embree's, and the routes' validity from the exact audit (clashes, violations,
// unrouted cables, routed length). Writes bench/results/voxel_planning.csv.
//
// Usage: bench_voxel_planning [REPS]
#include "core/io/scene_load.hpp"
#include "index/embree_index.hpp"
#include "routing/route/route_pipeline.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace loom;
namespace fs = std::filesystem;

/// The wing section's scene with its part files made absolute and a finer tessellation,
/// written beside the results (the STEP files stay where they are).
fs::path fine_wing_scene(const fs::path& dir) {
  const fs::path wing = fs::path(LOOM_SOURCE_DIR) / "examples/wing-section";
  std::ifstream in(wing / "scene.toml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string absolute =
      std::regex_replace(text.str(), std::regex("file = \""), "file = \"" + wing.string() + "/");
  const fs::path out = dir / "wing-fine.toml";
  std::ofstream(out) << absolute << "\n[tessellation]\nlinear_deflection = 0.004\nangular_deflection_deg = 2.5\n";
  return out;
}

struct Run {
  RouteReport rep;
  double plan_ms = 1e300, index_ms = 1e300;
};

double routed_length(const RouteReport& rep) {
  double sum = 0.0;
  for (const auto& c : rep.audit.result.cables) sum += c.length;
  return sum;
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const fs::path results = fs::path(LOOM_SOURCE_DIR) / "bench/results";
  const fs::path scratch = fs::temp_directory_path() / "loom-bench-voxel-planning";
  fs::create_directories(scratch);
  const std::vector<std::pair<std::string, fs::path>> scenes{
      {"wing-section", fs::path(LOOM_SOURCE_DIR) / "examples/wing-section/scene.toml"},
      {"wing-section-fine", fine_wing_scene(scratch)},
      {"building-scan", fs::path(LOOM_SOURCE_DIR) / "examples/building-scan/scene.toml"}};
  std::ofstream csv(results / "voxel_planning.csv");
  csv << "scene,triangles,variant,plan_ms,index_ms,embree_queries,map_decided,embree_bytes,map_bytes,"
         "map_resolution,routed,unrouted,clashes,violations,routed_length\n";
  for (const auto& [name, file] : scenes) {
    const Scene scene = load_scene(file);
    std::size_t triangles = 0;
    for (const auto& p : scene.parts) triangles += p.mesh.triangle_count();
    Run runs[2];
    for (int r = 0; r < reps; ++r)
      for (int v = 0; v < 2; ++v) {
        RouteOptions opt;
        opt.threads = 2;
        opt.voxel_layer = v == 1;
        RouteReport rep = route_scene(scene, opt);
        Run& best = runs[v];
        best.plan_ms = std::min(best.plan_ms, rep.timing.plan);
        best.index_ms = std::min(best.index_ms, rep.timing.index);
        best.rep = std::move(rep);
      }
    // Memory: the planning index on its own, against the map the voxel layer built.
    const EmbreeIndex embree(scene.parts);
    const std::size_t map_bytes = runs[1].rep.voxel_bytes;
    for (int v = 0; v < 2; ++v) {
      const RouteReport& rep = runs[v].rep;
      const std::size_t cables = rep.audit.cables.size();  // every harness cable
      csv << name << ',' << triangles << ',' << (v ? "voxel-first" : "exact-only") << ',' << runs[v].plan_ms << ','
          << runs[v].index_ms << ',' << rep.voxel_exact << ',' << rep.voxel_decided << ',' << embree.memory_bytes()
          << ',' << (v ? map_bytes : 0) << ',' << rep.voxel_resolution << ',' << cables - rep.unrouted.size() << ','
          << rep.unrouted.size() << ',' << rep.audit.result.clashes.size() << ','
          << rep.audit.result.violations.size() << ',' << routed_length(rep) << '\n';
      std::printf("%-18s %-11s plan %8.1f ms  index %7.1f ms  embree queries %9llu  map decided %8llu  "
                  "clashes %zu violations %zu unrouted %zu length %.1f\n",
                  name.c_str(), v ? "voxel-first" : "exact-only", runs[v].plan_ms, runs[v].index_ms,
                  static_cast<unsigned long long>(rep.voxel_exact), static_cast<unsigned long long>(rep.voxel_decided),
                  rep.audit.result.clashes.size(), rep.audit.result.violations.size(), rep.unrouted.size(),
                  routed_length(rep));
    }
  }
  std::printf("wrote %s\n", (results / "voxel_planning.csv").string().c_str());
  return 0;
}
