#pragma once
/// Findings against scanned parts (OctoMap trees, point clouds). Such a part's geometry is
/// the union of its occupied voxels: the structure lies somewhere inside them, so the
/// clearance c to the voxels is a lower bound on the clearance to the structure, and the
/// structure's clearance is at most c + one voxel diagonal (twice the part's accuracy, half
/// a diagonal). A finding is therefore one of:
///  - "beyond-bound": closer than required by more than the bound (c + 2·accuracy < required):
///    the scanned structure violates the requirement wherever it lies in its voxels;
///  - "within-bound": closer than required to the voxels, but within the bound: the scan
///    cannot say whether the structure itself is clear.
/// A cable clear of the voxels by the requirement has no finding: it is clear of the scan.

#include "core/part.hpp"

#include <string>
#include <vector>

namespace loom {

/// A scanned part's voxel description (scene units).
struct ScannedPartBound {
  int part = -1;                  ///< index into the scene's parts
  double voxel_edge = 0.0;        ///< voxel edge after the part's transform
  double accuracy = 0.0;          ///< half the voxel diagonal
  bool unknown_occupied = false;  ///< unobserved voxels within the map's bounds count as occupied
};

/// The scanned parts of a scene, in part order.
std::vector<ScannedPartBound> scanned_part_bounds(const std::vector<Part>& parts);

/// The bound of part `part`, or nullptr when it is a meshed part.
const ScannedPartBound* find_scanned_part(const std::vector<ScannedPartBound>& bounds, int part);

/// "beyond-bound" or "within-bound" for a finding with clearance `clearance` to the voxels
/// against a requirement `required` (0 for a clash); a non-finite clearance is beyond.
const char* voxel_finding_name(double clearance, double required, double accuracy);

}  // namespace loom
