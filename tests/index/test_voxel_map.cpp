// VoxelMap against the brute-force oracle: distances within the stated bound (half the
// voxel diagonal), inside tests, rays, segment checks, .bt save/load (EDT checked against a
// brute-force nearest-occupied-voxel oracle), the real OctoMap file from the shared data,
// OctoMap's key range, degenerate scenes, and rapidcheck properties.
#include "index/brute_force_index.hpp"
#include "index/voxel_map.hpp"
#include "index/index_conformance.hpp"
#include "index/index_test_meshes.hpp"

#include "core/error.hpp"

#include <gtest/gtest.h>
#include "common/shared_data.hpp"
#include <octomap/OcTree.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace loom;
using namespace loom::testmesh;

namespace {

std::vector<Part> scene() {
  std::mt19937_64 rng(44);
  std::vector<Part> parts;
  parts.push_back(make_part("sphere", uv_sphere(Vec3(0.3, 0.1, 0.2), 10, 24, 12), true));
  parts.push_back(make_part("box", box(Vec3(15, -5, -5), Vec3(30, 5, 8)), true));
  parts.push_back(make_part("torus", torus(Vec3(-25, 10, 0), 10, 3, 32, 12), true));
  parts.push_back(make_part("soup", random_soup(rng, 60, Vec3(-30, -30, -15), Vec3(30, 30, 15), 4), false));
  return parts;
}

AABB scene_box(const std::vector<Part>& parts) {
  AABB b;
  for (const auto& p : parts) b.extend(p.mesh.bounds());
  return b;
}

/// Semantic distance (0 inside closed parts) from the oracle.
double true_distance(const BruteForceIndex& b, const Vec3& p) {
  if (b.inside(p)) return 0.0;
  const ClosestHit h = b.closest(p);
  return h.found() ? h.distance : std::numeric_limits<double>::infinity();
}

const std::vector<Part>& shared_scene() {
  static const std::vector<Part> parts = scene();
  return parts;
}
const VoxelMap& shared_map() {
  static const VoxelMap vm(shared_scene(), VoxelOptions{1.0, 6.0});
  return vm;
}

}  // namespace

