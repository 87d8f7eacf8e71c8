#pragma once
/// Exact double-precision kernels on single triangles, shared by every ObstacleIndex
/// implementation and by the tests: closest point, segment distance, ray intersection and
/// solid angle (generalized winding number). All inputs and outputs are in the caller's
/// frame and units; nothing here allocates. Degenerate triangles (zero area, repeated
/// corners) are handled: they behave as the segment or point they collapse to.

#include "core/geometry.hpp"

#include <cstddef>

namespace loom {

/// Closest point on a triangle to a point.
struct TrianglePointResult {
  Vec3 point = Vec3::Zero();  ///< closest point on the triangle
  double dist2 = 0.0;         ///< squared distance from the query point to `point`
};

/// Closest point on triangle abc to p (exact up to double rounding).
TrianglePointResult closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                              const Vec3& c);

/// The same, with `degenerate` == triangle_is_degenerate(a, b, c) already known (an index
/// stores it per triangle): skips that test, identical result.
TrianglePointResult closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                              const Vec3& c, bool degenerate);

/// Closest points between two segments.
struct SegmentSegmentResult {
  double s = 0.0;  ///< parameter on the first segment, in [0,1]
  double t = 0.0;  ///< parameter on the second segment, in [0,1]
  Vec3 p = Vec3::Zero();  ///< point on the first segment
  Vec3 q = Vec3::Zero();  ///< point on the second segment
  double dist2 = 0.0;     ///< squared distance |p - q|²
};

/// Closest points between segments p0p1 and q0q1 (either may be a point).
SegmentSegmentResult closest_segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                             const Vec3& q1);

/// Closest points between a segment and a triangle.
struct SegmentTriangleResult {
  double s = 0.0;                   ///< parameter on the segment ab, in [0,1]
  Vec3 segment_point = Vec3::Zero();   ///< a + s (b - a)
  Vec3 triangle_point = Vec3::Zero();  ///< closest point on the triangle
  double dist2 = 0.0;                  ///< squared distance between the two points
};

/// Closest points between segment ab and triangle t0t1t2; distance 0 when they intersect.
SegmentTriangleResult closest_segment_triangle(const Vec3& a, const Vec3& b, const Vec3& t0,
                                               const Vec3& t1, const Vec3& t2);

/// The same, with `degenerate` == triangle_is_degenerate(t0, t1, t2) already known: skips
/// that test, identical result.
SegmentTriangleResult closest_segment_triangle(const Vec3& a, const Vec3& b, const Vec3& t0,
                                               const Vec3& t1, const Vec3& t2, bool degenerate);

/// Result of a ray–triangle intersection in double precision.
struct RayTriangleResult {
  bool hit = false;
  double t = 0.0;      ///< ray parameter: hit point = origin + t·dir
  double u = 0.0;      ///< barycentric weight of t1
  double v = 0.0;      ///< barycentric weight of t2 (weight of t0 is 1 - u - v)
};

/// Möller–Trumbore intersection of origin + t·dir (t ≥ 0) with triangle t0t1t2, both faces,
/// closed triangle (barycentrics ≥ 0). Parallel or degenerate triangles never hit.
RayTriangleResult intersect_ray_triangle(const Vec3& origin, const Vec3& dir, const Vec3& t0,
                                         const Vec3& t1, const Vec3& t2);

/// Signed solid angle (steradians, in [-2π, 2π]) subtended at p by the oriented triangle abc
/// (Van Oosterom–Strackee). Summed over a closed outward mesh and divided by 4π it gives
/// the winding number: 1 inside, 0 outside.
double triangle_solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Generalized winding number at p of the triangles t = 0 .. n−1, whose corners
/// `corners(t)` returns (an indexable of three Vec3): the sum of their solid angles over
/// 4π — 1 inside a closed outward mesh, 0 outside, 1/2 on its surface, −1 inside one
/// oriented inwards.
template <class Corners>
double triangles_winding_number(const Vec3& p, std::size_t n, Corners&& corners) {
  constexpr double kFourPi = 4.0 * 3.14159265358979323846;
  double sum = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    const auto c = corners(t);
    sum += triangle_solid_angle(p, c[0], c[1], c[2]);
  }
  return sum / kFourPi;
}

/// True if triangle abc has (numerically) zero area: |(b−a)×(c−a)|² ≤ 1e-24·(longest edge)⁴.
/// Such triangles are treated as the segments they collapse to.
bool triangle_is_degenerate(const Vec3& a, const Vec3& b, const Vec3& c);

/// Squared distance from p to the box [lo, hi] (0 inside). Inline: the indices call it
/// once per candidate triangle.
inline double point_box_dist2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 d = (lo - p).cwiseMax(Vec3::Zero()).cwiseMax(p - hi);
  return d.squaredNorm();
}

/// Lower bound on the squared distance from segment ab to the box [lo, hi] (exact when
/// the segment is a point): the larger of the gap between the segment's box and [lo, hi]
/// and the distance from the box to the sphere around the segment.
double segment_box_dist2_lower(const Vec3& a, const Vec3& b, const Vec3& lo, const Vec3& hi);

/// Lower bound on the squared distance from segment ab to triangle t0t1t2: the squared
/// distance to the triangle's plane when both ends lie on the same side of it, shrunk by a
/// relative 1e-9 so that rounding never lifts it above the exact kernel's value; 0 when the
/// segment meets the plane or the triangle is degenerate (has no plane). Costs a cross and
/// two dot products: an index tests it before closest_segment_triangle (five sub-kernels)
/// to skip triangles whose box comes near the segment but whose plane does not.
double segment_triangle_dist2_lower(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                    const Vec3& t2);

/// The same, with `degenerate` == triangle_is_degenerate(t0, t1, t2) already known (an index
/// stores it per triangle): skips that test, identical result.
double segment_triangle_dist2_lower(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                    const Vec3& t2, bool degenerate);

}  // namespace loom
