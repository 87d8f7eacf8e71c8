// Exact triangle kernels against independent formulations (projection + edges, sampled
// minimisation, closed-form solid angles) with fixed seeds, degenerate triangles and
// rapidcheck invariants.
#include "index/triangle_distance.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace loom;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Independent oracle: projection onto the plane if it falls inside (barycentric solve),
// otherwise the nearest edge.
double oracle_point_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  double best = std::min({point_segment_dist2(p, a, b), point_segment_dist2(p, b, c), point_segment_dist2(p, c, a)});
  if (n.squaredNorm() > 0) {
    Eigen::Matrix<double, 3, 2> m;
    m.col(0) = b - a;
    m.col(1) = c - a;
    const Eigen::Vector2d uv = m.colPivHouseholderQr().solve(p - a);
    if (uv.x() >= 0 && uv.y() >= 0 && uv.x() + uv.y() <= 1) best = std::min(best, (p - (a + m * uv)).squaredNorm());
  }
  return best;
}

Vec3 rnd(std::mt19937_64& rng, double s) {
  std::uniform_real_distribution<double> u(-s, s);
  return Vec3(u(rng), u(rng), u(rng));
}

}  // namespace

TEST(TriangleDistance, PointTriangleMatchesOracle) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 a = rnd(rng, 10), b = rnd(rng, 10), c = rnd(rng, 10), p = rnd(rng, 20);
    const TrianglePointResult r = closest_point_on_triangle(p, a, b, c);
    const double o = oracle_point_triangle(p, a, b, c);
    ASSERT_NEAR(r.dist2, o, 1e-9 * std::max(1.0, o)) << i;
    ASSERT_NEAR((p - r.point).squaredNorm(), r.dist2, 1e-9 * std::max(1.0, o));
    // The point lies on the triangle: its distance to the triangle is ~0.
    ASSERT_LE(oracle_point_triangle(r.point, a, b, c), 1e-18 * 1e4);
  }
}

TEST(TriangleDistance, DegenerateTriangles) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(2, 0, 0), p(0.5, 1, 0);
  // Collinear: behaves as the segment from a to c.
  EXPECT_NEAR(closest_point_on_triangle(p, a, b, c).dist2, 1.0, 1e-15);
  EXPECT_NEAR(closest_point_on_triangle(Vec3(3, 0, 0), a, b, c).dist2, 1.0, 1e-15);
  // Repeated vertex.
  EXPECT_NEAR(closest_point_on_triangle(p, a, a, b).dist2, 1.0, 1e-15);
  // A point triangle.
  EXPECT_NEAR(closest_point_on_triangle(p, b, b, b).dist2, 1.25, 1e-15);
  // Nearly degenerate sliver stays finite and matches the oracle.
  const Vec3 s(1, 1e-13, 0);
  const auto r = closest_point_on_triangle(Vec3(0.3, 0.2, 0.7), a, c, s);
  EXPECT_TRUE(std::isfinite(r.dist2));
  EXPECT_NEAR(r.dist2, oracle_point_triangle(Vec3(0.3, 0.2, 0.7), a, c, s), 1e-12);
  // Segment against a degenerate triangle and ray against it.
  EXPECT_NEAR(closest_segment_triangle(Vec3(0.5, -1, 1), Vec3(0.5, 1, 1), a, b, c).dist2, 1.0, 1e-15);
  EXPECT_FALSE(intersect_ray_triangle(Vec3(0.5, 0, 1), Vec3(0, 0, -1), a, b, c).hit);
}

TEST(TriangleDistance, SegmentSegmentMatchesCandidates) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p0 = rnd(rng, 5), p1 = i % 10 == 0 ? p0 : rnd(rng, 5);
    const Vec3 q0 = rnd(rng, 5), q1 = i % 13 == 0 ? q0 + (p1 - p0) : rnd(rng, 5);  // includes parallel pairs
    const SegmentSegmentResult r = closest_segment_segment(p0, p1, q0, q1);
    // Oracle: endpoint-to-segment candidates plus the interior critical point.
    double o = std::min({point_segment_dist2(p0, q0, q1), point_segment_dist2(p1, q0, q1),
                         point_segment_dist2(q0, p0, p1), point_segment_dist2(q1, p0, p1)});
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, w = p0 - q0;
    const double a = d1.dot(d1), b = d1.dot(d2), c = d2.dot(d2), d = d1.dot(w), e = d2.dot(w);
    const double den = a * c - b * b;
    if (den > 1e-12 * a * c) {
      const double s = (b * e - c * d) / den, t = (a * e - b * d) / den;
      if (s >= 0 && s <= 1 && t >= 0 && t <= 1) o = std::min(o, (p0 + s * d1 - q0 - t * d2).squaredNorm());
    }
    ASSERT_NEAR(r.dist2, o, 1e-9 * std::max(1.0, o)) << i;
    ASSERT_NEAR((r.p - r.q).squaredNorm(), r.dist2, 1e-12 * std::max(1.0, o));
  }
}

