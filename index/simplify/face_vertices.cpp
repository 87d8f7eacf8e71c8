#include "index/simplify/face_vertices.hpp"

#include "index/simplify/ring_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace loom {
namespace {

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; }

double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

/// Douglas–Peucker on chain[i..j] (the ends kept): clears `removable` of the vertices that
/// must stay so that every removed one lies within tol of the segment between kept ones.
void keep_far_vertices(const std::vector<Vec3>& v, const std::vector<std::uint32_t>& chain, std::size_t i,
                       std::size_t j, double tol, std::vector<char>& removable) {
  if (j <= i + 1) return;
  double worst = -1.0;
  std::size_t at = i;
  for (std::size_t k = i + 1; k < j; ++k) {
    const double d = segment_distance(v[chain[k]], v[chain[i]], v[chain[j]]);
    if (d > worst) {
      worst = d;
      at = k;
    }
  }
  if (worst <= tol) return;
  removable[chain[at]] = 0;
  keep_far_vertices(v, chain, i, at, tol, removable);
  keep_far_vertices(v, chain, at, j, tol, removable);
}

std::runtime_error failure(const std::string& what) { return std::runtime_error("merging face vertices: " + what); }

}  // namespace

FaceVertexMerge merge_face_vertices(FacedMesh& m, double tol) {
  const std::vector<Vec3>& V = m.mesh.vertices;
  const auto& T = m.mesh.triangles;
  const std::size_t nv = V.size(), nt = T.size();
  if (m.face.size() != nt) throw failure("one label per triangle is needed");

  // Each directed edge belongs to one triangle; its twin to the neighbour across it.
  std::unordered_map<std::uint64_t, std::uint32_t> tri_of;
  tri_of.reserve(3 * nt);
  for (std::uint32_t t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e)
      if (!tri_of.emplace(edge_key(T[t][e], T[t][(e + 1) % 3]), t).second)
        throw failure("a directed edge is in two triangles (not an oriented 2-manifold)");
  auto across = [&](std::uint32_t a, std::uint32_t b) {
    const auto it = tri_of.find(edge_key(b, a));
    if (it == tri_of.end()) throw failure("an edge has one triangle (the mesh is not closed)");
    return it->second;
  };

  // Faces: triangles joined across edges with one label.
  const std::vector<std::size_t> face_id = labelled_face_ids(m.mesh, m.face);
  // Per vertex: its labels (two tracked, more flagged) and its neighbours across crease
  // edges (edges between two labels).
  std::vector<int> label0(nv, -1), label1(nv, -1);
  std::vector<char> many_labels(nv, 0);
  std::vector<std::vector<std::uint32_t>> crease(nv);
  for (std::uint32_t t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = T[t][e], b = T[t][(e + 1) % 3];
      const int l = m.face[t];
      if (label0[a] == -1 || label0[a] == l) label0[a] = l;
      else if (label1[a] == -1 || label1[a] == l) label1[a] = l;
      else many_labels[a] = 1;
      if (a > b || m.face[across(a, b)] == l) continue;  // each undirected crease edge once
      crease[a].push_back(b);
      crease[b].push_back(a);
    }

  // Candidates: inside one face, or on exactly one crease line between two faces.
  std::vector<char> candidate(nv, 0), interior(nv, 0);
  for (std::uint32_t v = 0; v < nv; ++v) {
    if (label0[v] == -1 || many_labels[v]) continue;
    if (label1[v] == -1) {
      candidate[v] = interior[v] = crease[v].empty() ? 1 : 0;
    } else {
      candidate[v] = crease[v].size() == 2 ? 1 : 0;
    }
  }
  std::vector<std::vector<std::uint32_t>> members(nt);
  for (std::uint32_t t = 0; t < nt; ++t) members[face_id[t]].push_back(t);
  std::vector<char> removable(nv, 0), redo(nt, 0);
  for (std::uint32_t v = 0; v < nv; ++v) removable[v] = candidate[v];
  // Crease candidates in chains between kept vertices: Douglas–Peucker along each.
  // walk(v, nb): the vertices from v's neighbour nb along the crease line up to the first
  // kept one (included), or back to v (a closed chain: v is the last entry).
  auto walk = [&](std::uint32_t v, std::uint32_t nb) {
    std::vector<std::uint32_t> path{nb};
    std::uint32_t prev = v, cur = nb;
    while (cur != v && removable[cur] && !interior[cur]) {
      const std::uint32_t next = crease[cur][0] == prev ? crease[cur][1] : crease[cur][0];
      prev = cur;
      cur = next;
      path.push_back(cur);
    }
    return path;
  };
  std::vector<char> seen(nv, 0);
  for (std::uint32_t v = 0; v < nv; ++v) {
    if (!removable[v] || interior[v] || seen[v]) continue;
    std::vector<std::uint32_t> chain;
    const std::vector<std::uint32_t> one = walk(v, crease[v][0]);
    if (one.back() == v) {
      removable[v] = 0;  // a closed chain: v is kept, as both its ends
      chain.push_back(v);
      chain.insert(chain.end(), one.begin(), one.end());
    } else {
      const std::vector<std::uint32_t> other = walk(v, crease[v][1]);
      chain.assign(other.rbegin(), other.rend());
      chain.push_back(v);
      chain.insert(chain.end(), one.begin(), one.end());
    }
    for (std::uint32_t k : chain) seen[k] = 1;
    keep_far_vertices(V, chain, 0, chain.size() - 1, tol, removable);
  }
  for (std::uint32_t t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e)
      if (removable[T[t][e]]) redo[face_id[t]] = 1;

  FaceVertexMerge result;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (removable[v]) ++(interior[v] ? result.interior : result.crease);
  if (result.interior + result.crease == 0) return result;

  std::vector<std::array<std::uint32_t, 3>> tris;
  std::vector<int> labels;
  tris.reserve(nt);
  labels.reserve(nt);
  for (std::uint32_t t = 0; t < nt; ++t) {
    const std::size_t r = face_id[t];
    if (!redo[r]) {
      tris.push_back(T[t]);
      labels.push_back(m.face[t]);
      continue;
    }
    if (members[r].front() != t) continue;  // each face once, at its first triangle
    ++result.faces_retriangulated;
    const std::vector<std::uint32_t>& face = members[r];
    // Plane: Newell normal (sum of the triangles' area vectors) through the centroid.
    Vec3 n = Vec3::Zero(), c = Vec3::Zero();
    double area = 0.0;
    for (std::uint32_t f : face) {
      const Vec3 w = (V[T[f][1]] - V[T[f][0]]).cross(V[T[f][2]] - V[T[f][0]]);
      n += w;
      area += 0.5 * w.norm();
      c += V[T[f][0]] + V[T[f][1]] + V[T[f][2]];
    }
    c /= 3.0 * static_cast<double>(face.size());
    if (!(n.norm() > 0.0)) throw failure("a face has no area");
    n.normalize();
    for (std::uint32_t f : face)
      for (std::uint32_t k : T[f])
        if (std::abs((V[k] - c).dot(n)) > tol) throw failure("a face is not planar within the tolerance");
    // Boundary: the directed edges whose neighbour is in another face. From each kept
    // vertex the boundary runs through removed vertices (each has one boundary edge out of
    // it in this face: it lies on one crease line or inside) to the next kept one, and that
    // chord is a constraint of the triangulation. A boundary that touches itself (a vertex
    // used twice, or corefinement's copies of a vertex at one point, which become one
    // point) needs no loops: the triangulation takes the region from its constraints.
    Vec3 u = n.unitOrthogonal();
    const Vec3 w = n.cross(u);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;
    std::unordered_map<std::uint32_t, std::uint32_t> out_of;  // removed vertex → next on the boundary
    double perimeter = 0.0;
    for (std::uint32_t f : face)
      for (int e = 0; e < 3; ++e) {
        const std::uint32_t a = T[f][e], b = T[f][(e + 1) % 3];
        if (face_id[across(a, b)] == r) continue;
        boundary.emplace_back(a, b);
        perimeter += (V[b] - V[a]).norm();
        if (removable[a] && !out_of.emplace(a, b).second) throw failure("a face's boundary passes a removed vertex twice");
      }
    std::vector<Vec2> points;
    std::vector<std::uint32_t> global;
    std::map<std::pair<double, double>, int> index_at;  // one index per point of the plane
    auto index_of = [&](std::uint32_t g) {
      const Vec2 q((V[g] - c).dot(u), (V[g] - c).dot(w));
      const auto [it, added] = index_at.emplace(std::make_pair(q.x(), q.y()), static_cast<int>(points.size()));
      if (added) {
        points.push_back(q);
        global.push_back(g);
      }
      return it->second;
    };
    std::vector<std::vector<int>> chords;  // chords as two-point rings, in boundary order
    for (const auto& [a, b] : boundary) {
      if (removable[a]) continue;
      std::uint32_t z = b;
      for (std::size_t steps = 0; removable[z]; ++steps) {
        const auto it = out_of.find(z);
        if (it == out_of.end() || steps > boundary.size()) throw failure("a face boundary is not closed");
        z = it->second;
      }
      const int ia = index_of(a), iz = index_of(z);
      if (ia != iz) chords.push_back({ia, iz});
    }
    std::vector<std::array<int, 3>> cap;
    try {
      cap = triangulate_rings(points, chords);
    } catch (const std::runtime_error&) {
      throw failure("a face's boundary loops cross in its plane");
    }
    double new_area = 0.0;
    for (const auto& [a, b, d] : cap) {
      const Vec3 x = V[global[a]], y = V[global[b]], z = V[global[d]];
      const Vec3 wv = (y - x).cross(z - x);
      if (!(wv.dot(n) > 0.0)) throw failure("a new triangle of a face is flat or turned over");
      new_area += 0.5 * wv.norm();
      tris.push_back({global[a], global[b], global[d]});
      labels.push_back(m.face[t]);
    }
    if (std::abs(new_area - area) > tol * perimeter + 1e-9 * area)
      throw failure("a face's new triangles cover " + std::to_string(new_area) + " of its area " + std::to_string(area));
  }

  // Drop the vertices no triangle uses; the rest keep their order.
  std::vector<std::uint32_t> remap(nv, UINT32_MAX);
  for (const auto& f : tris)
    for (std::uint32_t k : f) remap[k] = 0;
  Mesh out;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (remap[v] == 0) {
      remap[v] = static_cast<std::uint32_t>(out.vertices.size());
      out.vertices.push_back(V[v]);
    }
  for (auto f : tris) {
    for (auto& k : f) k = remap[k];
    out.triangles.push_back(f);
  }
  m.mesh = std::move(out);
  m.face = std::move(labels);
  m.faces = labelled_faces(m.mesh, m.face);
  return result;
}

}  // namespace loom
