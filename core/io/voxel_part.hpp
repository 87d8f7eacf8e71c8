#pragma once
/// Scanned structure as a part: an OctoMap tree (.bt, .ot) or a point cloud (.pcd, .xyz,
/// .ply read as points) turned into the union of its occupied voxels, meshed as the
/// outward faces between occupied and free voxels. Every scanned point lies inside an
/// occupied voxel, so a distance to this mesh never exceeds the distance to the scan; the
/// mesh is within half a voxel diagonal of the occupied voxel centres (the part's accuracy).
/// Coordinates and resolution are the file's (the scene's transform applies afterwards).

#include "core/geometry.hpp"
#include "core/mesh.hpp"

#include <cstddef>
#include <filesystem>
#include <optional>

namespace loom {

/// How a scanned file becomes voxels.
struct VoxelPartOptions {
  double resolution = 0.0;     ///< point clouds: voxel edge, file units (> 0); trees: 0 (the file's own)
  std::optional<Vec3> origin;  ///< point clouds: sensor position, file frame; rays to the points mark free space
  bool unknown_occupied = false;  ///< voxels never observed, within the bounds of the observed ones, count as occupied
  std::size_t max_voxels = std::size_t(20) << 20;  ///< refuse a part with more occupied voxels than this
};

/// A scanned part as voxels and their boundary mesh (file frame and units).
struct VoxelPart {
  Mesh mesh;                        ///< outward faces between occupied and other voxels (2 triangles each)
  double resolution = 0.0;          ///< voxel edge, file units
  std::size_t occupied_voxels = 0;  ///< finest-level voxels counted as occupied (including filled unknown ones)
  std::size_t unknown_filled = 0;   ///< of them, unknown voxels filled because unknown = occupied
  std::size_t points = 0;           ///< point clouds: points inserted; trees: 0
};

/// True for .bt and .ot (OctoMap trees).
bool is_octree_file(const std::filesystem::path& p);
/// True for .pcd and .xyz; a .ply is a point cloud only when the part gives a resolution.
bool is_point_cloud_only_file(const std::filesystem::path& p);

/// Reads a scanned part. Throws InputError naming the file for a corrupt or truncated tree
/// (the node structure is checked before OctoMap reads it), an OctoMap tree type other than
/// OcTree, a resolution that is not positive and finite (point clouds: opt.resolution; given
/// for a tree), a point with a NaN or infinite coordinate, no occupied voxel, or more than
/// opt.max_voxels of them.
VoxelPart read_voxel_part(const std::filesystem::path& path, const VoxelPartOptions& opt);

}  // namespace loom
