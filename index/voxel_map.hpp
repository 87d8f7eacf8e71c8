#pragma once
/// VoxelMap: approximate obstacle model for planning (DESIGN §6–§7): an OctoMap OcTree of
/// the voxels the parts' surfaces pass through plus the interior voxels of closed parts,
/// and a dense Euclidean distance grid giving O(1) clearance lookups.
///
/// Resolution rule (derive_resolution): voxel edge = (r + c) / √3 for the smallest cable
/// radius r and the routing clearance c, so that the distance error bound, half the
/// voxel diagonal (edge·√3/2), is at most half of the gap r + c the planner must keep.
///
/// Distances: the grid stores, at each voxel centre within max_distance of the parts, the
/// exact distance to the nearest part (0 inside closed parts), computed by an exact index
/// (EmbreeIndex) seeded by a Felzenszwalb–Huttenlocher EDT of the occupied voxels; a query
/// returns the value of the voxel containing the point. Distance is 1-Lipschitz, so the
/// error is ≤ half the voxel diagonal (plus float storage rounding); accuracy() states it.
/// Beyond max_distance the map only knows "farther than max_distance".
/// A map loaded from a .bt file has no triangles: its distances come from the EDT of the
/// occupied voxel centres alone and are bounded by the full voxel diagonal.
///
/// OctoMap keys are 16-bit: the map covers ±32768 voxels per axis around the world origin.
/// The constructor checks that the scene (plus max_distance) fits and throws InputError if not.

#include "core/part.hpp"
#include "index/obstacle_index.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace octomap {
class OcTree;
}

namespace loom {

/// Settings of a voxel map.
struct VoxelOptions {
  double resolution = 0.0;    ///< voxel edge, scene units (> 0); see VoxelMap::derive_resolution
  double max_distance = 0.0;  ///< distances are known up to this (scene units); ≤ 0: 8 voxels
  std::size_t max_cells = std::size_t(64) << 20;  ///< budget for the dense distance grid (cells)
  int threads = 0;            ///< TBB workers for the build (≤ 0: all cores)
  /// Exact distances at the voxel centres within max_distance (error ≤ half a voxel
  /// diagonal). false: the distance transform of the occupied voxels alone, with no exact
  /// query in the build (error ≤ a voxel diagonal; cells whose side of a closed part the
  /// interior fill could not decide count as occupied).
  bool exact_refine = true;
};

/// Timings and sizes of a voxel map build (seconds, counts).
struct VoxelBuildStats {
  double voxelise_seconds = 0.0;  ///< surface voxels + interior fill + OctoMap insertion
  double edt_seconds = 0.0;       ///< Euclidean distance transform of the occupied voxels
  double refine_seconds = 0.0;    ///< exact distances at the voxel centres within max_distance
  std::size_t surface_voxels = 0;
  std::size_t interior_voxels = 0;
  std::size_t refined_voxels = 0;
  std::size_t grid_cells = 0;
};

/// Voxel occupancy (OctoMap) + distance grid; see ObstacleIndex for the query contract.
/// Per-part queries (closest_on_part) are answered by the exact index the map was built
/// with; inside() is exact too (voxel interior flags first, the exact index near surfaces).
class VoxelMap : public ObstacleIndex {
 public:
  /// Voxel edge for a cable of radius `cable_radius` and a required clearance `clearance`
  /// (scene units): (r + c) / √3. Throws std::invalid_argument unless r + c > 0.
  static double derive_resolution(double cable_radius, double clearance);

  /// Builds the map of `parts` (world frame). `exact` answers per-part queries and the
  /// exact distances at voxel centres; null builds an EmbreeIndex over `parts`. Throws
  /// InputError if the scene does not fit OctoMap's key range or the grid exceeds
  /// opt.max_cells; std::invalid_argument for a non-positive resolution.
  VoxelMap(const std::vector<Part>& parts, const VoxelOptions& opt,
           std::shared_ptr<const ObstacleIndex> exact = nullptr);
  ~VoxelMap() override;
  VoxelMap(const VoxelMap&) = delete;
  VoxelMap& operator=(const VoxelMap&) = delete;

  /// Loads an OctoMap .bt file (occupied voxels, no parts: part_count() is 1, every hit
  /// reports part 0). Throws InputError naming the file if it cannot be read.
  static std::unique_ptr<VoxelMap> load_bt(const std::string& path, const VoxelOptions& opt);
  /// Writes the occupancy as an OctoMap .bt file (atomically). Throws std::runtime_error.
  void save_bt(const std::string& path) const;

  std::string name() const override { return "voxel"; }
  IndexAccuracy accuracy() const override;
  int part_count() const override { return part_count_; }

  ClosestHit closest(const Vec3& p, double max_radius = std::numeric_limits<double>::infinity()) const override;
  ClosestHit closest_on_part(const Vec3& p, int part,
                             double max_radius = std::numeric_limits<double>::infinity()) const override;
  bool inside(const Vec3& p, int* part = nullptr) const override;
  /// With the exact index it was built from: its answer. A loaded map knows one part per
  /// solid voxel (part 0 when loaded from a file): that part, or none.
  void inside_parts(const Vec3& p, std::vector<int>& out) const override;
  RayHit ray(const Vec3& origin, const Vec3& dir,
             double t_max = std::numeric_limits<double>::infinity()) const override;
  bool any_within(const Vec3& p, double r) const override;
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override;
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                     double* segment_param = nullptr) const override;
  ClosestHit segment_closest(const Vec3& a, const Vec3& b,
                             double max_radius = std::numeric_limits<double>::infinity(),
                             double* segment_param = nullptr) const override;

  /// O(1) distance from p to the nearest part (scene units; 0 inside closed parts;
  /// +infinity beyond max_distance()). Error ≤ accuracy().abs_error.
  double distance(const Vec3& p) const;
  /// Voxel edge (scene units).
  double resolution() const { return res_; }
  /// Distances are known up to this (scene units).
  double max_distance() const { return max_distance_; }
  /// Build timings and counts.
  const VoxelBuildStats& stats() const { return stats_; }
  /// Bytes of the distance grid, flags, part ids and the OcTree.
  std::size_t memory_bytes() const;
  /// Occupied OcTree leaves (after pruning).
  std::size_t octree_leaf_count() const;

 private:
  VoxelMap() = default;
  void init_grid(const AABB& box, const std::string& what);
  void voxelise(const std::vector<Part>& parts);
  void fill_tree();
  void run_edt();
  void refine();
  long cell_of(const Vec3& p) const;  ///< linear cell index, -1 outside the grid
  Vec3 cell_centre(long i, long j, long k) const;

  double res_ = 0.0;
  double max_distance_ = 0.0;
  double half_diag_ = 0.0;
  bool from_file_ = false;
  bool edt_only_ = false;  ///< built without exact_refine
  int part_count_ = 0;
  int threads_ = 0;
  std::size_t max_cells_ = 0;
  long base_[3] = {0, 0, 0};  ///< integer voxel coordinate (floor(x/res)) of cell 0
  long n_[3] = {0, 0, 0};
  std::vector<float> dist_;          ///< per cell: distance (scene units), +inf beyond max_distance
  std::vector<std::int32_t> part_;   ///< per cell: nearest part (-1 unknown)
  std::vector<std::uint8_t> flags_;  ///< per cell: 0 free, 1 surface, 2 interior of a closed part, 3 undecided by the fill
  std::unique_ptr<octomap::OcTree> tree_;
  std::shared_ptr<const ObstacleIndex> exact_;
  VoxelBuildStats stats_;
};

}  // namespace loom
