#pragma once
// Labelled meshes for the tests of mesh_intersection and merge_face_vertices: a box with
// one label per side, and the closedness test their results must pass.

#include "index/index_test_meshes.hpp"
#include "index/simplify/mesh_boolean.hpp"

#include <gtest/gtest.h>

namespace loom::testmesh {

/// A box with one label per side (its two triangles).
inline FacedMesh labelled_box(const Vec3& lo, const Vec3& hi) {
  FacedMesh f;
  f.mesh = box(lo, hi);
  for (std::size_t t = 0; t < f.mesh.triangles.size(); ++t) f.face.push_back(static_cast<int>(t / 2));
  f.faces = 6;
  return f;
}

/// True if m, its equal vertices welded, has no boundary and no misoriented edge.
inline bool closed_and_oriented(const Mesh& m) {
  Mesh w = m;
  weld_identical_vertices(w);
  const MeshTopology t = analyse_topology(w);
  return t.boundary_edges == 0 && t.misoriented_edges == 0;
}

}  // namespace loom::testmesh
