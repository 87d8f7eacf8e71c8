// Clamp placement along routed segments (DESIGN §3 Supports).
#include "routing/route/clamp_placement.hpp"

#include "core/harness_topology.hpp"
#include "routing/audit/supports.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace loom {

namespace {

/// Most points looked at along one segment (a longer segment is walked in longer steps).
constexpr double kMaxSamplesPerSegment = 1e6;

/// A centreline point and the structure within reach of its bundle (part −1: none).
struct ReachSample {
  double s = 0.0;
  Vec3 point = Vec3::Zero();
  int part = -1;
};

}  // namespace

ClampPlacement place_clamps(const Harness& h, const std::vector<Part>& parts, const ObstacleIndex& index,
                            double clamp_spacing, double clamp_reach) {
  ClampPlacement out;
  const HarnessTopology topo(h);
  SegmentCurves curves(topo);
  std::set<std::string> ids;
  for (const Clamp& c : h.clamps) ids.insert(c.id);
  int next_id = 1;
  for (std::size_t si = 0; si < h.segments.size(); ++si) {
    const int s = static_cast<int>(si);
    if (topo.segment_cables(s).empty()) continue;
    const auto& curve = curves.segment(s, false);
    if (!curve) continue;
    const double len = curve->length();
    const double diameter = topo.segment_diameter(s);
    const double reach = clamp_reach + 0.5 * diameter;
    const double step = std::max(std::min(clamp_spacing / 20.0, clamp_reach), len / kMaxSamplesPerSegment);
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    std::vector<ReachSample> samples(static_cast<std::size_t>(n) + 1);
    for (int i = 0; i <= n; ++i) {
      ReachSample& r = samples[static_cast<std::size_t>(i)];
      r.s = len * i / n;
      r.point = curve->position(curve->parameter_at_length(r.s));
      const ClosestHit hit = nearest_structure(index, parts, r.point, reach);
      r.part = hit.found() ? hit.part : -1;
    }
    // Share within reach: each stretch between samples counts by its ends (half each).
    out.cable_length += len;
    for (int i = 0; i < n; ++i)
      out.length_within_reach += 0.5 * (len / n) *
                                 ((samples[static_cast<std::size_t>(i)].part >= 0) + (samples[static_cast<std::size_t>(i) + 1].part >= 0));
    const Segment& seg = h.segments[si];
    double last = h.find_port(seg.from) >= 0 ? 0.0 : -0.5 * clamp_spacing;
    const double end_slack = h.find_port(seg.to) >= 0 ? clamp_spacing : 0.5 * clamp_spacing;
    std::size_t i = 0;  // first sample not yet passed
    while (len - last > end_slack) {
      // The farthest sample within reach no more than the spacing on; else the nearest beyond.
      std::size_t pick = samples.size();
      for (std::size_t k = i; k < samples.size() && samples[k].s <= last + clamp_spacing; ++k)
        if (samples[k].s > last && samples[k].part >= 0) pick = k;
      if (pick == samples.size())
        for (std::size_t k = i; k < samples.size(); ++k)
          if (samples[k].s > last && samples[k].part >= 0) {
            pick = k;
            break;
          }
      if (pick == samples.size()) break;  // nothing ahead within reach: the audit says where
      Clamp c;
      do c.id = "clamp-" + std::to_string(next_id++);
      while (ids.count(c.id));
      ids.insert(c.id);
      c.position = samples[pick].point;
      c.segment = s;
      c.part = parts[static_cast<std::size_t>(samples[pick].part)].name;
      c.bundle_diameter = diameter;
      c.placed = true;
      out.clamps.push_back(c);
      last = samples[pick].s;
      i = pick + 1;
    }
  }
  return out;
}

}  // namespace loom
