// SceneIndices: the per-use choice of index, the derived voxel resolution and the logged
// fallbacks (key range, grid budget, empty scene), and agreement of the chosen indices
// with brute force on a small scene.
#include "index/brute_force_index.hpp"
#include "index/scene_indices.hpp"
#include "index/index_test_meshes.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace loom;
using namespace loom::testmesh;

namespace {

Scene small_scene(double cable_diameter, double clearance) {
  Scene s;
  s.name = "t";
  s.parts.push_back(make_part("sphere", uv_sphere(Vec3(0, 0, 0), 10, 16, 8), true));
  s.parts.push_back(make_part("box", box(Vec3(15, -5, -5), Vec3(30, 5, 8)), true));
  Cable c;
  c.id = "c1";
  c.physical.diameter = cable_diameter;
  s.harness.cables.push_back(c);
  s.has_harness = cable_diameter > 0;
  s.routing.clearance = {clearance, "scene file"};
  return s;
}

bool log_mentions(const SceneIndices& si, const std::string& what) {
  return std::any_of(si.log.begin(), si.log.end(), [&](const std::string& l) { return l.find(what) != std::string::npos; });
}

}  // namespace

TEST(SceneIndices, ChoosesIndexPerUseAndDerivesResolution) {
  const Scene s = small_scene(2.0, 1.0);
  const SceneIndices si = SceneIndices::build(s);
  ASSERT_TRUE(si.embree && si.fcl && si.voxel);
  EXPECT_EQ(si.for_use(QueryUse::PlanningCoarse).name(), "voxel");
  EXPECT_EQ(si.for_use(QueryUse::Reported).name(), "embree");
  EXPECT_EQ(si.for_use(QueryUse::Certification).name(), "fcl");
  EXPECT_EQ(si.choices.size(), 3u);
  EXPECT_NEAR(si.voxel->resolution(), VoxelMap::derive_resolution(1.0, 1.0), 1e-15);
  EXPECT_NEAR(si.voxel->max_distance(), 4.0 * 2.0, 1e-15);
  EXPECT_TRUE(log_mentions(si, "choice: planning -> voxel"));
  EXPECT_TRUE(log_mentions(si, "(r + c)/sqrt(3)"));
  EXPECT_FALSE(si.choice(QueryUse::Reported).reason.empty());
  // The chosen exact indices agree with brute force; the voxel one within its bound.
  const BruteForceIndex b(s.parts);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-20, 40);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p(u(rng), u(rng) * 0.5, u(rng) * 0.5);
    const ClosestHit hb = b.closest(p);
    EXPECT_NEAR(si.for_use(QueryUse::Reported).closest(p).distance, hb.distance, 1e-9);
    EXPECT_NEAR(si.for_use(QueryUse::Certification).closest(p).distance, hb.distance, 1e-9);
    const double t = b.inside(p) ? 0.0 : hb.distance;
    const ObstacleIndex& plan = si.for_use(QueryUse::PlanningCoarse);
    if (t <= si.voxel->max_distance() - plan.accuracy().abs_error) {
      EXPECT_NEAR(plan.closest(p).distance, t, plan.accuracy().abs_error);
    }
  }
}

TEST(SceneIndices, FallbacksAreLogged) {
  // No harness and no clearance: resolution from the scene diagonal.
  const SceneIndices a = SceneIndices::build(small_scene(0.0, 0.0));
  ASSERT_TRUE(a.voxel);
  EXPECT_TRUE(log_mentions(a, "scene diagonal / 256"));
  // A tiny grid budget coarsens the voxels and says so.
  SceneIndicesOptions tight;
  tight.voxel_max_cells = 20000;
  const SceneIndices b = SceneIndices::build(small_scene(0.2, 0.1), tight);
  ASSERT_TRUE(b.voxel);
  EXPECT_TRUE(log_mentions(b, "coarsened"));
  EXPECT_GT(b.voxel->resolution(), VoxelMap::derive_resolution(0.1, 0.1));
  // Far from the origin with fine voxels: coarsened to fit OctoMap's keys.
  Scene far = small_scene(0.02, 0.01);
  for (Part& p : far.parts) p.mesh.transform(Eigen::Affine3d(Eigen::Translation3d(5000, 0, 0)));
  SceneIndicesOptions big_budget;
  big_budget.voxel_max_cells = std::size_t(1) << 34;
  big_budget.voxel_resolution = 0.01;
  big_budget.voxel_max_distance = 0.05;
  big_budget.build_fcl = false;
  // Only check the derivation (the grid itself would be large): the key-range rule fires.
  SceneIndicesOptions no_voxel = big_budget;
  no_voxel.build_voxel = false;
  const SceneIndices c = SceneIndices::build(far, no_voxel);
  EXPECT_FALSE(c.voxel);
  EXPECT_FALSE(c.fcl);
  EXPECT_EQ(c.for_use(QueryUse::PlanningCoarse).name(), "embree");
  EXPECT_EQ(c.for_use(QueryUse::Certification).name(), "embree");
  // Empty scene: Embree only, everything answers "nothing".
  Scene empty;
  const SceneIndices e = SceneIndices::build(empty);
  EXPECT_FALSE(e.voxel);
  EXPECT_FALSE(e.for_use(QueryUse::PlanningCoarse).closest(Vec3::Zero()).found());
}

TEST(SceneIndices, KeyRangeCoarsening) {
  Scene far = small_scene(0.0, 0.0);
  for (Part& p : far.parts) p.mesh.transform(Eigen::Affine3d(Eigen::Translation3d(40000, 0, 0)));
  SceneIndicesOptions o;
  o.voxel_resolution = 1.0;
  o.voxel_max_distance = 2.0;
  o.build_fcl = false;
  const SceneIndices si = SceneIndices::build(far, o);
  ASSERT_TRUE(si.voxel);
  EXPECT_TRUE(log_mentions(si, "32768"));
  EXPECT_GT(si.voxel->resolution(), 40000.0 / 32768.0);
}

RC_GTEST_PROP(SceneIndicesProps, ReportedAndCertifiedDistancesAgree, ()) {
  // Embree (reported) cross-checked by FCL (certification) on the same scene.
  static const Scene s = small_scene(2.0, 1.0);
  static const SceneIndices si = [] {
    SceneIndicesOptions o;
    o.build_voxel = false;
    return SceneIndices::build(s, o);
  }();
  const auto coord = [](int lo, int hi) { return *rc::gen::inRange(lo, hi) / 10.0; };
  const Vec3 p(coord(-200, 400), coord(-150, 150), coord(-150, 150));
  const Vec3 q = p + Vec3(coord(-50, 50), coord(-50, 50), coord(-50, 50));
  const ClosestHit e = si.for_use(QueryUse::Reported).closest(p);
  const ClosestHit f = si.for_use(QueryUse::Certification).closest(p);
  RC_ASSERT(e.found() && f.found());
  RC_ASSERT(std::abs(e.distance - f.distance) <= 1e-9 * std::max(1.0, f.distance));
  const ClosestHit es = si.for_use(QueryUse::Reported).segment_closest(p, q);
  const ClosestHit fs = si.for_use(QueryUse::Certification).segment_closest(p, q);
  RC_ASSERT(std::abs(es.distance - fs.distance) <= 1e-9 * std::max(1.0, fs.distance));
  RC_ASSERT(si.for_use(QueryUse::Reported).inside(p) == si.for_use(QueryUse::Certification).inside(p));
}
