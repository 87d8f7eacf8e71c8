#pragma once
/// Centerline of a scanned cable (seed: cable-scan-centerline-and-sphere-sweep §3; DESIGN §6).
///
/// Two methods:
///  - Axis (the paper): split the cloud into slabs along the axis of its largest extent,
///    fit each slab's centre line by minimising the active-contour energy (eq. 1–3: squared
///    distance of the points to the line against the nominal radius, normalised by m·r²,
///    plus a smoothness term on the directions of neighbouring blocks) with Gauss–Newton /
///    Levenberg–Marquardt, take the slab midpoints as key points, interpolate a cubic.
///    Fails when the cable doubles back along the blocking axis (a slab then holds two
///    passes), on curves that are not monotone along that axis, and on outliers.
///  - Graph (improved): contract the cloud onto the cable axis (mean shift on a k-d tree),
///    order the contracted nodes by the longest path of their minimum spanning tree (a
///    principal curve that follows the cable, bridges gaps and ignores outlier specks),
///    block the points by arc length along that curve, and fit every block robustly
///    (IRLS: Huber then Tukey weights) with a curved axis (a parabola, so bends do not bias
///    the centre). The diameter is estimated when not given.
/// All coordinates are in the cloud's frame and units.

#include "core/centerline.hpp"
#include "core/geometry.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace loom {

/// Which centerline extraction to run.
enum class ScanMethod {
  Axis,   ///< the paper's: slabs along the largest extent, plain least squares, straight blocks
  Graph,  ///< blocks along the cable itself (MST principal curve), robust curved-block fits
};

/// Expected outcomes of an extraction.
enum class ScanStatus {
  Ok,            ///< a centerline was recovered
  TooFewPoints,  ///< fewer points than one block fit needs, or fewer than two usable blocks
  NotATube,      ///< the block fits do not agree with a tube (diameter estimate failed, fits diverged)
};

/// Name for reports: "ok", "too-few-points", "not-a-tube".
const char* to_string(ScanStatus s);
/// Name for reports: "axis", "graph".
const char* to_string(ScanMethod m);

/// What to extract and how.
struct ScanOptions {
  std::optional<double> diameter;  ///< nominal cable diameter; absent = estimate it
  ScanMethod method = ScanMethod::Graph;
  /// Block length along the cable (Graph) or slab width (Axis); 0 = derived: two diameters,
  /// lengthened until a block holds about `target_block_points` points.
  double block_length = 0.0;
  std::size_t target_block_points = 60;
  /// Weight of the paper's smoothness term (E_ext: alignment of neighbouring blocks'
  /// directions) relative to the normalised data term.
  double smoothness = 0.05;
  std::uint64_t seed = 1;  ///< random sampling of the diameter estimate (deterministic)
};

/// One block's fit.
struct ScanBlock {
  Vec3 center = Vec3::Zero();     ///< key point: fitted axis at the block's middle
  Vec3 direction = Vec3::UnitX(); ///< unit axis direction, along increasing s
  double radius = 0.0;            ///< fitted (free) radius, or the nominal one
  double s_begin = 0.0, s_end = 0.0;  ///< extent along the ordering (arc length or axis coordinate)
  std::size_t points = 0;         ///< points assigned to the block
  std::size_t inliers = 0;        ///< points with non-zero robust weight
  double rms = 0.0;               ///< RMS of |distance to axis − radius| over inliers
};

/// Wall-clock time per stage, milliseconds.
struct ScanTiming {
  double diameter_ms = 0.0;  ///< coarse diameter estimate (0 when given)
  double ordering_ms = 0.0;  ///< k-d tree, contraction, spanning tree, projection (Graph) / slabs (Axis)
  double fitting_ms = 0.0;   ///< block fits
  double spline_ms = 0.0;    ///< interpolation
  double total_ms = 0.0;
};

/// What extract_centerline found.
struct ScanResult {
  ScanStatus status = ScanStatus::TooFewPoints;
  std::string message;        ///< why, when status != Ok
  ScanMethod method = ScanMethod::Graph;
  double diameter = 0.0;      ///< the nominal one, or the estimate
  bool diameter_estimated = false;
  double diameter_spread = 0.0;  ///< robust spread (1.4826·MAD) of the per-block diameters (0 if given)
  Centerline centerline;      ///< cubic through the key points (empty unless Ok)
  std::vector<Vec3> key_points;  ///< block centres in order along the cable, plus the two ends
  std::vector<ScanBlock> blocks;
  double residual_rms = 0.0;  ///< RMS over inliers of |distance to the fitted block axis − r|
  double residual_max = 0.0;  ///< max of the same
  std::size_t points = 0;     ///< points given
  std::size_t inliers = 0;    ///< points used by the final fits
  std::size_t outliers = 0;   ///< points rejected (far from the cable or zero robust weight)
  int gaps = 0;               ///< stretches along the cable without points longer than a block
  double largest_gap = 0.0;   ///< longest such stretch (length units)
  ScanTiming timing;
};

/// Extracts the centerline of a single scanned cable. Never throws for a bad cloud: an
/// unusable one gives status != Ok with a message. Throws std::invalid_argument for a
/// non-positive or non-finite nominal diameter or block length.
ScanResult extract_centerline(const std::vector<Vec3>& cloud, const ScanOptions& opt = {});

/// Coarse diameter of a tube-like cloud: circle fits to cross-sections of neighbourhoods at
/// a self-consistent scale (neighbourhood radius ≈ 2.5 diameters). nullopt if no
/// neighbourhood gives a consistent circle. Deterministic for a given seed.
std::optional<double> estimate_tube_diameter(const std::vector<Vec3>& cloud, std::uint64_t seed = 1);

}  // namespace loom
