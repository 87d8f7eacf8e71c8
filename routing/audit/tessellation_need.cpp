// Tessellation by need: which coarse CAD parts the cables come near, and their refinement.
#include "routing/audit/tessellation_need.hpp"

#include "core/io/mesh_read.hpp"
#include "core/io/scene_load.hpp"
#include "core/stopwatch.hpp"
#include "index/box_tree.hpp"
#include "index/embree_index.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <mutex>

namespace loom {

namespace {

/// A CAD part meshed coarser than the fine deflection (rounding aside).
bool coarse(const Part& p, double fine) { return is_cad_file(p.source_file) && p.deflection > fine * (1.0 + 1e-12); }

}  // namespace

std::vector<int> parts_within_reach(const std::vector<Part>& parts, const std::vector<CableInput>& cables,
                                    double routing_clearance, double fine_deflection, double tolerance) {
  // Only the coarse CAD parts are candidates: the index holds them alone (the scene's
  // meshes and fine parts can be far larger and are never refined).
  std::vector<int> candidates;
  std::vector<Part> coarse_parts;
  std::vector<double> reach_beyond;  // per candidate: required clearance + its deflection
  for (std::size_t q = 0; q < parts.size(); ++q)
    if (coarse(parts[q], fine_deflection)) {
      candidates.push_back(static_cast<int>(q));
      coarse_parts.push_back(parts[q]);
      reach_beyond.push_back(std::max(0.0, routing_clearance + parts[q].clearance) + parts[q].deflection);
    }
  if (candidates.empty() || cables.empty()) return {};
  const double widest = *std::max_element(reach_beyond.begin(), reach_beyond.end());
  const EmbreeIndex index(coarse_parts);
  std::vector<AABB> boxes(coarse_parts.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) boxes[k] = *index.part_bounds(static_cast<int>(k));
  const BoxTree tree(std::move(boxes));
  std::vector<char> near(coarse_parts.size(), 0);
  std::mutex mu;
  tbb::parallel_for(std::size_t{0}, cables.size(), [&](std::size_t c) {
    const CableInput& cable = cables[c];
    const double r = cable.radius;
    std::vector<char> mine(coarse_parts.size(), 0);
    std::vector<std::uint32_t> cand;
    std::vector<int> inside;
    for (const auto& [s, p] : cable.curve.sample_by_arc_length(r)) {
      (void)s;
      tree.overlapping(AABB{p, p}.inflated(1.5 * r + tolerance + widest), cand);
      for (const std::uint32_t k : cand)
        if (!mine[k] && index.closest_on_part(p, static_cast<int>(k), 1.5 * r + tolerance + reach_beyond[k]).found())
          mine[k] = 1;
      if (!cand.empty()) {
        // Deep inside a large closed part no surface is near, and that is a clash too.
        index.inside_parts(p, inside);
        for (const int k : inside) mine[static_cast<std::size_t>(k)] = 1;
      }
    }
    std::lock_guard<std::mutex> lock(mu);
    for (std::size_t k = 0; k < near.size(); ++k) near[k] = static_cast<char>(near[k] | mine[k]);
  });
  std::vector<int> out;
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (near[k]) out.push_back(candidates[k]);
  return out;
}

std::string tessellation_note(const TessellationByNeed& t) {
  if (!t.used) return "";
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "tessellation by need: %zu CAD parts meshed at %g, %zu left at %g (no cable within their reach: "
                "they hold no finding at either)",
                t.refined.size(), t.fine_deflection, t.coarse_parts, t.coarse_deflection);
  return buf;
}

TessellationByNeed tessellate_by_need(Scene& scene, const std::vector<CableInput>& cables, double tolerance,
                                      CadShapeStore* cad_shapes) {
  TessellationByNeed out;
  if (!scene.tessellation.by_need) return out;
  const Stopwatch t0;
  out.used = true;
  out.coarse_deflection = scene.tessellation.coarse_deflection.value;
  out.fine_deflection = scene.tessellation.linear_deflection.value;
  out.refined = parts_within_reach(scene.parts, cables, scene.routing.clearance.value, out.fine_deflection, tolerance);
  if (!out.refined.empty()) retessellate_parts(scene, out.refined, out.fine_deflection, cad_shapes);
  for (const Part& p : scene.parts)
    if (coarse(p, out.fine_deflection)) ++out.coarse_parts;
  out.ms = t0.ms();
  return out;
}

}  // namespace loom