TEST(VoxelMap, ResolutionRule) {
  EXPECT_NEAR(VoxelMap::derive_resolution(2.5, 5.0), 7.5 / std::sqrt(3.0), 1e-15);
  // Half the voxel diagonal is half the gap r + c.
  const double res = VoxelMap::derive_resolution(1.0, 2.0);
  EXPECT_NEAR(0.5 * std::sqrt(3.0) * res, 1.5, 1e-12);
  EXPECT_THROW(VoxelMap::derive_resolution(0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(VoxelMap::derive_resolution(-1.0, 0.5), std::invalid_argument);
}

TEST(VoxelMap, DistancesWithinStatedBound) {
  const auto& parts = shared_scene();
  const VoxelMap& vm = shared_map();
  const BruteForceIndex b(parts);
  const double bound = vm.accuracy().abs_error;
  EXPECT_FALSE(vm.accuracy().exact);
  EXPECT_LE(bound, 0.5 * std::sqrt(3.0) * vm.resolution() * (1 + 1e-6));
  EXPECT_GT(vm.stats().surface_voxels, 100u);
  EXPECT_GT(vm.stats().interior_voxels, 100u);
  EXPECT_GT(vm.octree_leaf_count(), 0u);
  std::mt19937_64 rng(17);
  const auto pts = random_points(rng, scene_box(parts), 8, 3000);
  int near = 0;
  for (const Vec3& p : pts) {
    const double t = true_distance(b, p);
    const double d = vm.distance(p);
    if (t <= vm.max_distance() - bound) {
      ++near;
      ASSERT_NEAR(d, t, bound) << p.transpose();
      // Closest reports the same distance and a part whose distance is within the bound.
      const ClosestHit h = vm.closest(p);
      ASSERT_TRUE(h.found());
      EXPECT_EQ(h.distance, d);
      EXPECT_LE(true_distance(BruteForceIndex({parts[h.part]}), p), t + 2 * bound + 1e-9);
    } else if (t > vm.max_distance() + bound) {
      EXPECT_FALSE(std::isfinite(d)) << p.transpose();
      EXPECT_FALSE(vm.closest(p).found());
    }
    // any_within agrees wherever the bound decides it.
    for (double r : {0.5, 2.0, 5.0}) {
      if (t <= r - bound) {
        EXPECT_TRUE(vm.any_within(p, r)) << p.transpose() << " r " << r;
      }
      if (t > r + bound) {
        EXPECT_FALSE(vm.any_within(p, r)) << p.transpose() << " r " << r;
      }
    }
  }
  EXPECT_GT(near, 500);
}

TEST(VoxelMap, InsideIsExact) {
  const auto& parts = shared_scene();
  const VoxelMap& vm = shared_map();
  const BruteForceIndex b(parts);
  std::mt19937_64 rng(18);
  int in = 0;
  for (const Vec3& p : random_points(rng, scene_box(parts), 2, 3000)) {
    int pv = -1, pb = -1;
    const bool iv = vm.inside(p, &pv), ib = b.inside(p, &pb);
    ASSERT_EQ(iv, ib) << p.transpose();
    if (ib) {
      ++in;
      EXPECT_EQ(pv, pb);
    }
  }
  EXPECT_GT(in, 100);
}

TEST(VoxelMap, SegmentsAndRaysWithinBound) {
  const auto& parts = shared_scene();
  const VoxelMap& vm = shared_map();
  const BruteForceIndex b(parts);
  const double bound = vm.accuracy().abs_error;
  const double seg_bound = bound + 0.25 * vm.resolution();
  std::mt19937_64 rng(19);
  std::normal_distribution<double> n01;
  const auto pts = random_points(rng, scene_box(parts), 4, 400);
  int hits = 0;
  for (std::size_t i = 0; i + 1 < pts.size(); i += 2) {
    const Vec3 a = pts[i], c = a + 6.0 * Vec3(n01(rng), n01(rng), n01(rng)).normalized();
    // Segment oracle: brute segment distance, 0 if an endpoint is inside a closed part.
    const ClosestHit bs = b.segment_closest(a, c);
    const double t = (b.inside(a) || b.inside(c)) ? 0.0 : bs.distance;
    for (double r : {0.5, 2.0}) {
      if (t <= r - bound) {
        EXPECT_TRUE(vm.segment_within(a, c, r)) << i;
      }
      if (t > r + seg_bound) {
        EXPECT_FALSE(vm.segment_within(a, c, r)) << i;
      }
    }
    const ClosestHit vs = vm.segment_closest(a, c, 5.0);
    if (t <= 5.0 - seg_bound) {
      ASSERT_TRUE(vs.found()) << i;
      EXPECT_NEAR(vs.distance, t, seg_bound) << i;
    }
    // Rays: the voxel hit comes no later than the surface hit, and lies within a voxel
    // diagonal of a surface.
    const Vec3 dir(n01(rng), n01(rng), n01(rng));
    const RayHit rb = b.ray(a, dir);
    const RayHit rv = vm.ray(a, dir);
    if (rb.found()) {
      ASSERT_TRUE(rv.found()) << i;
      EXPECT_LE(rv.t, rb.t + 1e-4) << i;
      ++hits;
    }
    if (rv.found()) {
      const Vec3 at = a + rv.t * dir.normalized();
      EXPECT_LE(true_distance(b, at), 2.0 * bound + 1e-4) << i;
    }
  }
  EXPECT_GT(hits, 20);
  EXPECT_THROW(vm.ray(Vec3::Zero(), Vec3::Zero()), std::invalid_argument);
  // Per-part queries go to the exact index.
  const ClosestHit h = vm.closest_on_part(Vec3(0, 0, 20), 0);
  ASSERT_TRUE(h.found());
  EXPECT_NEAR(h.distance, b.closest_on_part(Vec3(0, 0, 20), 0).distance, 1e-12);
  EXPECT_THROW(vm.closest_on_part(Vec3::Zero(), 7), std::out_of_range);
}

TEST(VoxelMap, SaveLoadRoundTripAndEdtOracle) {
  const VoxelMap& vm = shared_map();
  const auto path = std::filesystem::temp_directory_path() / "loom_test_voxel_map.bt";
  vm.save_bt(path.string());
  const auto loaded = VoxelMap::load_bt(path.string(), VoxelOptions{0.0, 6.0});
  std::filesystem::remove(path);
  EXPECT_EQ(loaded->resolution(), vm.resolution());
  EXPECT_EQ(loaded->octree_leaf_count(), vm.octree_leaf_count());
  EXPECT_EQ(loaded->stats().surface_voxels, vm.stats().surface_voxels + vm.stats().interior_voxels);
  EXPECT_EQ(loaded->part_count(), 1);
  // Loaded distances agree with the built ones within both bounds.
  const BruteForceIndex b(shared_scene());
  std::mt19937_64 rng(20);
  for (const Vec3& p : random_points(rng, scene_box(shared_scene()), 4, 1000)) {
    const double t = true_distance(b, p);
    if (t <= 6.0 - loaded->accuracy().abs_error) {
      EXPECT_NEAR(loaded->distance(p), t, loaded->accuracy().abs_error) << p.transpose();
    }
  }
}

TEST(VoxelMap, RealOctomapFile) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const std::string path = std::string(LOOM_SHARED_DATA) + "/octomap/geb079.bt";
  const auto vm = VoxelMap::load_bt(path, VoxelOptions{0.0, 0.0});
  ASSERT_GT(vm->resolution(), 0.0);
  ASSERT_GT(vm->octree_leaf_count(), 0u);
  // Oracle: the EDT value at a voxel centre is the distance to the nearest occupied voxel centre.
  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary(path));
  const double res = tree.getResolution();
  std::vector<Vec3> occ;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const long steps = std::max(1L, static_cast<long>(std::llround(it.getSize() / res)));
    const Vec3 corner = Vec3(it.getX(), it.getY(), it.getZ()) - Vec3::Constant(0.5 * it.getSize());
    for (long a = 0; a < steps; ++a)
      for (long b = 0; b < steps; ++b)
        for (long c = 0; c < steps; ++c) occ.push_back(corner + (Vec3(a, b, c) + Vec3::Constant(0.5)) * res);
  }
  ASSERT_FALSE(occ.empty());
  EXPECT_EQ(vm->stats().surface_voxels, occ.size());
  EXPECT_EQ(vm->distance(occ.front()), 0.0);
  EXPECT_TRUE(vm->inside(occ.back()));
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<std::size_t> pick(0, occ.size() - 1);
  std::normal_distribution<double> n01;
  for (int i = 0; i < 60; ++i) {
    // A voxel centre a few voxels away from an occupied one.
    const Vec3 off = 3.0 * res * Vec3(n01(rng), n01(rng), n01(rng));
    const Vec3 p = ((occ[pick(rng)] + off) / res).array().floor().matrix() * res + Vec3::Constant(0.5 * res);
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& o : occ) best = std::min(best, (o - p).norm());
    const double d = vm->distance(p);
    if (best <= vm->max_distance()) {
      EXPECT_NEAR(d, best, 1e-5 * std::max(1.0, best)) << p.transpose();
    } else {
      EXPECT_FALSE(std::isfinite(d));
    }
  }
  EXPECT_THROW(VoxelMap::load_bt(std::string(LOOM_SHARED_DATA) + "/fcl/env.obj", VoxelOptions{}), InputError);
}

