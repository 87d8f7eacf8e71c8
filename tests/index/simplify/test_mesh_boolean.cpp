// Exact mesh intersection (CGAL corefinement, α-SIM's general Boolean) against
// closed forms: boxes whose faces coincide (the degenerate case corefinement must get
// right), a box turned 45° (an octagonal prism), spheres (volume against the inscribed
// polyhedra), and refusals.
#include "index/simplify/mesh_boolean.hpp"

#include "index/simplify/faced_meshes.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

using namespace loom;
using testmesh::labelled_box;

namespace {

/// A mesh with one label per triangle.
FacedMesh each_triangle_a_face(Mesh m) {
  FacedMesh f;
  f.face.resize(m.triangles.size());
  for (std::size_t t = 0; t < f.face.size(); ++t) f.face[t] = static_cast<int>(t);
  f.faces = static_cast<int>(m.triangles.size());
  f.mesh = std::move(m);
  return f;
}

void expect_closed(const Mesh& m) {
  EXPECT_TRUE(testmesh::closed_and_oriented(m));
  EXPECT_GT(m.signed_volume(), 0.0) << "outward orientation";
}

}  // namespace

TEST(MeshBoolean, OverlappingBoxesGiveTheirCommonBox) {
  const FacedMesh r = mesh_intersection(labelled_box({0, 0, 0}, {4, 3, 2}), labelled_box({1, -1, 1}, {6, 2, 5}));
  expect_closed(r.mesh);
  ASSERT_EQ(r.face.size(), r.mesh.triangles.size());
  EXPECT_NEAR(r.mesh.signed_volume(), 3.0 * 2.0 * 1.0, 1e-12);
  EXPECT_EQ(r.faces, 6);
  // Corefinement keeps the split points of the inputs' triangles (Steiner vertices on the
  // faces and edges): every vertex is on the common box's surface, exactly.
  for (const Vec3& v : r.mesh.vertices) {
    EXPECT_TRUE(v.x() >= 1 && v.x() <= 4 && v.y() >= 0 && v.y() <= 2 && v.z() >= 1 && v.z() <= 2) << v.transpose();
    EXPECT_TRUE(v.x() == 1 || v.x() == 4 || v.y() == 0 || v.y() == 2 || v.z() == 1 || v.z() == 2) << v.transpose();
  }
}

TEST(MeshBoolean, BoxesSharingFacePlanes) {
  // Same y and z range: four face planes coincide pairwise, and the result has 6 faces.
  const FacedMesh r = mesh_intersection(labelled_box({0, 0, 0}, {2, 2, 2}), labelled_box({1, 0, 0}, {3, 2, 2}));
  expect_closed(r.mesh);
  EXPECT_NEAR(r.mesh.signed_volume(), 4.0, 1e-12);
  EXPECT_EQ(r.faces, 6);
  // A box inside another, touching it on three faces: itself.
  const FacedMesh s = mesh_intersection(labelled_box({0, 0, 0}, {5, 5, 5}), labelled_box({0, 0, 0}, {1, 2, 3}));
  EXPECT_NEAR(s.mesh.signed_volume(), 6.0, 1e-12);
  EXPECT_EQ(s.faces, 6);
}

TEST(MeshBoolean, BoxTurnedByFortyFiveDegreesGivesAnOctagonalPrism) {
  // The square [-1, 1]² ∩ the same square turned 45° is the regular octagon of inradius 1:
  // area 8·tan(22.5°) = 8·(√2 − 1), times the height 2.
  FacedMesh turned = labelled_box({-1, -1, -2}, {1, 1, 2});
  const Eigen::AngleAxisd rot(M_PI / 4.0, Vec3::UnitZ());
  for (Vec3& v : turned.mesh.vertices) v = rot * v;
  const FacedMesh r = mesh_intersection(labelled_box({-1, -1, -1}, {1, 1, 1}), turned);
  expect_closed(r.mesh);
  EXPECT_NEAR(r.mesh.signed_volume(), 8.0 * (std::sqrt(2.0) - 1.0) * 2.0, 1e-12);
  EXPECT_EQ(r.faces, 10);  // eight sides, two caps
}

