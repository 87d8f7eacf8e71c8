// Mesh model: welding, closedness, orientation, volume against closed forms.
#include "core/mesh.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

namespace loom {
namespace {

/// Axis-aligned box as 12 triangles with unwelded corners (as an STL writer emits them).
Mesh unwelded_box(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  const Vec3 c[8] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), lo.z()},
                     {lo.x(), hi.y(), lo.z()}, {lo.x(), lo.y(), hi.z()}, {hi.x(), lo.y(), hi.z()},
                     {hi.x(), hi.y(), hi.z()}, {lo.x(), hi.y(), hi.z()}};
  const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                        {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  for (const auto& t : f) {
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (int k = 0; k < 3; ++k) m.vertices.push_back(c[t[k]]);
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

TEST(Mesh, WeldMakesUnweldedBoxClosed) {
  Mesh m = unwelded_box({0, 0, 0}, {1, 2, 3});
  EXPECT_FALSE(analyse_topology(m).closed);
  EXPECT_EQ(weld_identical_vertices(m), 36u - 8u);
  const auto topo = analyse_topology(m);
  EXPECT_TRUE(topo.closed);
  EXPECT_EQ(topo.boundary_edges, 0u);
  EXPECT_NEAR(m.signed_volume(), 6.0, 1e-12);
  EXPECT_NEAR(m.area(), 2 * (2 + 6 + 3), 1e-12);
}

TEST(Mesh, InsideOutBoxIsFlipped) {
  Mesh m = unwelded_box({0, 0, 0}, {1, 1, 1});
  weld_identical_vertices(m);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  const auto topo = analyse_topology(m);
  ASSERT_TRUE(topo.closed);
  EXPECT_LT(m.signed_volume(), 0);
  EXPECT_TRUE(orient_outward(m, topo));
  EXPECT_NEAR(m.signed_volume(), 1.0, 1e-12);
}

TEST(Mesh, OpenMeshHasBoundary) {
  Mesh m = unwelded_box({0, 0, 0}, {1, 1, 1});
  weld_identical_vertices(m);
  m.triangles.pop_back();
  const auto topo = analyse_topology(m);
  EXPECT_FALSE(topo.closed);
  EXPECT_EQ(topo.boundary_edges, 3u);
}

TEST(Mesh, MisorientedTriangleIsDetected) {
  Mesh m = unwelded_box({0, 0, 0}, {1, 1, 1});
  weld_identical_vertices(m);
  std::swap(m.triangles[0][1], m.triangles[0][2]);
  const auto topo = analyse_topology(m);
  EXPECT_FALSE(topo.closed);
  EXPECT_EQ(topo.misoriented_edges, 3u);
}

TEST(Mesh, DegenerateTrianglesAreDroppedByWeld) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 1, 3}};
  weld_identical_vertices(m);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.vertices.size(), 3u);
}

TEST(Mesh, EmptyMesh) {
  Mesh m;
  EXPECT_TRUE(m.empty());
  EXPECT_TRUE(m.bounds().empty());
  EXPECT_FALSE(analyse_topology(m).closed);
  EXPECT_EQ(m.signed_volume(), 0.0);
}

TEST(Mesh, NonFiniteVertexFound) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, std::nan(""), 0}};
  EXPECT_EQ(first_non_finite_vertex(m), 1);
}

TEST(Mesh, MirrorTransformKeepsOutwardOrientation) {
  Mesh m = unwelded_box({0, 0, 0}, {1, 1, 1});
  weld_identical_vertices(m);
  Eigen::Affine3d mirror = Eigen::Affine3d::Identity();
  mirror.linear()(0, 0) = -1;
  m.transform(mirror);
  EXPECT_NEAR(m.signed_volume(), 1.0, 1e-12);
}

// Volume is invariant under rigid motions and scales with s³, far from the origin too.
RC_GTEST_PROP(MeshProps, VolumeUnderSimilarity, ()) {
  const double s = *rc::gen::inRange(1, 1000) / 10.0;
  const double tx = *rc::gen::inRange(-1000000, 1000000) * 1.0;
  const double ang = *rc::gen::inRange(0, 628) / 100.0;
  Mesh m = unwelded_box({0, 0, 0}, {1, 2, 3});
  weld_identical_vertices(m);
  Eigen::Affine3d xf = Eigen::Affine3d::Identity();
  xf.linear() = Eigen::AngleAxisd(ang, Vec3(1, 2, 3).normalized()).toRotationMatrix() * s;
  xf.translation() = Vec3(tx, -tx, 0.5 * tx);
  m.transform(xf);
  RC_ASSERT(std::abs(m.signed_volume() - 6.0 * s * s * s) <= 1e-9 * 6.0 * s * s * s);
  RC_ASSERT(analyse_topology(m).closed);
}

}  // namespace
}  // namespace loom
