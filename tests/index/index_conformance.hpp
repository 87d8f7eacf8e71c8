#pragma once
// Conformance checks shared by the index tests: an ObstacleIndex against the brute-force
// oracle over random points, segments and rays with fixed seeds.

#include "index/brute_force_index.hpp"
#include "index/obstacle_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iomanip>
#include <random>
#include <vector>

namespace loom::testmesh {

/// Random points in the box [lo, hi] grown by `margin`.
inline std::vector<Vec3> random_points(std::mt19937_64& rng, const AABB& box, double margin, int n) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Vec3> pts;
  const Vec3 lo = box.min - Vec3::Constant(margin), hi = box.max + Vec3::Constant(margin);
  for (int i = 0; i < n; ++i) pts.push_back(lo + (hi - lo).cwiseProduct(Vec3(u01(rng), u01(rng), u01(rng))));
  return pts;
}

/// Tolerance for comparing a distance d: rel·max(d, scale) (scale = scene size).
inline double tol(double d, double rel, double scale) { return rel * std::max(d, scale); }

/// inside_parts() against brute force, and inside() consistent with it (true exactly when
/// some part holds p, naming one of them). Returns how many points lie in two parts or more.
inline int expect_inside_parts_match(const ObstacleIndex& idx, const BruteForceIndex& brute,
                                     const std::vector<Vec3>& pts) {
  int overlapped = 0;
  std::vector<int> got, want;
  for (const Vec3& p : pts) {
    idx.inside_parts(p, got);
    brute.inside_parts(p, want);
    EXPECT_EQ(got, want) << std::setprecision(17) << "at (" << p.x() << ", " << p.y() << ", " << p.z() << ")";
    int part = -1;
    EXPECT_EQ(idx.inside(p, &part), !got.empty());
    if (!got.empty()) {
      EXPECT_NE(std::find(got.begin(), got.end(), part), got.end()) << "inside() named " << part;
    }
    overlapped += want.size() >= 2 ? 1 : 0;
  }
  return overlapped;
}

/// closest / closest_on_part / any_within / segment queries against brute force.
inline void expect_distances_match(const ObstacleIndex& idx, const BruteForceIndex& brute,
                                   const std::vector<Vec3>& pts, double rel, double scale) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vec3& p = pts[i];
    const ClosestHit b = brute.closest(p);
    const ClosestHit e = idx.closest(p);
    ASSERT_EQ(b.found(), e.found()) << "point " << i;
    if (!b.found()) continue;
    EXPECT_NEAR(e.distance, b.distance, tol(b.distance, rel, scale)) << "point " << i;
    EXPECT_NEAR((e.point - p).norm(), e.distance, tol(b.distance, rel, scale)) << "point " << i;
    // Bounded radius: just above and just below the distance.
    const double slack = tol(b.distance, 10 * rel, scale);
    EXPECT_TRUE(idx.closest(p, b.distance + slack).found()) << "point " << i;
    if (b.distance - slack > 0) {
      EXPECT_FALSE(idx.closest(p, b.distance - slack).found()) << "point " << i;
    }
    EXPECT_TRUE(idx.any_within(p, b.distance + slack)) << "point " << i;
    if (b.distance - slack > 0) {
      EXPECT_FALSE(idx.any_within(p, b.distance - slack)) << "point " << i;
    }
    // One given part.
    const int part = static_cast<int>(i % static_cast<std::size_t>(brute.part_count()));
    const ClosestHit bp = brute.closest_on_part(p, part);
    const ClosestHit ep = idx.closest_on_part(p, part);
    ASSERT_EQ(bp.found(), ep.found()) << "point " << i << " part " << part;
    if (bp.found()) {
      EXPECT_EQ(ep.part, part);
      EXPECT_NEAR(ep.distance, bp.distance, tol(bp.distance, rel, scale)) << "point " << i;
    }
    // Segment from p to another point.
    const Vec3& q = pts[(i * 7 + 3) % pts.size()];
    const Vec3 qb = p + (q - p) * u01(rng);
    double sb = -1, se = -1;
    const ClosestHit bs = brute.segment_closest(p, qb, std::numeric_limits<double>::infinity(), &sb);
    const ClosestHit es = idx.segment_closest(p, qb, std::numeric_limits<double>::infinity(), &se);
    ASSERT_EQ(bs.found(), es.found());
    if (bs.found()) {
      EXPECT_NEAR(es.distance, bs.distance, tol(bs.distance, rel, scale)) << "segment " << i;
      EXPECT_GE(se, 0.0);
      EXPECT_LE(se, 1.0);
      const Vec3 on_seg = p + se * (qb - p);
      EXPECT_NEAR((on_seg - es.point).norm(), es.distance, tol(bs.distance, 10 * rel, scale)) << "segment " << i;
      const double sl = tol(bs.distance, 10 * rel, scale);
      EXPECT_TRUE(idx.segment_within(p, qb, bs.distance + sl)) << "segment " << i;
      if (bs.distance - sl > 0) {
        EXPECT_FALSE(idx.segment_within(p, qb, bs.distance - sl)) << "segment " << i;
      }
    }
  }
}

/// Rays from the points in random directions against brute force.
inline void expect_rays_match(const ObstacleIndex& idx, const BruteForceIndex& brute,
                              const std::vector<Vec3>& pts, double rel, double scale) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01;
  int compared = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vec3 dir(n01(rng), n01(rng), n01(rng));
    const RayHit b = brute.ray(pts[i], dir);
    const RayHit e = idx.ray(pts[i], dir);
    ASSERT_EQ(b.found(), e.found()) << "ray " << i;
    if (!b.found()) continue;
    ++compared;
    EXPECT_NEAR(e.t, b.t, tol(b.t, rel, scale)) << "ray " << i;
    EXPECT_NEAR(e.normal.norm(), 1.0, 1e-9);
    // t_max just below the hit: nothing.
    if (b.t > tol(b.t, 10 * rel, scale)) {
      EXPECT_FALSE(idx.ray(pts[i], dir, b.t - tol(b.t, 10 * rel, scale)).found());
    }
  }
  EXPECT_GT(compared, 0);
}

}  // namespace loom::testmesh
