#pragma once
/// SceneIndices: the obstacle indices of one scene, built once and shared by planning and
/// audit (DESIGN §7), and the rule that says which index answers which use:
///  - planning's coarse checks → VoxelMap (O(1) lookups, error ≤ half a voxel diagonal),
///    falling back to Embree when no voxel map could be built;
///  - anything reported → EmbreeIndex (exact triangles);
///  - certification of audits → FclIndex (exact, independent of Embree), else Embree.
/// Every choice and derived setting is returned as text in `log` and `choices` (no global
/// logger state), for the report.

#include "core/progress.hpp"
#include "core/scene.hpp"
#include "index/embree_index.hpp"
#include "index/fcl_index.hpp"
#include "index/voxel_map.hpp"

#include <memory>
#include <string>
#include <vector>

namespace loom {

/// What a query is for.
enum class QueryUse {
  PlanningCoarse,  ///< validity / clearance checks inside the planner
  Reported,        ///< distances and clashes written to a report
  Certification,   ///< the certified audit and cross-checks
};

/// "planning" | "reported" | "certification".
const char* query_use_name(QueryUse u);

/// Which index answers a use, and why.
struct IndexChoice {
  QueryUse use = QueryUse::Reported;
  std::string index;   ///< ObstacleIndex::name() of the chosen index
  std::string reason;  ///< one line, with the accuracy it guarantees
};

/// What to build.
struct SceneIndicesOptions {
  bool build_voxel = true;       ///< build the OctoMap voxel map for planning
  bool build_fcl = true;         ///< build FCL models for certification
  double voxel_resolution = 0.0;     ///< > 0 overrides the derived voxel edge (scene units)
  double voxel_max_distance = 0.0;   ///< > 0 overrides the derived reach (default 4 (r + c))
  std::size_t voxel_max_cells = std::size_t(64) << 20;  ///< dense grid budget; coarsens beyond
  EmbreeOptions embree;
  int threads = 0;  ///< TBB workers for builds (≤ 0: all)
  /// Stage "index": indices built (Embree, then FCL and the voxel map if asked), reported
  /// from the calling thread.
  ProgressFn progress;
};

/// The built indices of a scene with the choice of index per use.
struct SceneIndices {
  std::shared_ptr<const EmbreeIndex> embree;  ///< always built
  std::shared_ptr<const FclIndex> fcl;        ///< null unless built
  std::shared_ptr<const VoxelMap> voxel;      ///< null unless built
  std::vector<IndexChoice> choices;           ///< one per QueryUse
  std::vector<std::string> log;               ///< derivations, build times, fallbacks

  /// Builds the indices for `scene` (world frame, scene units). Throws InputError for bad
  /// meshes (see EmbreeIndex).
  static SceneIndices build(const Scene& scene, const SceneIndicesOptions& opt = {});
  /// The index that answers `use` (see the rule above).
  const ObstacleIndex& for_use(QueryUse use) const;
  /// The choice recorded for `use`.
  const IndexChoice& choice(QueryUse use) const;
};

}  // namespace loom