TEST(TriangleDistance, SegmentTriangleMatchesSampling) {
  std::mt19937_64 rng(3);
  constexpr int kSamples = 2000;
  for (int i = 0; i < 400; ++i) {
    const Vec3 t0 = rnd(rng, 3), t1 = rnd(rng, 3), t2 = rnd(rng, 3);
    const Vec3 a = rnd(rng, 5), b = rnd(rng, 5);
    const SegmentTriangleResult r = closest_segment_triangle(a, b, t0, t1, t2);
    double sampled = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= kSamples; ++k)
      sampled = std::min(sampled, std::sqrt(oracle_point_triangle(a + (b - a) * (double(k) / kSamples), t0, t1, t2)));
    const double d = std::sqrt(r.dist2);
    // Exact distance ≤ sampled minimum, and ≥ it minus half a sample step (1-Lipschitz).
    ASSERT_LE(d, sampled + 1e-12) << i;
    ASSERT_GE(d, sampled - 0.5 * (b - a).norm() / kSamples - 1e-12) << i;
    ASSERT_NEAR((r.segment_point - r.triangle_point).norm(), d, 1e-12);
    ASSERT_NEAR((a + r.s * (b - a) - r.segment_point).norm(), 0.0, 1e-12);
  }
}

TEST(TriangleDistance, SegmentPiercingTriangleIsZero) {
  const Vec3 t0(0, 0, 0), t1(1, 0, 0), t2(0, 1, 0);
  const auto r = closest_segment_triangle(Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 3), t0, t1, t2);
  EXPECT_EQ(r.dist2, 0.0);
  EXPECT_NEAR(r.s, 0.25, 1e-15);
  EXPECT_NEAR((r.triangle_point - Vec3(0.2, 0.2, 0)).norm(), 0.0, 1e-15);
  // Coplanar segment crossing an edge.
  EXPECT_NEAR(closest_segment_triangle(Vec3(-1, 0.3, 0), Vec3(2, 0.3, 0), t0, t1, t2).dist2, 0.0, 1e-30);
  // Parallel segment above the face.
  EXPECT_NEAR(closest_segment_triangle(Vec3(0.1, 0.1, 2), Vec3(0.3, 0.2, 2), t0, t1, t2).dist2, 4.0, 1e-14);
}

TEST(TriangleDistance, RayTriangle) {
  std::mt19937_64 rng(4);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 t0 = rnd(rng, 3), t1 = rnd(rng, 3), t2 = rnd(rng, 3), o = rnd(rng, 6);
    const Vec3 d = rnd(rng, 1);
    const RayTriangleResult r = intersect_ray_triangle(o, d, t0, t1, t2);
    // Oracle: plane intersection then the point-triangle distance of the hit point.
    const Vec3 n = (t1 - t0).cross(t2 - t0);
    const double den = n.dot(d);
    if (std::abs(den) < 1e-9 * n.norm() * d.norm()) continue;
    const double t = n.dot(t0 - o) / den;
    const bool in_plane_hit = t >= 0 && oracle_point_triangle(o + t * d, t0, t1, t2) < 1e-20;
    const bool near_boundary = std::min({r.u, r.v, 1 - r.u - r.v}) < 1e-9;
    if (!near_boundary) {
      ASSERT_EQ(r.hit, in_plane_hit) << i;
    }
    if (r.hit) {
      ++hits;
      ASSERT_NEAR(r.t, t, 1e-9 * std::max(1.0, t));
    }
  }
  EXPECT_GT(hits, 100);
}

