#pragma once
/// Supports of a routed harness (DESIGN §4–§5): clamps, the structure each is fixed to, and
/// the stretches of cable longer than the clamp spacing between two supports. A cable's
/// supports are its two ports (the connector holds it) and the clamps on its segments whose
/// bundle comes within `clamp_reach` of a structure part (keep-out zones hold nothing).
/// World frame, scene units; s is arc length from the cable's first port, summed over the
/// segment curves of its chain as the rest of the audit counts it.

#include "core/centerline.hpp"
#include "core/harness.hpp"
#include "core/part.hpp"
#include "index/obstacle_index.hpp"

#include <string>
#include <vector>

namespace loom {

/// True if a clamp may be fixed to the part: structure that does not move. Keep-out zones
/// and moving parts (a clamp there would ride the mechanism and drop or chafe the bundle)
/// hold nothing.
bool holds_clamps(const Part& p);

/// Nearest point of a part that holds clamps (holds_clamps) within `max_radius` of p, exact
/// to the index's accuracy; found() == false if none.
ClosestHit nearest_structure(const ObstacleIndex& index, const std::vector<Part>& parts, const Vec3& p,
                             double max_radius);

/// The point of a curve nearest to p: its arc length from the start and the distance.
struct CurveProjection {
  double s = 0.0;         ///< arc length from the curve's start, scene units
  double distance = 0.0;  ///< |C(s) − p|, scene units
};

/// Projects p onto `curve`: dense samples (at most `step` apart, 16..4096 of them), then a
/// golden-section search between the neighbours of the nearest one.
CurveProjection project_on_curve(const Centerline& curve, const Vec3& p, double step);

/// One clamp as the audit sees it (report.json "clamps").
struct ClampLoad {
  std::string id;
  Vec3 point = Vec3::Zero();   ///< where it holds the bundle
  int segment = -1;            ///< harness segment it holds (−1: none within its bundle radius)
  int part = -1;               ///< structure part within reach it is fixed to (−1: none)
  double distance = 0.0;       ///< from the centreline point to that part's surface (when part ≥ 0)
  double bundle_diameter = 0.0;  ///< diameter of the bundle it holds
  bool placed = false;         ///< placed by the router (else given by the harness file)
  double segment_s = 0.0;      ///< arc length along its segment's curve (from → to) where it holds it
  /// True when it supports the cable: it holds a segment and structure is within reach.
  bool supports() const { return segment >= 0 && part >= 0; }
};

/// A stretch of one cable longer than the clamp spacing without a support.
struct UnsupportedSpan {
  int cable = -1;      ///< index into Harness::cables
  double from_s = 0.0;  ///< arc length of the support before it (0: the first port)
  double to_s = 0.0;    ///< arc length of the support after it (the length: the second port)
  double spacing = 0.0;  ///< the clamp spacing it exceeds
  Vec3 point = Vec3::Zero();  ///< centreline point in the middle of the stretch
};

/// What the supports audit found.
struct SupportAudit {
  std::vector<ClampLoad> clamps;        ///< one per Harness::clamps entry, in file order
  std::vector<UnsupportedSpan> spans;   ///< by cable, then from_s
  std::vector<std::string> notes;       ///< clamps that hold no segment
};

/// Measures every clamp of `h` (its segment: the one given, else the nearest centreline;
/// its part: nearest_structure within clamp_reach + bundle radius) and, when `check_spans`,
/// every routed cable's unsupported stretches longer than `clamp_spacing`. Cables with an
/// unrouted segment are skipped (the audit reports them unrouted).
SupportAudit audit_supports(const Harness& h, const std::vector<Part>& parts, const ObstacleIndex& index,
                            double clamp_spacing, double clamp_reach, bool check_spans);

/// The stretches of every routed cable of `h` longer than `clamp_spacing` between two of
/// its supports (its ports and the clamps of `clamps` that support it), by cable, then
/// from_s: the part of audit_supports that needs no structure, for clamps measured
/// elsewhere (a sharded audit merges each clamp's nearest part first).
std::vector<UnsupportedSpan> unsupported_spans(const Harness& h, const std::vector<ClampLoad>& clamps,
                                               double clamp_spacing);

}  // namespace loom
