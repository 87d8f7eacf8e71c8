// The cable-motion lines of the `audit` and `route` summaries.
#include "app/motion_summary.hpp"

#include <cstdio>

namespace loom {

std::size_t print_motion_clashes(const AuditReport& rep, std::size_t max_lines) {
  std::size_t shown = 0;
  for (const MotionClash& m : rep.motion.clashes) {
    if (shown++ >= max_lines) continue;
    std::printf("  motion %-12s part %-20s clearance %.4f %s at pose %.4g %s (s = %.2f)\n",
                rep.check_ids[static_cast<std::size_t>(m.cable)].c_str(),
                rep.part_names[static_cast<std::size_t>(m.part)].c_str(), m.clearance, rep.units.c_str(), m.pose,
                m.motion == MotionKind::Rotate ? "deg" : rep.units.c_str(), m.s);
  }
  if (shown > max_lines) std::printf("  ... %zu more cable-motion clashes in the report\n", shown - max_lines);
  return rep.motion.clashes.size();
}

}  // namespace loom