TEST(TriangleDistance, SolidAngle) {
  // The octant triangle subtends 1/8 of the sphere from the origin.
  EXPECT_NEAR(triangle_solid_angle(Vec3::Zero(), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)), kPi / 2, 1e-14);
  EXPECT_NEAR(triangle_solid_angle(Vec3::Zero(), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0)), -kPi / 2, 1e-14);
  // A tetrahedron: 4π inside, 0 outside (outward orientation).
  const Vec3 v[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  auto total = [&](const Vec3& p) {
    double s = 0;
    for (const auto& t : f) s += triangle_solid_angle(p, v[t[0]], v[t[1]], v[t[2]]);
    return s;
  };
  EXPECT_NEAR(total(Vec3(0.1, 0.1, 0.1)), 4 * kPi, 1e-12);
  EXPECT_NEAR(total(Vec3(1, 1, 1)), 0.0, 1e-12);
  EXPECT_NEAR(total(Vec3(-0.001, 0.2, 0.2)), 0.0, 1e-9);
  EXPECT_EQ(triangle_solid_angle(Vec3::Zero(), Vec3::Zero(), Vec3(1, 0, 0), Vec3(0, 1, 0)), 0.0);
}

TEST(TriangleDistance, BoxDistances) {
  EXPECT_EQ(point_box_dist2(Vec3(0.5, 0.5, 0.5), Vec3::Zero(), Vec3::Ones()), 0.0);
  EXPECT_NEAR(point_box_dist2(Vec3(2, 3, 0.5), Vec3::Zero(), Vec3::Ones()), 5.0, 1e-15);
  // The lower bound never exceeds the true segment–box distance.
  EXPECT_LE(segment_box_dist2_lower(Vec3(-1, 2, 0.5), Vec3(2, 2, 0.5), Vec3::Zero(), Vec3::Ones()), 1.0);
}

TEST(TriangleDistance, SegmentBoxLowerBoundAgainstExactMinimum) {
  // Oracle: the point–box distance is convex along the segment, so a ternary search over the
  // segment parameter finds the true segment–box distance (to ~1e-15 after 200 steps).
  std::mt19937_64 rng(17);
  auto exact = [](const Vec3& a, const Vec3& b, const Vec3& lo, const Vec3& hi) {
    auto f = [&](double t) { return std::sqrt(point_box_dist2(a + (b - a) * t, lo, hi)); };
    double l = 0.0, r = 1.0;
    for (int i = 0; i < 200; ++i) {
      const double m1 = l + (r - l) / 3.0, m2 = r - (r - l) / 3.0;
      if (f(m1) <= f(m2)) r = m2;
      else l = m1;
    }
    return std::min({f(0.0), f(1.0), f(0.5 * (l + r))});
  };
  for (int k = 0; k < 600; ++k) {
    Vec3 a = rnd(rng, 3), b = a + rnd(rng, 2);
    const Vec3 c0 = rnd(rng, 2), c1 = c0 + rnd(rng, 1).cwiseAbs();
    if (k % 3 == 1) b = Vec3(b.x(), a.y(), a.z());  // along an axis: the segment is its own box
    if (k % 3 == 2) b = a;                          // a point
    const double d = exact(a, b, c0, c1);
    const double lower = std::sqrt(segment_box_dist2_lower(a, b, c0, c1));
    EXPECT_LE(lower, d + 1e-12) << k;
    // Exact in both special cases (the midpoint-sphere bound alone is loose along an axis).
    if (k % 3 != 0) {
      EXPECT_NEAR(lower, d, 1e-9) << k;
    }
  }
  // A segment running along a face, 1 above it: the bound is the gap, exactly.
  EXPECT_NEAR(segment_box_dist2_lower(Vec3(-5, 2, 0.5), Vec3(5, 2, 0.5), Vec3::Zero(), Vec3::Ones()), 1.0, 1e-15);
}

