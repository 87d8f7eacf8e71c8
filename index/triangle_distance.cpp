#include "index/triangle_distance.hpp"

#include <algorithm>
#include <cmath>

namespace loom {

namespace {

/// Relative shrink of the plane lower bound: far above the rounding of its few products,
/// far below any distance difference a caller decides on.
constexpr double kPlaneBoundShrinkRel = 1e-9;
/// Relative threshold below which a triangle's squared area (|n|²) counts as zero compared
/// with the fourth power of its longest edge: such a triangle is treated as its edges.
constexpr double kDegenerateArea2Rel = 1e-24;

/// Closest point on segment ab to p, squared distance.
TrianglePointResult closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  TrianglePointResult r;
  r.point = a + t * ab;
  r.dist2 = (p - r.point).squaredNorm();
  return r;
}

bool is_degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double e2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return !(n.squaredNorm() > kDegenerateArea2Rel * e2 * e2);
}

}  // namespace

TrianglePointResult closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                              const Vec3& c) {
  return closest_point_on_triangle(p, a, b, c, is_degenerate(a, b, c));
}

TrianglePointResult closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                              const Vec3& c, bool degenerate) {
  if (degenerate) {
    TrianglePointResult best = closest_point_on_segment(p, a, b);
    for (const auto& r : {closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)})
      if (r.dist2 < best.dist2) best = r;
    return best;
  }
  // Region classification by barycentric tests (Ericson, Real-Time Collision Detection §5.1.5).
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  TrianglePointResult r;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    r.point = a;
  } else {
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    const double vc = d1 * d4 - d3 * d2;
    const double vb = d5 * d2 - d1 * d6;
    const double va = d3 * d6 - d5 * d4;
    if (d3 >= 0.0 && d4 <= d3) {
      r.point = b;
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
      r.point = a + (d1 / (d1 - d3)) * ab;
    } else if (d6 >= 0.0 && d5 <= d6) {
      r.point = c;
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
      r.point = a + (d2 / (d2 - d6)) * ac;
    } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
      r.point = b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    } else {
      const double denom = 1.0 / (va + vb + vc);
      r.point = a + ab * (vb * denom) + ac * (vc * denom);
    }
  }
  r.dist2 = (p - r.point).squaredNorm();
  if (!std::isfinite(r.dist2)) {  // rounding pathologies: fall back to the edges
    TrianglePointResult best = closest_point_on_segment(p, a, b);
    for (const auto& e : {closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)})
      if (e.dist2 < best.dist2) best = e;
    return best;
  }
  return r;
}

SegmentSegmentResult closest_segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                             const Vec3& q1) {
  // Ericson §5.1.9, with the degenerate (point) cases handled explicitly.
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0.0 && e <= 0.0) {
    s = t = 0.0;
  } else if (a <= 0.0) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0.0) {
      t = 0.0;
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      if (denom > 0.0)
        s = std::clamp((b * f - c * e) / denom, 0.0, 1.0);
      else
        s = 0.0;  // parallel: any s works, the t clamp below finds the distance
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  SegmentSegmentResult out;
  out.s = s;
  out.t = t;
  out.p = p0 + s * d1;
  out.q = q0 + t * d2;
  out.dist2 = (out.p - out.q).squaredNorm();
  return out;
}

SegmentTriangleResult closest_segment_triangle(const Vec3& a, const Vec3& b, const Vec3& t0,
                                               const Vec3& t1, const Vec3& t2) {
  return closest_segment_triangle(a, b, t0, t1, t2, is_degenerate(t0, t1, t2));
}

