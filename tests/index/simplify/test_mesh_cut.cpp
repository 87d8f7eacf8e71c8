// cut_mesh against closed forms: the halves tile the surface (areas add up, the welded
// union is closed again), each half lies on its side, and the cut edges are shared bit for
// bit — on spheres, tori and boxes cut by random planes, and by planes through vertices.
#include "index/simplify/mesh_cut.hpp"

#include "index/index_test_meshes.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

using namespace loom;

namespace {

/// Checks one cut; `what` names the case in failures (with the plane at full precision).
void check_cut(const Mesh& m, int axis, double at, const std::string& what) {
  const std::string at_s = what + " cut at x[" + std::to_string(axis) + "] = " + full_precision(at);
  const MeshHalves h = cut_mesh(m, axis, at);
  EXPECT_NEAR(h.below.area() + h.above.area(), m.area(), 1e-9 * m.area()) << at_s;
  for (const auto& f : h.below.triangles)
    for (auto i : f) ASSERT_LE(h.below.vertices[i][axis], at) << at_s;
  for (const auto& f : h.above.triangles)
    for (auto i : f) ASSERT_GE(h.above.vertices[i][axis], at) << at_s;
  Mesh both = h.below;
  both.append(h.above);
  weld_identical_vertices(both);
  const MeshTopology t = analyse_topology(both);
  EXPECT_EQ(t.boundary_edges, 0u) << at_s;
  EXPECT_EQ(t.misoriented_edges, 0u) << at_s;
  EXPECT_NEAR(both.signed_volume(), m.signed_volume(), 1e-9 * std::abs(m.signed_volume())) << at_s;
}

}  // namespace

TEST(MeshCut, HalvesTileTheSurfaceOnRandomPlanes) {
  const std::vector<std::pair<std::string, Mesh>> meshes = {
      {"sphere", testmesh::uv_sphere({1, 2, 3}, 5.0, 24, 12)},
      {"torus", testmesh::torus({0, 0, 0}, 6.0, 2.0, 32, 16)},
      {"box", testmesh::box({-1, -2, -3}, {4, 5, 6})}};
  std::mt19937_64 rng(7);
  for (const auto& [name, m] : meshes) {
    const AABB b = m.bounds();
    for (int k = 0; k < 30; ++k) {
      const int axis = static_cast<int>(rng() % 3);
      std::uniform_real_distribution<double> u(b.min[axis], b.max[axis]);
      check_cut(m, axis, u(rng), name);
    }
  }
}

TEST(MeshCut, PlanesThroughVerticesAndFaces) {
  // A plane within rounding of a ring of the sphere's vertices, one in a box face, one outside.
  const Mesh s = testmesh::uv_sphere({0, 0, 0}, 5.0, 24, 12);
  check_cut(s, 2, 0.0, "sphere equator");
  const Mesh b = testmesh::box({0, 0, 0}, {2, 2, 2});
  check_cut(b, 0, 0.0, "box face");
  const MeshHalves in_face = cut_mesh(b, 0, 0.0);
  EXPECT_EQ(in_face.below.triangle_count(), 2u);  // the face in the plane goes below
  EXPECT_EQ(in_face.above.triangle_count(), 10u);
  const MeshHalves outside = cut_mesh(b, 1, 5.0);
  EXPECT_EQ(outside.below.triangle_count(), 12u);
  EXPECT_TRUE(outside.above.empty());
}
