#include "core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

namespace loom {

AABB Mesh::bounds() const {
  AABB box;
  if (triangles.empty()) {
    for (const auto& v : vertices) box.extend(v);
    return box;
  }
  for (const auto& f : triangles)
    for (auto i : f) box.extend(vertices[i]);
  return box;
}

double Mesh::area() const {
  double a = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto c = corners(t);
    a += 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).norm();
  }
  return a;
}

double Mesh::signed_volume() const {
  // Re-centre on the bounding box so that the sum does not lose digits far from the origin.
  const Vec3 o = bounds().center();
  double v = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto c = corners(t);
    v += (c[0] - o).dot((c[1] - o).cross(c[2] - o));
  }
  return v / 6.0;
}

void Mesh::transform(const Eigen::Affine3d& m) {
  for (auto& v : vertices) v = m * v;
  if (m.linear().determinant() < 0.0)
    for (auto& f : triangles) std::swap(f[1], f[2]);
}

void Mesh::append(const Mesh& other) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  for (const auto& f : other.triangles) triangles.push_back({f[0] + base, f[1] + base, f[2] + base});
}

namespace {
struct Vec3Hash {
  std::size_t operator()(const Vec3& v) const noexcept {
    std::size_t h = 1469598103934665603ull;
    for (int i = 0; i < 3; ++i) {
      double d = v[i] == 0.0 ? 0.0 : v[i];  // -0 and +0 weld together
      std::uint64_t bits;
      std::memcpy(&bits, &d, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
    }
    return h;
  }
};
struct Vec3Eq {
  bool operator()(const Vec3& a, const Vec3& b) const noexcept { return a == b; }
};
}  // namespace

std::size_t weld_identical_vertices(Mesh& mesh) {
  std::unordered_map<Vec3, std::uint32_t, Vec3Hash, Vec3Eq> first;
  first.reserve(mesh.vertices.size());
  std::vector<std::uint32_t> remap(mesh.vertices.size());
  std::vector<Vec3> kept;
  kept.reserve(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    auto [it, inserted] = first.emplace(mesh.vertices[i], static_cast<std::uint32_t>(kept.size()));
    if (inserted) kept.push_back(mesh.vertices[i]);
    remap[i] = it->second;
  }
  const std::size_t removed = mesh.vertices.size() - kept.size();
  mesh.vertices = std::move(kept);
  std::vector<std::array<std::uint32_t, 3>> tris;
  tris.reserve(mesh.triangles.size());
  for (auto f : mesh.triangles) {
    for (auto& i : f) i = remap[i];
    if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) tris.push_back(f);
  }
  mesh.triangles = std::move(tris);
  return removed;
}

MeshTopology analyse_topology(const Mesh& mesh) {
  MeshTopology topo;
  // Each triangle edge as (a << 32 | b with a < b, backward), sorted: the uses of one
  // undirected edge form a run (a sort is faster than a hash map of the edges).
  std::vector<std::pair<std::uint64_t, bool>> uses;
  uses.reserve(mesh.triangles.size() * 3);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) {
      ++topo.degenerate_triangles;
      continue;
    }
    const auto c = mesh.corners(t);
    if ((c[1] - c[0]).cross(c[2] - c[0]).squaredNorm() == 0.0) ++topo.degenerate_triangles;
    for (int k = 0; k < 3; ++k) {
      std::uint64_t a = f[k], b = f[(k + 1) % 3];
      const bool backward = b < a;
      if (backward) std::swap(a, b);
      uses.emplace_back((a << 32) | b, backward);
    }
  }
  std::sort(uses.begin(), uses.end());
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    int forward = 0;
    for (; j < uses.size() && uses[j].first == uses[i].first; ++j) forward += uses[j].second ? 0 : 1;
    const std::size_t n = j - i;
    if (n == 1) ++topo.boundary_edges;
    else if (n > 2) ++topo.nonmanifold_edges;
    else if (forward != 1) ++topo.misoriented_edges;
    i = j;
  }
  topo.closed = !mesh.triangles.empty() && topo.boundary_edges == 0 && topo.nonmanifold_edges == 0 &&
                topo.misoriented_edges == 0;
  return topo;
}

bool orient_outward(Mesh& mesh, const MeshTopology& topo) {
  if (!topo.closed || mesh.signed_volume() >= 0.0) return false;
  for (auto& f : mesh.triangles) std::swap(f[1], f[2]);
  return true;
}

long first_non_finite_vertex(const Mesh& mesh) {
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite()) return static_cast<long>(i);
  return -1;
}

}  // namespace loom
