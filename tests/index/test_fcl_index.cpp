// FclIndex against the brute-force oracle (1e-9 relative) and the FCL 0.7 cases it relies
// on: degenerate query triangles for points and segments, touching/piercing segments,
// zero-area and tiny triangles in the parts, rays via collision candidates.
#include "index/brute_force_index.hpp"
#include "index/fcl_index.hpp"
#include "index/triangle_distance.hpp"
#include "index/index_conformance.hpp"
#include "index/index_test_meshes.hpp"

#include "core/error.hpp"

#include <gtest/gtest.h>
#include "common/shared_data.hpp"
#include <rapidcheck/gtest.h>

#include <random>

using namespace loom;
using namespace loom::testmesh;

namespace {

constexpr double kExactRel = 1e-9;

/// The mixed scene at a coarser resolution (FCL builds are slower than Embree's).
std::vector<Part> scene(const Vec3& offset) {
  MixedSceneDetail d;
  d.seed = 43;
  d.soup = 200;
  d.sphere_nu = 20;
  d.sphere_nv = 10;
  d.torus_nu = 24;
  d.torus_nv = 10;
  return mixed_scene(offset, d);
}


}  // namespace

TEST(FclIndex, MatchesBruteForce) {
  const auto parts = scene(Vec3::Zero());
  const FclIndex f(parts);
  const BruteForceIndex b(parts);
  EXPECT_EQ(f.direct_triangle_count(), 0u);
  std::mt19937_64 rng(12);
  const auto pts = random_points(rng, bounds_of(parts), 10, 250);
  expect_distances_match(f, b, pts, kExactRel, 1e-9);
  expect_rays_match(f, b, pts, kExactRel, 1e-9);
  for (const Vec3& p : pts) EXPECT_EQ(f.inside(p), b.inside(p));
  EXPECT_TRUE(f.accuracy().exact);
}

TEST(FclIndex, InsidePartsNamesEveryOverlappingClosedPart) {
  const auto parts = overlapping_scene();
  const FclIndex f(parts);
  const BruteForceIndex b(parts);
  std::mt19937_64 rng(29);
  EXPECT_GT(expect_inside_parts_match(f, b, random_points(rng, bounds_of(parts), 2, 1000)), 100);
}

TEST(FclIndex, FarFromOriginMatchesBruteForce) {
  const auto parts = scene(Vec3(-35000, 52000, 8000));
  const FclIndex f(parts);
  const BruteForceIndex b(parts);
  std::mt19937_64 rng(13);
  const auto pts = random_points(rng, bounds_of(parts), 5, 120);
  expect_distances_match(f, b, pts, kExactRel, 1e-9);
}

TEST(FclIndex, TouchingPiercingAndCapsules) {
  std::vector<Part> parts{make_part("box", box(Vec3(0, 0, 0), Vec3(2, 2, 2)), true)};
  const FclIndex f(parts);
  // Segment piercing the box: distance 0 (FCL returns 0 without nearest points).
  const ClosestHit h = f.segment_closest(Vec3(1, 1, -3), Vec3(1, 1, 3));
  ASSERT_TRUE(h.found());
  EXPECT_EQ(h.distance, 0.0);
  EXPECT_TRUE(f.segment_within(Vec3(1, 1, -3), Vec3(1, 1, 3), 0.0));
  // Point on a face, on an edge, on a vertex.
  EXPECT_NEAR(f.closest(Vec3(1, 1, 2)).distance, 0.0, 1e-15);
  EXPECT_NEAR(f.closest(Vec3(2, 1, 2)).distance, 0.0, 1e-15);
  EXPECT_NEAR(f.closest(Vec3(2, 2, 2)).distance, 0.0, 1e-15);
  // Segment parallel to a face, above it; and along an edge direction outside.
  EXPECT_NEAR(f.segment_closest(Vec3(0.5, 0.5, 2.7), Vec3(1.5, 1.5, 2.7)).distance, 0.7, 1e-14);
  EXPECT_NEAR(f.segment_closest(Vec3(3, 3, -1), Vec3(3, 3, 5)).distance, std::sqrt(2.0), 1e-14);
  // Capsule gap: radius 0.5 at height 0.7 → +0.2; radius 1 → −0.3.
  double s = -1;
  EXPECT_NEAR(f.capsule_on_part(Vec3(0.5, 0.5, 2.7), Vec3(1.5, 1.5, 2.7), 0.5, 0, &s).distance, 0.2, 1e-14);
  EXPECT_GE(s, 0.0);
  EXPECT_LE(s, 1.0);
  EXPECT_NEAR(f.capsule_on_part(Vec3(0.5, 0.5, 2.7), Vec3(1.5, 1.5, 2.7), 1.0, 0).distance, -0.3, 1e-14);
  // Rays: from outside, from inside, along a face (grazing), through an edge.
  EXPECT_NEAR(f.ray(Vec3(1, 1, 5), Vec3(0, 0, -1)).t, 3.0, 1e-14);
  EXPECT_NEAR(f.ray(Vec3(1, 1, 1), Vec3(1, 0, 0)).t, 1.0, 1e-14);
  EXPECT_NEAR(f.ray(Vec3(-1, 2, 2), Vec3(1, 0, 0), 10).t, 1.0, 1e-14);
  EXPECT_FALSE(f.ray(Vec3(1, 1, 5), Vec3(0, 0, 1)).found());
  EXPECT_TRUE(f.inside(Vec3(1, 1, 1)));
  EXPECT_FALSE(f.inside(Vec3(1, 1, 2.0001)));
}

