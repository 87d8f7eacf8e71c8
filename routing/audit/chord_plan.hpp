#pragma once
/// Flattening a centerline into chords with a proven deviation bound: the polylines the
/// certified audit measures exactly (clash_check). Every point of the curve between two
/// consecutive vertices lies within `eps` of the chord joining them, and no chord is longer
/// than `hmax`. Frame and units are the curve's (world frame, scene units); u is the curve
/// parameter, s arc length.

#include "core/centerline.hpp"

#include <cstddef>
#include <vector>

namespace loom {

/// Polyline approximation of a stretch of a centerline.
struct Chords {
  std::vector<Vec3> p;     ///< vertices (on the curve)
  std::vector<double> s;   ///< arc length at each vertex
  /// Number of chords (vertices − 1, 0 when empty).
  std::size_t size() const { return p.empty() ? 0 : p.size() - 1; }
};

/// Chords the deviation bound alone asks of the span piece [a, b] of c (at least 1): on a
/// span of a degree ≤ 3 spline C'' is affine, so a chord over Δu deviates at most
/// Δu²/8 · max(|C''| at the ends), and Δu·sqrt(max|C''| / (8·eps)) chords suffice.
double deviation_chords(const Centerline& c, double a, double b, double eps);

/// Chords no longer than hmax that the span piece [a, b] of c needs when cut uniformly in u
/// (at least 1): (b − a) · max|C'| / hmax, max|C'| bounded by the hodograph's Bézier points
/// (degree ≤ 3). A chord is no longer than the arc it spans, and that arc no longer than
/// max|C'|·Δu; the span's length alone would not do where the speed varies along it.
double length_chords(const Centerline& c, double a, double b, double hmax);

/// How many chords flatten() makes over the whole curve (counted without making them: the
/// audit refuses a curve that wiggles on the scale of its tolerance before flattening it).
double planned_chords(const Centerline& c, double eps, double hmax, double short_len);

/// Appends to `out` the chords of c over [u0, u1], deviating at most eps from the curve and
/// no longer than hmax: each knot span is cut uniformly in u into the larger of
/// deviation_chords() and length_chords(), except that a run of consecutive spans each
/// shorter than `short_len` becomes one chord where the hull of their Bézier points lies
/// within eps of it (convex hull property, Centerline::hull_bounds) and their arc within
/// hmax. Arc lengths are exact at piece ends and shared out within a piece in proportion to
/// the chord lengths. A non-empty `out` is continued from its last vertex (which must be
/// the curve at u0).
void flatten(const Centerline& c, double u0, double u1, double eps, double hmax, double short_len, Chords& out);

}  // namespace loom