SegmentTriangleResult closest_segment_triangle(const Vec3& a, const Vec3& b, const Vec3& t0,
                                               const Vec3& t1, const Vec3& t2, bool degenerate) {
  SegmentTriangleResult best;
  best.dist2 = std::numeric_limits<double>::infinity();
  if (!degenerate) {
    const Vec3 n = (t1 - t0).cross(t2 - t0);  // the same expression is_degenerate() tests
    // Proper crossing of the triangle's plane inside the triangle: distance 0.
    const double da = n.dot(a - t0), db = n.dot(b - t0);
    if ((da <= 0.0 && db >= 0.0) || (da >= 0.0 && db <= 0.0)) {
      if (da != db) {
        const double s = da / (da - db);
        const Vec3 x = a + s * (b - a);
        // Inside test by the signs of the sub-triangle normals against n.
        const bool in = n.dot((t1 - t0).cross(x - t0)) >= 0.0 &&
                        n.dot((t2 - t1).cross(x - t1)) >= 0.0 &&
                        n.dot((t0 - t2).cross(x - t2)) >= 0.0;
        if (in) {
          best.s = s;
          best.segment_point = x;
          best.triangle_point = x;
          best.dist2 = 0.0;
          return best;
        }
      }
    }
  }
  // Otherwise the closest pair involves a segment endpoint or a triangle edge.
  for (int k = 0; k < 2; ++k) {
    const Vec3& p = k == 0 ? a : b;
    const TrianglePointResult r = closest_point_on_triangle(p, t0, t1, t2, degenerate);
    if (r.dist2 < best.dist2) {
      best.s = k;
      best.segment_point = p;
      best.triangle_point = r.point;
      best.dist2 = r.dist2;
    }
  }
  const Vec3* corners[3] = {&t0, &t1, &t2};
  for (int k = 0; k < 3; ++k) {
    const SegmentSegmentResult r = closest_segment_segment(a, b, *corners[k], *corners[(k + 1) % 3]);
    if (r.dist2 < best.dist2) {
      best.s = r.s;
      best.segment_point = r.p;
      best.triangle_point = r.q;
      best.dist2 = r.dist2;
    }
  }
  return best;
}

RayTriangleResult intersect_ray_triangle(const Vec3& origin, const Vec3& dir, const Vec3& t0,
                                         const Vec3& t1, const Vec3& t2) {
  RayTriangleResult r;
  const Vec3 e1 = t1 - t0, e2 = t2 - t0;
  const Vec3 pv = dir.cross(e2);
  const double det = e1.dot(pv);
  const double scale = e1.norm() * e2.norm() * dir.norm();
  if (!(std::abs(det) > 1e-14 * scale)) return r;  // parallel or degenerate
  const double inv = 1.0 / det;
  const Vec3 tv = origin - t0;
  const double u = tv.dot(pv) * inv;
  if (u < 0.0 || u > 1.0) return r;
  const Vec3 qv = tv.cross(e1);
  const double v = dir.dot(qv) * inv;
  if (v < 0.0 || u + v > 1.0) return r;
  const double t = e2.dot(qv) * inv;
  if (t < 0.0) return r;
  r.hit = true;
  r.t = t;
  r.u = u;
  r.v = v;
  return r;
}

double triangle_solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 x = a - p, y = b - p, z = c - p;
  const double lx = x.norm(), ly = y.norm(), lz = z.norm();
  const double num = x.dot(y.cross(z));
  const double den = lx * ly * lz + x.dot(y) * lz + x.dot(z) * ly + y.dot(z) * lx;
  if (num == 0.0 && den == 0.0) return 0.0;
  return 2.0 * std::atan2(num, den);
}

bool triangle_is_degenerate(const Vec3& a, const Vec3& b, const Vec3& c) { return is_degenerate(a, b, c); }

double segment_box_dist2_lower(const Vec3& a, const Vec3& b, const Vec3& lo, const Vec3& hi) {
  // Two bounds, the larger taken: the gap between the segment's own box and the box (tight
  // when the segment runs along a face), and the midpoint sphere's (tight for a segment
  // pointing at the box).
  const double gap2 = (lo - a.cwiseMax(b)).cwiseMax(a.cwiseMin(b) - hi).cwiseMax(Vec3::Zero()).squaredNorm();
  const Vec3 m = 0.5 * (a + b);
  const double half = 0.5 * (b - a).norm();
  const double d = std::sqrt(point_box_dist2(m, lo, hi)) - half;
  return d > 0.0 ? std::max(gap2, d * d) : gap2;
}

double segment_triangle_dist2_lower(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                    const Vec3& t2) {
  return segment_triangle_dist2_lower(a, b, t0, t1, t2, is_degenerate(t0, t1, t2));
}

double segment_triangle_dist2_lower(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                    const Vec3& t2, bool degenerate) {
  // The same degeneracy rule as the kernels: a sliver's rounded normal is no plane.
  if (degenerate) return 0.0;
  const Vec3 n = (t1 - t0).cross(t2 - t0);
  const double n2 = n.squaredNorm();
  const double da = n.dot(a - t0), db = n.dot(b - t0);
  // Ends on both sides (or on the plane): the segment meets the plane, no bound.
  if ((da <= 0.0 && db >= 0.0) || (da >= 0.0 && db <= 0.0)) return 0.0;
  const double m = std::min(std::abs(da), std::abs(db));
  const double d2 = m * m / n2;
  return std::isfinite(d2) ? d2 * (1.0 - kPlaneBoundShrinkRel) : 0.0;
}

}  // namespace loom
