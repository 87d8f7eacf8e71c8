#include "index/scene_indices.hpp"

#include "core/stopwatch.hpp"
#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace loom {

namespace {

/// OctoMap key half-range (voxels per axis on each side of the origin).
constexpr double kOctomapKeyHalf = 32767.0;
/// Default reach of the distance map, in multiples of the gap r + c.
constexpr double kReachGaps = 4.0;
/// Voxel edge when the scene gives no cable radius or clearance: diagonal / this.
constexpr double kFallbackVoxelsPerDiagonal = 256.0;
/// Factor by which the voxel edge grows while the grid exceeds its budget.
constexpr double kCoarsenFactor = 1.25;


/// Cells of the dense distance grid for box `b` at edge `res` with `reach` margin.
double grid_cells(const AABB& b, double res, double reach) {
  const Vec3 s = b.size() + Vec3::Constant(2.0 * (reach + 2.0 * res));
  return std::ceil(s.x() / res) * std::ceil(s.y() / res) * std::ceil(s.z() / res);
}

}  // namespace

const char* query_use_name(QueryUse u) {
  switch (u) {
    case QueryUse::PlanningCoarse: return "planning";
    case QueryUse::Reported: return "reported";
    case QueryUse::Certification: return "certification";
  }
  return "?";
}

SceneIndices SceneIndices::build(const Scene& scene, const SceneIndicesOptions& opt) {
  SceneIndices out;
  AABB box;
  for (const Part& p : scene.parts) box.extend(p.mesh.bounds());
  const bool want_voxel = opt.build_voxel && !box.empty();
  ProgressCounter built(opt.progress, "index", 1 + (opt.build_fcl ? 1 : 0) + (want_voxel ? 1 : 0), "indices");
  const Stopwatch t0;
  out.embree = std::make_shared<EmbreeIndex>(scene.parts, opt.embree);
  built.add();
  out.log.push_back("embree: " + std::to_string(out.embree->triangle_count()) + " triangles in " +
                    std::to_string(scene.parts.size()) + " parts, built in " + full_precision(t0.seconds()) +
                    " s; " + out.embree->accuracy().description);
  if (opt.build_fcl) {
    const Stopwatch t1;
    out.fcl = std::make_shared<FclIndex>(scene.parts);
    out.log.push_back("fcl: OBBRSS models built in " + full_precision(t1.seconds()) + " s; " +
                      std::to_string(out.fcl->direct_triangle_count()) +
                      " degenerate/tiny triangles answered by the exact kernels");
    built.add();
  }
  if (want_voxel) {
    const double r = scene.has_harness ? 0.5 * scene.harness.smallest_diameter() : 0.0;
    const double c = std::max(0.0, scene.routing.clearance.value);
    double res = 0.0;
    std::string rule;
    if (opt.voxel_resolution > 0.0) {
      res = opt.voxel_resolution;
      rule = "given";
    } else if (r + c > 0.0) {
      res = VoxelMap::derive_resolution(r, c);
      rule = "(r + c)/sqrt(3) with smallest cable radius r = " + full_precision(r) + " and clearance c = " +
             full_precision(c);
    } else {
      res = box.diagonal() / kFallbackVoxelsPerDiagonal;
      rule = "scene diagonal / 256 (no cable radius or clearance in the scene)";
    }
    const double gap = r + c > 0.0 ? r + c : 4.0 * res;
    const double reach = opt.voxel_max_distance > 0.0 ? opt.voxel_max_distance : kReachGaps * gap;
    // OctoMap's 16-bit keys: every coordinate within ±32767 voxels of the origin.
    const double extent = std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff()) + reach + 2.0 * res;
    if (extent / res > kOctomapKeyHalf) {
      const double need = extent / kOctomapKeyHalf;
      out.log.push_back("voxel: resolution " + full_precision(res) + " would put the scene beyond OctoMap's +/-32768 "
                        "voxel keys; coarsened to " + full_precision(need));
      res = need;
    }
    while (res > 0.0 && grid_cells(box, res, reach) > static_cast<double>(opt.voxel_max_cells)) {
      const double next = res * kCoarsenFactor;
      out.log.push_back("voxel: resolution " + full_precision(res) + " needs " +
                        full_precision(grid_cells(box, res, reach)) + " grid cells (budget " +
                        std::to_string(opt.voxel_max_cells) + "); coarsened to " + full_precision(next));
      res = next;
    }
    VoxelOptions vo;
    vo.resolution = res;
    vo.max_distance = reach;
    vo.max_cells = opt.voxel_max_cells;
    vo.threads = opt.threads;
    try {
      const Stopwatch t2;
      out.voxel = std::make_shared<VoxelMap>(scene.parts, vo, out.embree);
      out.log.push_back("voxel: resolution " + full_precision(res) + " (" + rule + "), reach " + full_precision(reach) +
                        ", built in " + full_precision(t2.seconds()) + " s; " + out.voxel->accuracy().description);
    } catch (const InputError& e) {
      out.log.push_back(std::string("voxel: not built: ") + e.what());
    }
  }
  built.finish();
  // The rule.
  {
    IndexChoice plan{QueryUse::PlanningCoarse, "", ""};
    if (out.voxel) {
      plan.index = out.voxel->name();
      plan.reason = "O(1) voxel distance lookups for the planner's many checks; " + out.voxel->accuracy().description;
    } else {
      plan.index = out.embree->name();
      plan.reason = "no voxel map (not requested, empty scene or over budget): exact Embree queries";
    }
    out.choices.push_back(plan);
    out.choices.push_back({QueryUse::Reported, out.embree->name(),
                           "everything reported uses the exact triangles; " + out.embree->accuracy().description});
    if (out.fcl)
      out.choices.push_back({QueryUse::Certification, out.fcl->name(),
                             "independent exact distances (FCL) to certify audits; " + out.fcl->accuracy().description});
    else
      out.choices.push_back({QueryUse::Certification, out.embree->name(), "FCL not built: exact Embree queries"});
  }
  for (const IndexChoice& ch : out.choices)
    out.log.push_back(std::string("choice: ") + query_use_name(ch.use) + " -> " + ch.index + " (" + ch.reason + ")");
  return out;
}

const IndexChoice& SceneIndices::choice(QueryUse use) const {
  for (const IndexChoice& c : choices)
    if (c.use == use) return c;
  throw std::logic_error("scene indices: no choice recorded (build() not called)");
}

const ObstacleIndex& SceneIndices::for_use(QueryUse use) const {
  const std::string& name = choice(use).index;
  if (voxel && name == voxel->name()) return *voxel;
  if (fcl && name == fcl->name()) return *fcl;
  if (embree) return *embree;
  throw std::logic_error("scene indices: no index built");
}

}  // namespace loom