TEST(MeshBoolean, SphereCutByABoxKeepsTheSphereInside) {
  // A tessellated sphere of radius 1 inside a box that clips nothing: the sphere itself,
  // vertex for vertex; clipped by the half-space box z ≥ 0 at its equator ring, its upper
  // half (the equator ring's vertices are on the cut plane).
  Mesh uv = testmesh::uv_sphere(Vec3::Zero(), 1.0, 24, 12);
  for (Vec3& v : uv.vertices)
    if (std::abs(v.z()) < 1e-15) v.z() = 0.0;  // the equator ring exactly at z = 0 (cos(π/2) is not 0 in double)
  const FacedMesh sphere = each_triangle_a_face(uv);
  const FacedMesh all = mesh_intersection(sphere, labelled_box({-2, -2, -2}, {2, 2, 2}));
  EXPECT_NEAR(all.mesh.signed_volume(), sphere.mesh.signed_volume(), 1e-12);
  EXPECT_EQ(all.mesh.triangle_count(), sphere.mesh.triangle_count());
  EXPECT_EQ(all.faces, sphere.faces);
  const FacedMesh upper = mesh_intersection(sphere, labelled_box({-2, -2, 0}, {2, 2, 2}));
  expect_closed(upper.mesh);
  EXPECT_NEAR(upper.mesh.signed_volume(), 0.5 * sphere.mesh.signed_volume(), 1e-12);
  // The upper half's triangles, each its own face, and the cut: one face (the equator disc).
  EXPECT_EQ(upper.faces, sphere.faces / 2 + 1);
  for (const Vec3& v : upper.mesh.vertices) EXPECT_GE(v.z(), -1e-15) << v.transpose();
}

TEST(MeshBoolean, RefusesEmptyOpenAndTouchingInputs) {
  EXPECT_THROW(mesh_intersection(labelled_box({0, 0, 0}, {1, 1, 1}), labelled_box({2, 2, 2}, {3, 3, 3})), std::runtime_error);
  // Two boxes touching along an edge (x = y = 1): not a 2-manifold, which CGAL's Booleans
  // do not take (the caller uses OpenCASCADE there).
  FacedMesh touching = labelled_box({0, 0, 0}, {1, 1, 1});
  {
    const FacedMesh other = labelled_box({1, 1, 0}, {2, 2, 1});
    const auto base = static_cast<std::uint32_t>(touching.mesh.vertices.size());
    touching.mesh.vertices.insert(touching.mesh.vertices.end(), other.mesh.vertices.begin(), other.mesh.vertices.end());
    for (auto t : other.mesh.triangles) touching.mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    for (int l : other.face) touching.face.push_back(l + 6);
  }
  // As two shells (the edge's vertices twice: they touch, a self-intersection for CGAL)
  // and welded (one edge of four triangles).
  EXPECT_THROW(mesh_intersection(touching, labelled_box({0, 0, 0}, {2, 2, 2})), std::runtime_error);
  ASSERT_EQ(weld_identical_vertices(touching.mesh), 2u);
  EXPECT_THROW(mesh_intersection(touching, labelled_box({0, 0, 0}, {2, 2, 2})), std::runtime_error);
  FacedMesh unlabelled = labelled_box({0, 0, 0}, {1, 1, 1});
  unlabelled.face.pop_back();
  EXPECT_THROW(mesh_intersection(unlabelled, labelled_box({0, 0, 0}, {2, 2, 2})), std::runtime_error);
  FacedMesh open = labelled_box({0, 0, 0}, {1, 1, 1});
  open.mesh.triangles.pop_back();
  open.face.pop_back();
  EXPECT_THROW(mesh_intersection(open, labelled_box({0, 0, 0}, {2, 2, 2})), std::runtime_error);
}

RC_GTEST_PROP(MeshBooleanProperty, BoxesOnASmallGridGiveTheProductOfTheirOverlaps, ()) {
  // Corners on a 0..4 grid: faces coincide, edges overlap, boxes touch — the degenerate
  // configurations. A positive overlap is a box (6 faces, its volume); none or a flat one
  // is refused as empty.
  auto corner = [] { return *rc::gen::inRange(0, 5); };
  Vec3 lo[2], hi[2];
  for (int b = 0; b < 2; ++b)
    for (int k = 0; k < 3; ++k) {
      int p = corner(), q = corner();
      if (p == q) q = p == 4 ? 3 : p + 1;
      lo[b][k] = std::min(p, q);
      hi[b][k] = std::max(p, q);
    }
  double vol = 1.0;
  for (int k = 0; k < 3; ++k) vol *= std::max(0.0, std::min(hi[0][k], hi[1][k]) - std::max(lo[0][k], lo[1][k]));
  if (vol == 0.0) {
    RC_ASSERT_THROWS_AS(mesh_intersection(labelled_box(lo[0], hi[0]), labelled_box(lo[1], hi[1])), std::runtime_error);
    return;
  }
  const FacedMesh r = mesh_intersection(labelled_box(lo[0], hi[0]), labelled_box(lo[1], hi[1]));
  RC_ASSERT(std::abs(r.mesh.signed_volume() - vol) <= 1e-12 * vol);
  RC_ASSERT(r.faces == 6);
  RC_ASSERT(testmesh::closed_and_oriented(r.mesh));
}
