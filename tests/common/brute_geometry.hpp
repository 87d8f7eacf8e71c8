#pragma once
// Test-only geometry oracles, written independently of loom's own kernels
// (index/triangle_distance): the tests compare loom against these.

#include "core/geometry.hpp"
#include "core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace loom::test_oracle {

/// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection §5.1.5).
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double den = va + vb + vc;
  if (!(std::abs(den) > 0)) {  // zero-area triangle: nearest of its three edges
    Vec3 best = a;
    for (auto [s, e] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      const Vec3 d = e - s;
      const double l2 = d.squaredNorm();
      const double t = l2 > 0 ? std::clamp((p - s).dot(d) / l2, 0.0, 1.0) : 0.0;
      const Vec3 q = s + t * d;
      if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    }
    return best;
  }
  const double v = vb / den, w = vc / den;
  return a + ab * v + ac * w;
}

/// Exact distance from p to triangle abc (scene units).
inline double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return (closest_on_triangle(p, a, b, c) - p).norm();
}

/// Unsigned distance from p to the surface of m (every triangle; scene units).
inline double mesh_distance(const Mesh& m, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    best = std::min(best, (closest_on_triangle(p, c[0], c[1], c[2]) - p).squaredNorm());
  }
  return std::sqrt(best);
}

/// Generalized winding number of m about p (van Oosterom–Strackee solid angles / 4π): ≈1
/// inside a closed outward mesh, ≈0 outside.
inline double mesh_winding_number(const Mesh& m, const Vec3& p) {
  double sum = 0.0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    const Vec3 a = c[0] - p, b = c[1] - p, d = c[2] - p;
    const double la = a.norm(), lb = b.norm(), ld = d.norm();
    const double num = a.dot(b.cross(d));
    const double den = la * lb * ld + a.dot(b) * ld + b.dot(d) * la + d.dot(a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * M_PI);
}

}  // namespace loom::test_oracle