TEST(TriangleDistance, SegmentTrianglePlaneLowerBound) {
  // Oracle: the exact segment–triangle kernel. The bound never exceeds it, is 0 whenever the
  // segment meets the plane, and equals it when the closest pair lies inside the triangle.
  std::mt19937_64 rng(23);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 t0 = rnd(rng, 2), t1 = rnd(rng, 2);
    Vec3 t2 = rnd(rng, 2);
    Vec3 a = rnd(rng, 4), b = a + rnd(rng, 3);
    if (k % 4 == 1) b = a;  // a point
    if (k % 4 == 2) t2 = t0 + 0.5 * (t1 - t0);  // degenerate: no plane, no bound
    const double exact = closest_segment_triangle(a, b, t0, t1, t2).dist2;
    const double lower = segment_triangle_dist2_lower(a, b, t0, t1, t2);
    // The overload with the degeneracy known gives the same value, bit for bit.
    ASSERT_EQ(lower, segment_triangle_dist2_lower(a, b, t0, t1, t2, triangle_is_degenerate(t0, t1, t2))) << k;
    ASSERT_LE(lower, exact) << k << " a=" << a.transpose() << " b=" << b.transpose();
    ASSERT_GE(lower, 0.0) << k;
    if (k % 4 == 2) {
      EXPECT_EQ(lower, 0.0) << k;
    }
  }
  // A segment parallel to the triangle, 2 above its interior: the bound is the distance.
  const Vec3 t0(0, 0, 0), t1(4, 0, 0), t2(0, 4, 0);
  EXPECT_NEAR(segment_triangle_dist2_lower(Vec3(0.5, 0.5, 2), Vec3(1.5, 0.5, 2), t0, t1, t2), 4.0, 1e-8);
  // Ends on both sides of the plane (far outside the triangle): no bound.
  EXPECT_EQ(segment_triangle_dist2_lower(Vec3(9, 9, -1), Vec3(9, 9, 1), t0, t1, t2), 0.0);
  // An end on the plane: no bound.
  EXPECT_EQ(segment_triangle_dist2_lower(Vec3(9, 9, 0), Vec3(9, 9, 1), t0, t1, t2), 0.0);
  // Below the plane, 3 away: the sign does not matter.
  EXPECT_NEAR(segment_triangle_dist2_lower(Vec3(1, 1, -3), Vec3(1, 1, -5), t0, t1, t2), 9.0, 1e-7);
}

TEST(TriangleDistance, KnownDegeneracyGivesIdenticalResults) {
  // The overloads taking triangle_is_degenerate() as known must agree bit for bit with the
  // ones that test it, on proper, sliver, collinear and point triangles.
  std::mt19937_64 rng(23);
  for (int k = 0; k < 2000; ++k) {
    Vec3 a = rnd(rng, 5), b = rnd(rng, 5), c = rnd(rng, 5);
    switch (k % 4) {
      case 1: c = a + 0.5 * (b - a); break;                       // collinear
      case 2: b = c = a; break;                                  // a point
      case 3: c = a + 0.3 * (b - a) + Vec3(1e-14, 0, 0); break;  // sliver
      default: break;
    }
    const Vec3 p = rnd(rng, 8), q = rnd(rng, 8);
    const bool deg = triangle_is_degenerate(a, b, c);
    const TrianglePointResult r0 = closest_point_on_triangle(p, a, b, c), r1 = closest_point_on_triangle(p, a, b, c, deg);
    EXPECT_EQ(r0.dist2, r1.dist2) << k;
    EXPECT_EQ(r0.point, r1.point) << k;
    const SegmentTriangleResult s0 = closest_segment_triangle(p, q, a, b, c), s1 = closest_segment_triangle(p, q, a, b, c, deg);
    EXPECT_EQ(s0.dist2, s1.dist2) << k;
    EXPECT_EQ(s0.s, s1.s) << k;
    EXPECT_EQ(s0.triangle_point, s1.triangle_point) << k;
  }
}

RC_GTEST_PROP(TriangleDistanceProps, ClosestIsNoFartherThanCornersAndTranslationInvariant, ()) {
  const auto gen = [] {
    return Vec3(*rc::gen::inRange(-1000, 1000) / 100.0, *rc::gen::inRange(-1000, 1000) / 100.0,
                *rc::gen::inRange(-1000, 1000) / 100.0);
  };
  const Vec3 a = gen(), b = gen(), c = gen(), p = gen(), shift = gen() * 100.0;
  const auto r = closest_point_on_triangle(p, a, b, c);
  RC_ASSERT(r.dist2 <= (p - a).squaredNorm() + 1e-12);
  RC_ASSERT(r.dist2 <= (p - b).squaredNorm() + 1e-12);
  RC_ASSERT(r.dist2 <= (p - c).squaredNorm() + 1e-12);
  const auto s = closest_point_on_triangle(p + shift, a + shift, b + shift, c + shift);
  RC_ASSERT(std::abs(std::sqrt(s.dist2) - std::sqrt(r.dist2)) <= 1e-9);
  // Segment distance ≤ distance of each endpoint, and = point distance for a point segment.
  const Vec3 q = gen();
  const auto st = closest_segment_triangle(p, q, a, b, c);
  RC_ASSERT(st.dist2 <= r.dist2 + 1e-12);
  RC_ASSERT(std::abs(closest_segment_triangle(p, p, a, b, c).dist2 - r.dist2) <= 1e-9 * std::max(1.0, r.dist2));
}
