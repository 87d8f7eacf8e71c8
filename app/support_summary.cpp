// The supports and segregation lines of the `audit` and `route` summaries.
#include "app/support_summary.hpp"

#include <cstdio>

namespace loom {

std::size_t print_support_findings(const AuditReport& rep, std::size_t max_lines) {
  std::size_t shown = 0;
  const char* u = rep.units.c_str();
  for (const UnsupportedSpan& sp : rep.supports.spans)
    if (shown++ < max_lines)
      std::printf("  unsupported-span %-12s s = %.1f .. %.1f: %.1f %s without a support (spacing %.4g)\n",
                  rep.cables[static_cast<std::size_t>(sp.cable)].id.c_str(), sp.from_s, sp.to_s, sp.to_s - sp.from_s,
                  u, sp.spacing);
  for (const SegregationFinding& f : rep.segregation) {
    if (shown++ >= max_lines) continue;
    const std::string& a = rep.check_ids[static_cast<std::size_t>(f.cable)];
    const std::string& b = rep.check_ids[static_cast<std::size_t>(f.other)];
    if (f.segment >= 0)
      std::printf("  segregation %-12s shares bundle segment %s with %s (separation %.4g %s)\n", a.c_str(),
                  rep.segment_names[static_cast<std::size_t>(f.segment)].c_str(), b.c_str(), f.required, u);
    else
      std::printf("  segregation %-12s %.4f < %.4g %s from %s at s = %.2f\n", a.c_str(), f.distance, f.required, u,
                  b.c_str(), f.s);
  }
  if (shown > max_lines) std::printf("  ... %zu more in the report\n", shown - max_lines);
  return rep.supports.spans.size() + rep.segregation.size();
}

}  // namespace loom