TEST(FclIndex, DegenerateAndTinyTriangles) {
  // Zero-area triangles and triangles below FCL's absolute face-test threshold go to the
  // exact kernels; distances must still match brute force.
  Mesh degenerate;
  degenerate.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0), Vec3(5, 5, 5)};
  degenerate.triangles = {{0, 1, 2}, {1, 3, 1}, {4, 4, 4}};
  Mesh tiny = uv_sphere(Vec3(0, 3, 0), 1e-4, 8, 4);  // edges ~1e-4: |n|² ~ 1e-17
  Mesh single;
  single.vertices = {Vec3(0, 0, 3), Vec3(1, 0, 3), Vec3(0, 1, 3)};
  single.triangles = {{0, 1, 2}};
  std::vector<Part> parts{make_part("degenerate", degenerate, false), make_part("tiny", tiny, true),
                          make_part("single", single, false), make_part("empty", Mesh{}, false)};
  const FclIndex f(parts);
  const BruteForceIndex b(parts);
  EXPECT_EQ(f.direct_triangle_count(), 3u + tiny.triangle_count());
  EXPECT_NEAR(f.closest(Vec3(5, 5, 6)).distance, 1.0, 1e-14);
  EXPECT_NEAR(f.closest(Vec3(0, 3, 1)).distance, b.closest(Vec3(0, 3, 1)).distance, 1e-14);
  std::mt19937_64 rng(14);
  const auto pts = random_points(rng, bounds_of(parts), 2, 200);
  expect_distances_match(f, b, pts, kExactRel, 1e-12);
  EXPECT_TRUE(f.inside(Vec3(0, 3, 0)));
  const FclIndex empty(std::vector<Part>{});
  EXPECT_FALSE(empty.closest(Vec3::Zero()).found());
  EXPECT_FALSE(empty.any_within(Vec3::Zero(), 1e9));
  EXPECT_FALSE(empty.ray(Vec3::Zero(), Vec3::UnitZ()).found());
  EXPECT_FALSE(empty.inside(Vec3::Zero()));
}

TEST(FclIndex, SmallTrianglesJustAboveTheThresholdStayInFcl) {
  // Triangles of edge 1e-3 (|n|² ~ 1e-12) are answered by FCL itself: check they are exact.
  std::vector<Part> parts{make_part("small", uv_sphere(Vec3(0.25, 0, 0), 3e-3, 12, 6), true)};
  const FclIndex f(parts);
  const BruteForceIndex b(parts);
  EXPECT_EQ(f.direct_triangle_count(), 0u);
  std::mt19937_64 rng(15);
  const auto pts = random_points(rng, bounds_of(parts), 2e-3, 300);
  expect_distances_match(f, b, pts, kExactRel, 1e-12);
}

TEST(FclIndex, RealMeshFromSharedData) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  Mesh m = read_obj(std::string(LOOM_SHARED_DATA) + "/fcl/rob.obj");
  ASSERT_GT(m.triangle_count(), 100u);
  weld_identical_vertices(m);
  std::vector<Part> parts{make_part("rob", m, analyse_topology(m).closed)};
  const FclIndex f(parts);
  const BruteForceIndex b(parts);
  std::mt19937_64 rng(16);
  const AABB box = m.bounds();
  const auto pts = random_points(rng, box, 0.1 * box.diagonal(), 150);
  expect_distances_match(f, b, pts, kExactRel, 1e-9 * box.diagonal());
  expect_rays_match(f, b, pts, kExactRel, 1e-9 * box.diagonal());
}

TEST(FclIndex, RejectsBadMeshes) {
  Mesh bad;
  bad.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  bad.triangles = {{0, 1, 5}};
  EXPECT_THROW(FclIndex({make_part("bad", bad, false)}), InputError);
}

RC_GTEST_PROP(FclIndexProps, SegmentDistanceMatchesBruteForce, ()) {
  static const std::vector<Part> parts = scene(Vec3::Zero());
  static const FclIndex f(parts);
  static const BruteForceIndex b(parts);
  const auto coord = [](int lim) { return *rc::gen::inRange(-lim, lim) / 10.0; };
  const Vec3 a(coord(500), coord(500), coord(300));
  const Vec3 c = a + Vec3(coord(100), coord(100), coord(100));
  const ClosestHit hf = f.segment_closest(a, c), hb = b.segment_closest(a, c);
  RC_ASSERT(hf.found() == hb.found());
  RC_ASSERT(std::abs(hf.distance - hb.distance) <= 1e-9 * std::max(1.0, hb.distance));
  // Capsule gap is the segment distance minus the radius, for every part.
  const int part = *rc::gen::inRange(0, 4);
  const double r = *rc::gen::inRange(0, 50) / 10.0;
  const ClosestHit cap = f.capsule_on_part(a, c, r, part);
  double exact = std::numeric_limits<double>::infinity();
  const Mesh& m = parts[part].mesh;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto k = m.corners(t);
    exact = std::min(exact, std::sqrt(closest_segment_triangle(a, c, k[0], k[1], k[2]).dist2));
  }
  RC_ASSERT(cap.found());
  RC_ASSERT(std::abs(cap.distance - (exact - r)) <= 1e-9 * std::max(1.0, exact));
  RC_ASSERT(cap.distance + r >= hb.distance - 1e-9);
  // The per-part segment distance (FCL and brute force) is that part's exact distance, and
  // a radius below it finds nothing.
  for (const ObstacleIndex* idx : {static_cast<const ObstacleIndex*>(&f), static_cast<const ObstacleIndex*>(&b)}) {
    const ClosestHit on = idx->segment_closest_on_part(a, c, part, std::numeric_limits<double>::infinity());
    RC_ASSERT(on.found());
    RC_ASSERT(on.part == part);
    RC_ASSERT(std::abs(on.distance - exact) <= 1e-9 * std::max(1.0, exact));
    if (exact > 1e-6) RC_ASSERT(!idx->segment_closest_on_part(a, c, part, 0.99 * exact).found());
  }
}
