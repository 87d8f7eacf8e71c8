// The voxel layer in front of Embree: every answer equals the exact index's (the map only
// decides what its lower bound proves), on the index tests' scenes (closed sphere, box and
// torus, an open soup; parts modelled through each other) at two resolutions, with and
// without exact refinement; and the lower bound never exceeds the brute-force distance.
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "index/voxel_first_index.hpp"
#include "index/voxel_map.hpp"

#include <gtest/gtest.h>

#include <random>

namespace loom {
namespace {

struct Case {
  const char* scene;
  double resolution;
  bool refine;
};

std::vector<Part> scene_of(const std::string& name) {
  return name == "mixed" ? testmesh::mixed_scene(Vec3(3, -2, 1)) : testmesh::overlapping_scene();
}

class VoxelFirst : public ::testing::TestWithParam<Case> {};

TEST_P(VoxelFirst, AnswersAreTheExactIndexs) {
  const Case c = GetParam();
  const std::vector<Part> parts = scene_of(c.scene);
  const auto exact = std::make_shared<EmbreeIndex>(parts);
  VoxelOptions vo;
  vo.resolution = c.resolution;
  vo.max_distance = 6.0 * c.resolution;
  vo.exact_refine = c.refine;
  vo.threads = 1;
  const VoxelMap map(parts, vo, exact);
  const VoxelFirstIndex index(*exact, &map);
  AABB box = testmesh::bounds_of(parts);
  box.min -= Vec3::Constant(20.0);
  box.max += Vec3::Constant(20.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(box.min.x(), box.max.x()), uy(box.min.y(), box.max.y()),
      uz(box.min.z(), box.max.z()), ur(0.0, 12.0), ustep(-6.0, 6.0);
  for (int q = 0; q < 4000; ++q) {
    const Vec3 p(ux(rng), uy(rng), uz(rng));
    const Vec3 b = p + Vec3(ustep(rng), ustep(rng), ustep(rng));
    const double r = ur(rng);
    SCOPED_TRACE("query " + std::to_string(q) + " at " + full_precision(p) + " r " + full_precision(r));
    const double d = exact->closest(p, std::numeric_limits<double>::infinity()).distance;
    ASSERT_LE(index.distance_lower_bound(p), d + 1e-9);
    EXPECT_EQ(index.any_within(p, r), exact->any_within(p, r));
    int part_v = -1, part_e = -1;
    const bool in_v = index.inside(p, &part_v), in_e = exact->inside(p, &part_e);
    ASSERT_EQ(in_v, in_e);
    if (in_e) {
      EXPECT_EQ(part_v, part_e);
    }
    EXPECT_EQ(index.segment_within(p, b, r), exact->segment_within(p, b, r));
    const ClosestHit hv = index.closest(p, r), he = exact->closest(p, r);
    ASSERT_EQ(hv.found(), he.found());
    if (he.found()) {
      EXPECT_EQ(hv.distance, he.distance);
    }
    const ClosestHit sv = index.segment_closest(p, b, r, nullptr), se = exact->segment_closest(p, b, r, nullptr);
    ASSERT_EQ(sv.found(), se.found());
    if (se.found()) {
      EXPECT_EQ(sv.distance, se.distance);
    }
  }
  // The map decides a good share of these queries (most points are well clear of the parts).
  const VoxelFirstCounts n = index.counts();
  EXPECT_GT(n.decided, n.exact / 4) << "decided " << n.decided << ", exact " << n.exact;
  // Without a map: the same answers, every query counted as exact.
  const VoxelFirstIndex plain(*exact, nullptr);
  EXPECT_EQ(plain.distance_lower_bound(Vec3(1e3, 1e3, 1e3)), 0.0);
  EXPECT_EQ(plain.any_within(Vec3(1e3, 1e3, 1e3), 1.0), false);
  EXPECT_EQ(plain.inside(Vec3(3, -2, 1), nullptr), exact->inside(Vec3(3, -2, 1), nullptr));
  EXPECT_EQ(plain.counts().decided, 0u);
  EXPECT_EQ(plain.counts().exact, 2u);
}

INSTANTIATE_TEST_SUITE_P(Scenes, VoxelFirst,
                         ::testing::Values(Case{"mixed", 1.0, true}, Case{"mixed", 2.5, false},
                                           Case{"overlapping", 0.8, false}, Case{"overlapping", 2.0, true}),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return std::string(param.param.scene) + (param.param.refine ? "Refined" : "Edt") +
                                  std::to_string(param.index);
                         });

}  // namespace
}  // namespace loom
