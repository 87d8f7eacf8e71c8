#pragma once
// Mesh generators shared by the index tests and bench/bench_index.cpp: closed tessellated
// spheres, boxes and tori (outward orientation), random open soups, and a tiny OBJ reader
// for the shared real data (v/f lines only).

#include "core/mesh.hpp"
#include "core/part.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace loom::testmesh {

constexpr double kPi = 3.14159265358979323846;

/// Closed UV sphere (two pole vertices), outward, ~2·nu·(nv-1) triangles.
inline Mesh uv_sphere(const Vec3& c, double r, int nu, int nv) {
  Mesh m;
  m.vertices.push_back(c + Vec3(0, 0, r));
  for (int j = 1; j < nv; ++j) {
    const double th = kPi * j / nv;
    for (int i = 0; i < nu; ++i) {
      const double ph = 2 * kPi * i / nu;
      m.vertices.push_back(c + r * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
    }
  }
  m.vertices.push_back(c + Vec3(0, 0, -r));
  const auto ring = [&](int j, int i) { return static_cast<std::uint32_t>(1 + (j - 1) * nu + (i % nu)); };
  const auto south = static_cast<std::uint32_t>(m.vertices.size() - 1);
  for (int i = 0; i < nu; ++i) m.triangles.push_back({0u, ring(1, i), ring(1, i + 1)});
  for (int j = 1; j + 1 < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      m.triangles.push_back({ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)});
      m.triangles.push_back({ring(j, i), ring(j + 1, i + 1), ring(j, i + 1)});
    }
  for (int i = 0; i < nu; ++i) m.triangles.push_back({ring(nv - 1, i), south, ring(nv - 1, i + 1)});
  return m;
}

/// Closed axis-aligned box, 12 triangles, outward.
inline Mesh box(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  for (int k = 0; k < 8; ++k)
    m.vertices.push_back(Vec3(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z()));
  const std::uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

/// Closed torus around the z axis through c (major radius R, minor r), outward.
inline Mesh torus(const Vec3& c, double R, double r, int nu, int nv) {
  Mesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      m.vertices.push_back(c + Vec3((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)));
    }
  const auto id = [&](int i, int j) { return static_cast<std::uint32_t>((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// Random open triangle soup: n triangles with corners in [lo, hi], edges up to `size`.
inline Mesh random_soup(std::mt19937_64& rng, int n, const Vec3& lo, const Vec3& hi, double size) {
  std::uniform_real_distribution<double> u01(0.0, 1.0), us(-size, size);
  Mesh m;
  for (int t = 0; t < n; ++t) {
    const Vec3 a = lo + (hi - lo).cwiseProduct(Vec3(u01(rng), u01(rng), u01(rng)));
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.push_back(a);
    m.vertices.push_back(a + Vec3(us(rng), us(rng), us(rng)));
    m.vertices.push_back(a + Vec3(us(rng), us(rng), us(rng)));
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

/// A part around a mesh.
inline Part make_part(const std::string& name, Mesh mesh, bool closed) {
  Part p;
  p.name = name;
  p.mesh = std::move(mesh);
  p.closed = closed;
  return p;
}

/// An axis-aligned box part [lo, hi] with the given role, closed as its topology says.
inline Part box_part(const std::string& name, const Vec3& lo, const Vec3& hi, PartRole role = PartRole::Structure) {
  Part p = make_part(name, box(lo, hi), false);
  p.role = role;
  p.closed = analyse_topology(p.mesh).closed;
  return p;
}

/// Resolution and randomness of mixed_scene().
struct MixedSceneDetail {
  std::uint64_t seed = 42;       ///< seeds the soup
  int soup = 300;                ///< random triangles in the open soup
  int sphere_nu = 24, sphere_nv = 12;
  int torus_nu = 32, torus_nv = 12;
};

/// The index tests' scene, shifted by `offset`: a sphere (r 10), a box and a torus (closed,
/// outward) and an open soup of random triangles spread over [−40, 40]×[−40, 40]×[−20, 20].
inline std::vector<Part> mixed_scene(const Vec3& offset, const MixedSceneDetail& d = {}) {
  std::mt19937_64 rng(d.seed);
  std::vector<Part> parts;
  parts.push_back(make_part("sphere", uv_sphere(offset, 10, d.sphere_nu, d.sphere_nv), true));
  parts.push_back(make_part("box", box(offset + Vec3(15, -5, -5), offset + Vec3(30, 5, 8)), true));
  parts.push_back(make_part("torus", torus(offset + Vec3(-25, 10, 0), 10, 3, d.torus_nu, d.torus_nv), true));
  parts.push_back(
      make_part("soup", random_soup(rng, d.soup, offset + Vec3(-40, -40, -20), offset + Vec3(40, 40, 20), 4), false));
  return parts;
}

/// Closed parts modelled through each other, as real assemblies have them: a box with a
/// keep-out box drawn around it, a sphere overlapping both, a torus through the sphere, a
/// box nested in the inner box, and an open soup (no inside) across them all.
inline std::vector<Part> overlapping_scene() {
  std::mt19937_64 rng(5);
  std::vector<Part> parts;
  parts.push_back(make_part("box", box(Vec3(-10, -10, -10), Vec3(10, 10, 10)), true));
  parts.push_back(make_part("keep-out", box(Vec3(-13, -13, -13), Vec3(13, 13, 13)), true));
  parts.push_back(make_part("sphere", uv_sphere(Vec3(12, 0, 0), 8, 24, 12), true));
  parts.push_back(make_part("torus", torus(Vec3(16, 0, 0), 6, 2, 32, 12), true));
  parts.push_back(make_part("nested", box(Vec3(-4, -4, -4), Vec3(4, 4, 4)), true));
  parts.push_back(make_part("soup", random_soup(rng, 100, Vec3(-15, -15, -15), Vec3(25, 15, 15), 4), false));
  return parts;
}

/// Bounding box of all the parts' meshes.
inline AABB bounds_of(const std::vector<Part>& parts) {
  AABB b;
  for (const auto& p : parts) b.extend(p.mesh.bounds());
  return b;
}

/// Reads the v and f lines of an OBJ file (1-based or negative indices, polygons fanned).
inline Mesh read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  Mesh m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      Vec3 v;
      ls >> v.x() >> v.y() >> v.z();
      m.vertices.push_back(v);
    } else if (tag == "f") {
      std::vector<std::uint32_t> f;
      std::string tok;
      while (ls >> tok) {
        const long i = std::stol(tok.substr(0, tok.find('/')));
        f.push_back(static_cast<std::uint32_t>(i > 0 ? i - 1 : static_cast<long>(m.vertices.size()) + i));
      }
      for (std::size_t k = 1; k + 1 < f.size(); ++k) m.triangles.push_back({f[0], f[k], f[k + 1]});
    }
  }
  return m;
}

}  // namespace loom::testmesh
