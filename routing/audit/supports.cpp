// Supports audit: clamps, their structure, and unsupported spans (DESIGN §5).
#include "routing/audit/supports.hpp"

#include "core/harness_topology.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace loom {

namespace {

/// Fewest and most samples project_on_curve takes before refining.
constexpr int kMinProjectionSamples = 16;
constexpr int kMaxProjectionSamples = 4096;
/// Golden-section steps of the refinement (the bracket shrinks by 0.618 per step).
constexpr int kGoldenSteps = 60;

}  // namespace

bool holds_clamps(const Part& p) { return p.role == PartRole::Structure && !p.motion; }

ClosestHit nearest_structure(const ObstacleIndex& index, const std::vector<Part>& parts, const Vec3& p,
                             double max_radius) {
  const ClosestHit any = index.closest(p, max_radius);
  if (!any.found() || holds_clamps(parts[static_cast<std::size_t>(any.part)])) return any;
  // The nearest surface holds nothing (a keep-out zone, a moving part): ask the others.
  ClosestHit best;
  for (std::size_t q = 0; q < parts.size(); ++q) {
    if (!holds_clamps(parts[q])) continue;
    if (const auto box = index.part_bounds(static_cast<int>(q)); box && !box->inflated(best.found() ? best.distance : max_radius).contains(p))
      continue;
    const ClosestHit h = index.closest_on_part(p, static_cast<int>(q), best.found() ? best.distance : max_radius);
    if (h.found() && (!best.found() || h.distance < best.distance)) best = h;
  }
  return best;
}

CurveProjection project_on_curve(const Centerline& curve, const Vec3& p, double step) {
  const double len = curve.length();
  const int n = std::clamp(step > 0.0 ? static_cast<int>(std::ceil(len / step)) : kMaxProjectionSamples,
                           kMinProjectionSamples, kMaxProjectionSamples);
  auto dist = [&](double u) { return (curve.position(u) - p).norm(); };
  int best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  std::vector<double> us(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i <= n; ++i) {
    us[static_cast<std::size_t>(i)] = curve.parameter_at_length(len * i / n);
    const double d = dist(us[static_cast<std::size_t>(i)]);
    if (d < best_d) best_d = d, best = i;
  }
  double a = us[static_cast<std::size_t>(std::max(best - 1, 0))], b = us[static_cast<std::size_t>(std::min(best + 1, n))];
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = dist(c), fd = dist(d);
  for (int k = 0; k < kGoldenSteps && b - a > 0.0; ++k) {
    if (fc < fd) b = d, d = c, fd = fc, c = b - g * (b - a), fc = dist(c);
    else a = c, c = d, fc = fd, d = a + g * (b - a), fd = dist(d);
  }
  double u = fc < fd ? c : d, du = std::min(fc, fd);
  // The sample itself may beat the bracket's interior (the nearest point at an end).
  if (best_d <= du) u = us[static_cast<std::size_t>(best)], du = best_d;
  return {std::clamp(curve.arc_length_at(u), 0.0, len), du};
}

SupportAudit audit_supports(const Harness& h, const std::vector<Part>& parts, const ObstacleIndex& index,
                            double clamp_spacing, double clamp_reach, bool check_spans) {
  SupportAudit out;
  const HarnessTopology topo(h);
  SegmentCurves curves(topo);
  for (std::size_t k = 0; k < h.clamps.size(); ++k) {
    const Clamp& c = h.clamps[k];
    ClampLoad load;
    load.id = c.id;
    load.point = c.position;
    load.placed = c.placed;
    // The segment it holds: the one given, else the nearest centreline; either way within the
    // clamp's reach of the bundle surface (a clip's point may sit on its base, not the axis).
    CurveProjection at{0.0, std::numeric_limits<double>::infinity()};
    int seg = -1;
    for (std::size_t s = 0; s < h.segments.size(); ++s) {
      if (c.segment >= 0 && static_cast<int>(s) != c.segment) continue;
      const auto& curve = curves.segment(static_cast<int>(s), false);
      if (!curve) continue;
      const CurveProjection pr = project_on_curve(*curve, c.position, 0.5 * topo.segment_diameter(static_cast<int>(s)));
      if (pr.distance < at.distance) at = pr, seg = static_cast<int>(s);
    }
    if (seg >= 0 && at.distance > 0.5 * topo.segment_diameter(seg) + clamp_reach) seg = -1;
    if (seg < 0) {
      out.notes.push_back("clamp '" + c.id + "' (line " + std::to_string(c.line) + ") holds no routed segment" +
                          (c.segment >= 0 ? " (its segment passes farther than its reach)" : "") + ": it supports nothing");
      out.clamps.push_back(load);
      continue;
    }
    load.segment = seg;
    load.bundle_diameter = topo.segment_diameter(seg);
    const auto& curve = *curves.segment(seg, false);
    const Vec3 held = curve.position(curve.parameter_at_length(at.s));
    const ClosestHit hit = nearest_structure(index, parts, held, clamp_reach + 0.5 * load.bundle_diameter);
    if (hit.found()) load.part = hit.part, load.distance = hit.distance;
    load.segment_s = at.s;
    out.clamps.push_back(load);
  }
  if (check_spans) out.spans = unsupported_spans(h, out.clamps, clamp_spacing);
  return out;
}

std::vector<UnsupportedSpan> unsupported_spans(const Harness& h, const std::vector<ClampLoad>& clamps,
                                               double clamp_spacing) {
  std::vector<UnsupportedSpan> out;
  const HarnessTopology topo(h);
  SegmentCurves curves(topo);
  for (std::size_t c = 0; c < h.cables.size(); ++c) {
    const auto& chain = topo.cable_chain(static_cast<int>(c));
    std::vector<double> supports{0.0};
    double s0 = 0.0;
    bool routed = true;
    for (const SegmentUse& u : chain) {
      const auto& curve = curves.segment(u.segment, false);
      if (!curve) {
        routed = false;
        break;
      }
      const double len = curve->length();
      for (const ClampLoad& k : clamps)
        if (k.supports() && k.segment == u.segment)
          supports.push_back(s0 + (u.reversed ? len - k.segment_s : k.segment_s));
      s0 += len;
    }
    if (!routed) continue;
    supports.push_back(s0);
    std::sort(supports.begin(), supports.end());
    for (std::size_t i = 0; i + 1 < supports.size(); ++i) {
      if (!(supports[i + 1] - supports[i] > clamp_spacing)) continue;
      UnsupportedSpan sp;
      sp.cable = static_cast<int>(c);
      sp.from_s = supports[i];
      sp.to_s = supports[i + 1];
      sp.spacing = clamp_spacing;
      // The middle of the stretch, on the segment that holds it.
      const double mid = 0.5 * (sp.from_s + sp.to_s);
      double t = 0.0;
      for (const SegmentUse& u : chain) {
        const auto& curve = *curves.segment(u.segment, false);
        const double len = curve.length();
        if (mid <= t + len || &u == &chain.back()) {
          const double local = std::clamp(u.reversed ? t + len - mid : mid - t, 0.0, len);
          sp.point = curve.position(curve.parameter_at_length(local));
          break;
        }
        t += len;
      }
      out.push_back(sp);
    }
  }
  return out;
}

}  // namespace loom
