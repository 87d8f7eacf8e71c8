#include "routing/audit/voxel_findings.hpp"

#include <cmath>

namespace loom {

std::vector<ScannedPartBound> scanned_part_bounds(const std::vector<Part>& parts) {
  std::vector<ScannedPartBound> out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!(parts[i].voxel_edge > 0.0)) continue;
    out.push_back({static_cast<int>(i), parts[i].voxel_edge, voxel_accuracy(parts[i]), parts[i].unknown_occupied});
  }
  return out;
}

const ScannedPartBound* find_scanned_part(const std::vector<ScannedPartBound>& bounds, int part) {
  for (const auto& b : bounds)
    if (b.part == part) return &b;
  return nullptr;
}

const char* voxel_finding_name(double clearance, double required, double accuracy) {
  // The structure lies within one voxel diagonal (2·accuracy) of the nearest voxel point.
  if (!std::isfinite(clearance) || clearance + 2.0 * accuracy < required) return "beyond-bound";
  return "within-bound";
}

}  // namespace loom
