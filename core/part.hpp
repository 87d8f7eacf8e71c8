#pragma once
/// A part of the scene: named, meshed geometry in world coordinates.

#include "core/mesh.hpp"
#include "core/motion.hpp"

#include <cmath>
#include <optional>
#include <string>

namespace loom {

/// What a part is for the harness.
enum class PartRole {
  Structure,  ///< a solid the cables must not hit (ribs, spars, boxes)
  KeepOut,    ///< a zone the cables must not enter (e.g. a moving actuator's envelope)
};

/// "structure" | "keep_out".
const char* role_name(PartRole r);

/// One part: a mesh in world coordinates with its role and the extra clearance it asks for.
struct Part {
  std::string name;        ///< unique within the scene
  Mesh mesh;               ///< exact triangles, world frame, scene units
  PartRole role = PartRole::Structure;
  double clearance = 0.0;  ///< extra clearance to this part, added to the routing clearance
  bool closed = false;     ///< true if the mesh is watertight: only then does it have an inside
  std::string source_file;  ///< file it came from
  std::string source_name;  ///< product / solid name inside that file (STEP), if any
  int source_faces = 0;     ///< B-rep faces it was tessellated from (STEP/IGES), else 0
  /// CAD parts: the linear deflection its mesh was tessellated at (scene units), so the
  /// largest distance between the mesh and the B-rep surface; 0 for meshes and scans.
  double deflection = 0.0;
  /// CAD parts: which leaf product of its file it is (read_cad_file order; −1: the file's
  /// compound as one part), and the scene entry's transform (file frame → world), so that
  /// it can be tessellated again (tessellation by need).
  int source_leaf = -1;
  Eigen::Affine3d source_transform = Eigen::Affine3d::Identity();
  /// Scanned parts (OctoMap tree or point cloud): voxel edge after the transform, scene
  /// units; the mesh is the union of occupied voxels. 0 for meshed parts.
  double voxel_edge = 0.0;
  bool unknown_occupied = false;  ///< scanned parts: unobserved voxels within the map's bounds count as occupied
  /// How the part moves (its mesh is the rest pose); nullopt for a fixed part.
  std::optional<Motion> motion;
};

/// Certified bound of a scanned part: half its voxel diagonal (scene units), 0 for meshes.
/// The voxel union lies within it of the occupied voxel centres.
inline double voxel_accuracy(const Part& p) { return 0.5 * std::sqrt(3.0) * p.voxel_edge; }

}  // namespace loom