TEST(VoxelMap, KeyRangeBudgetAndDegenerateScenes) {
  // 40 000 voxels from the origin: beyond OctoMap's 16-bit keys.
  std::vector<Part> far{make_part("far", box(Vec3(40000, 0, 0), Vec3(40001, 1, 1)), true)};
  try {
    VoxelMap vm(far, VoxelOptions{1.0, 2.0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("32768"), std::string::npos) << e.what();
  }
  // The same box at a coarser resolution fits.
  EXPECT_NO_THROW(VoxelMap(far, VoxelOptions{4.0, 8.0}));
  // Cell budget.
  std::vector<Part> big{make_part("big", box(Vec3(0, 0, 0), Vec3(100, 100, 100)), true)};
  VoxelOptions small_budget{0.5, 1.0};
  small_budget.max_cells = 1000;
  EXPECT_THROW(VoxelMap(big, small_budget), InputError);
  EXPECT_THROW(VoxelMap(big, VoxelOptions{0.0, 1.0}), std::invalid_argument);
  // Empty scene: nothing anywhere.
  const VoxelMap empty(std::vector<Part>{}, VoxelOptions{1.0, 3.0});
  EXPECT_FALSE(std::isfinite(empty.distance(Vec3::Zero())));
  EXPECT_FALSE(empty.inside(Vec3::Zero()));
  EXPECT_FALSE(empty.any_within(Vec3::Zero(), 2.0));
  EXPECT_FALSE(empty.ray(Vec3::Zero(), Vec3::UnitX()).found());
  // A single triangle and a mesh of zero-area triangles (open: no interior).
  Mesh single;
  single.vertices = {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};
  single.triangles = {{0, 1, 2}};
  Mesh degenerate;
  degenerate.vertices = {Vec3(10, 0, 0), Vec3(12, 0, 0), Vec3(14, 0, 0), Vec3(12, 0, 0)};
  degenerate.triangles = {{0, 1, 2}, {1, 3, 1}};
  std::vector<Part> parts{make_part("single", single, false), make_part("degenerate", degenerate, false)};
  const VoxelMap vm(parts, VoxelOptions{0.5, 3.0});
  const BruteForceIndex b(parts);
  EXPECT_EQ(vm.stats().interior_voxels, 0u);
  std::mt19937_64 rng(22);
  for (const Vec3& p : random_points(rng, scene_box(parts), 2, 500)) {
    const double t = b.closest(p).distance;
    if (t <= 3.0 - vm.accuracy().abs_error) {
      EXPECT_NEAR(vm.distance(p), t, vm.accuracy().abs_error);
    }
  }
}

RC_GTEST_PROP(VoxelMapProps, DistanceIsLipschitzWithinTwiceTheBound, ()) {
  const VoxelMap& vm = shared_map();
  const auto coord = [](int lim) { return *rc::gen::inRange(-lim, lim) / 10.0; };
  const Vec3 p(coord(450), coord(300), coord(200));
  const Vec3 q = p + Vec3(coord(30), coord(30), coord(30));
  const double dp = vm.distance(p), dq = vm.distance(q);
  if (std::isfinite(dp) && std::isfinite(dq)) RC_ASSERT(std::abs(dp - dq) <= (p - q).norm() + 2 * vm.accuracy().abs_error);
  RC_ASSERT(!(dp < 0.0));
  // any_within(p, d) holds exactly at the map's own distance.
  if (std::isfinite(dp)) RC_ASSERT(vm.any_within(p, dp));
}
