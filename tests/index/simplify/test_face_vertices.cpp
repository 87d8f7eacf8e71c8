// Removing the vertices a polyhedral mesh does not need (α-SIM after exact corefinement):
// closed forms (subdivided boxes), the tolerance along a crease, refusals, and
// corefined random solids against their own volume and corners.
#include "index/simplify/face_vertices.hpp"

#include "index/simplify/faced_meshes.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <set>
#include <stdexcept>
#include <tuple>

using namespace loom;
using testmesh::labelled_box;

namespace {

/// Splits triangle t at point p (three triangles, same label).
void split_triangle(FacedMesh& f, std::size_t t, const Vec3& p) {
  const auto [a, b, c] = f.mesh.triangles[t];
  const auto v = static_cast<std::uint32_t>(f.mesh.vertices.size());
  f.mesh.vertices.push_back(p);
  f.mesh.triangles[t] = {a, b, v};
  f.mesh.triangles.push_back({b, c, v});
  f.mesh.triangles.push_back({c, a, v});
  f.face.push_back(f.face[t]);
  f.face.push_back(f.face[t]);
}

/// Splits the edge (a, b) at point p in both triangles that hold it.
void split_edge(FacedMesh& f, std::uint32_t a, std::uint32_t b, const Vec3& p) {
  const auto v = static_cast<std::uint32_t>(f.mesh.vertices.size());
  f.mesh.vertices.push_back(p);
  const std::size_t n = f.mesh.triangles.size();
  for (std::size_t t = 0; t < n; ++t) {
    auto& tri = f.mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t x = tri[e], y = tri[(e + 1) % 3], z = tri[(e + 2) % 3];
      if ((x == a && y == b) || (x == b && y == a)) {
        tri = {x, v, z};
        f.mesh.triangles.push_back({v, y, z});
        f.face.push_back(f.face[t]);
        break;
      }
    }
  }
}

int vertex_index(const FacedMesh& f, const Vec3& p) {
  for (std::size_t i = 0; i < f.mesh.vertices.size(); ++i)
    if (f.mesh.vertices[i] == p) return static_cast<int>(i);
  return -1;
}

void expect_closed(const Mesh& m) { EXPECT_TRUE(testmesh::closed_and_oriented(m)); }

}  // namespace

TEST(FaceVertices, SubdividedBoxIsItsEightCorners) {
  FacedMesh f = labelled_box({0, 0, 0}, {4, 2, 1});
  split_triangle(f, 0, Vec3(1.0, 1.0, 0.0));  // inside the bottom face
  split_edge(f, static_cast<std::uint32_t>(vertex_index(f, {0, 0, 0})),
             static_cast<std::uint32_t>(vertex_index(f, {4, 0, 0})), Vec3(1.5, 0, 0));  // on an edge
  split_edge(f, static_cast<std::uint32_t>(vertex_index(f, {0, 0, 0})), static_cast<std::uint32_t>(vertex_index(f, {1.5, 0, 0})),
             Vec3(0.25, 0, 0));  // a chain of two on that edge
  ASSERT_EQ(f.mesh.vertices.size(), 11u);
  const double volume = f.mesh.signed_volume();
  const FaceVertexMerge r = merge_face_vertices(f, 1e-9);
  EXPECT_EQ(r.interior, 1u);
  EXPECT_EQ(r.crease, 2u);
  EXPECT_EQ(f.mesh.vertices.size(), 8u);
  EXPECT_EQ(f.mesh.triangles.size(), 12u);
  EXPECT_EQ(f.faces, 6);
  EXPECT_NEAR(f.mesh.signed_volume(), volume, 1e-12);
  expect_closed(f.mesh);
}

TEST(FaceVertices, AKinkBeyondTheToleranceStays) {
  // A vertex pushed 1e-3 off the box's edge (the two sides there bend a little): with tol
  // 1e-4 it stays; with tol 1e-2 it goes (the sides are planar within that too).
  for (const double tol : {1e-4, 1e-2}) {
    FacedMesh f = labelled_box({0, 0, 0}, {4, 2, 1});
    split_edge(f, static_cast<std::uint32_t>(vertex_index(f, {0, 0, 0})),
               static_cast<std::uint32_t>(vertex_index(f, {4, 0, 0})), Vec3(2, -1e-3, -1e-3));
    merge_face_vertices(f, tol);
    EXPECT_EQ(f.mesh.vertices.size(), tol < 1e-3 ? 9u : 8u) << tol;
    expect_closed(f.mesh);
  }
}

TEST(FaceVertices, RefusesAnOpenMeshAndLeavesItUnchanged) {
  FacedMesh f = labelled_box({0, 0, 0}, {1, 1, 1});
  split_triangle(f, 0, Vec3(0.25, 0.5, 0.0));
  f.mesh.triangles.pop_back();
  f.face.pop_back();
  const FacedMesh before = f;
  EXPECT_THROW(merge_face_vertices(f, 1e-9), std::runtime_error);
  EXPECT_EQ(f.mesh.triangles, before.mesh.triangles);
  EXPECT_EQ(f.face, before.face);
}

TEST(FaceVertices, NothingToRemoveLeavesTheMeshAsItIs) {
  FacedMesh f = labelled_box({0, 0, 0}, {1, 1, 1});
  const FacedMesh before = f;
  const FaceVertexMerge r = merge_face_vertices(f, 1e-9);
  EXPECT_EQ(r.interior + r.crease, 0u);
  EXPECT_EQ(f.mesh.triangles, before.mesh.triangles);
}

RC_GTEST_PROP(FaceVerticesProperty, CorefinedBoxesKeepTheirVolumeAndOnlyTheirCorners, ()) {
  // An axis box ∩ a box turned about z by a random angle: a convex prism whose every
  // vertex is a corner (on three or more faces). Corefinement leaves extra points; after
  // merging, every vertex lies on ≥ 3 faces, the volume is the same and the mesh closed.
  const double angle = *rc::gen::inRange(1, 89) * M_PI / 180.0;
  const double h = *rc::gen::inRange(1, 5) * 0.5;
  FacedMesh turned = labelled_box({-1, -1, -h}, {1, 1, h});
  const Eigen::AngleAxisd rot(angle, Vec3::UnitZ());
  for (Vec3& v : turned.mesh.vertices) v = rot * v;
  FacedMesh f = mesh_intersection(labelled_box({-1.1, -0.9, -1}, {1.2, 0.8, 1}), turned);
  const double volume = f.mesh.signed_volume();
  const std::size_t before = f.mesh.vertices.size();
  merge_face_vertices(f, 1e-12);
  RC_ASSERT(std::abs(f.mesh.signed_volume() - volume) <= 1e-12 * volume);
  RC_ASSERT(f.mesh.vertices.size() <= before);
  RC_ASSERT(testmesh::closed_and_oriented(f.mesh));
  std::vector<std::set<int>> labels(f.mesh.vertices.size());
  for (std::size_t k = 0; k < f.mesh.triangles.size(); ++k)
    for (std::uint32_t v : f.mesh.triangles[k]) labels[v].insert(f.face[k]);
  for (const auto& l : labels) RC_ASSERT(l.size() >= 3u);
  // Euler: a convex polyhedron with V corners and F faces has 2V − 4 triangles.
  RC_ASSERT(f.mesh.triangles.size() == 2 * f.mesh.vertices.size() - 4);
}
