#pragma once
/// Scenes shared by the audit benches: closed part meshes (UV spheres, capped cylinders),
/// smooth cubic centerlines, and the seed paper's "complex" scene (≥ 100 cables of 1–3 m,
/// d = 2–10 mm, among ≥ 200 closed parts). Scene units mm, world frame, fixed seeds.
#include "core/centerline.hpp"
#include "core/part.hpp"
#include "routing/audit/clash_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace loom::bench {

/// Parts: closed ellipsoids (UV spheres), capped cylinders (pipes, rods) and boxes.
inline Mesh uv_sphere(int n_lat, int n_lon) {
  Mesh m;
  m.vertices.emplace_back(0, 0, 1);
  for (int i = 1; i < n_lat; ++i) {
    const double th = M_PI * i / n_lat;
    for (int j = 0; j < n_lon; ++j) {
      const double ph = 2 * M_PI * j / n_lon;
      m.vertices.emplace_back(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
    }
  }
  m.vertices.emplace_back(0, 0, -1);
  const auto S = static_cast<std::uint32_t>(m.vertices.size() - 1);
  auto ring = [&](int i, int j) { return static_cast<std::uint32_t>(1 + (i - 1) * n_lon + (j % n_lon)); };
  for (int j = 0; j < n_lon; ++j) m.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  for (int j = 0; j < n_lon; ++j) m.triangles.push_back({S, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)});
  return m;
}

/// Unit cylinder radius 1, z in [0, 1], closed by fans.
inline Mesh cylinder(int n_seg, int n_len) {
  Mesh m;
  for (int i = 0; i <= n_len; ++i)
    for (int j = 0; j < n_seg; ++j) {
      const double ph = 2 * M_PI * j / n_seg;
      m.vertices.emplace_back(std::cos(ph), std::sin(ph), static_cast<double>(i) / n_len);
    }
  const auto c0 = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.emplace_back(0, 0, 0);
  m.vertices.emplace_back(0, 0, 1);
  auto v = [&](int i, int j) { return static_cast<std::uint32_t>(i * n_seg + (j % n_seg)); };
  for (int i = 0; i < n_len; ++i)
    for (int j = 0; j < n_seg; ++j) {
      m.triangles.push_back({v(i, j), v(i, j + 1), v(i + 1, j + 1)});
      m.triangles.push_back({v(i, j), v(i + 1, j + 1), v(i + 1, j)});
    }
  for (int j = 0; j < n_seg; ++j) {
    m.triangles.push_back({c0, v(0, j + 1), v(0, j)});
    m.triangles.push_back({c0 + 1, v(n_len, j), v(n_len, j + 1)});
  }
  return m;
}

/// Clamped uniform cubic B-spline on the given control points (a smooth centerline).
inline Centerline cubic_from_controls(const std::vector<Vec3>& cps) {
  const int n = static_cast<int>(cps.size());
  std::vector<double> knots(4, 0.0);
  for (int i = 1; i < n - 3; ++i) knots.push_back(static_cast<double>(i));
  for (int i = 0; i < 4; ++i) knots.push_back(static_cast<double>(n - 3));
  return Centerline(3, knots, cps);
}

/// A generated audit scene: parts, cables, and the parts' triangle count.
struct BenchScene {
  std::vector<Part> parts;
  std::vector<CableInput> cables;
  std::size_t triangles = 0;
};

/// `n_parts` parts of ~`tris_per_part` triangles in a 3 × 1 × 1 m section, `n_cables`
/// cubic cables of 1–3 m through it, d = 2–10 mm.
inline BenchScene make_scene(int n_parts, int tris_per_part, int n_cables, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  BenchScene sc;
  const Vec3 extent = Vec3(3000, 1000, 1000) * scale;
  for (int i = 0; i < n_parts; ++i) {
    Part p;
    p.name = "part-" + std::to_string(i);
    const int kind = i % 3;
    const int n = std::max(4, static_cast<int>(std::sqrt(tris_per_part / 2.0)));
    Mesh m = kind == 0 ? uv_sphere(n, n) : cylinder(n, std::max(1, n / 2));
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    t.translate(Vec3(U(rng) * extent.x(), U(rng) * extent.y(), U(rng) * extent.z()));
    t.rotate(Eigen::AngleAxisd(U(rng) * M_PI, Vec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5).normalized()));
    if (kind == 0) t.scale(Vec3(20 + 60 * U(rng), 20 + 60 * U(rng), 20 + 60 * U(rng)));
    else if (kind == 1) t.scale(Vec3(3 + 10 * U(rng), 3 + 10 * U(rng), 100 + 300 * U(rng)));  // rods, pipes
    else t.scale(Vec3(30 + 60 * U(rng), 30 + 60 * U(rng), 20 + 80 * U(rng)));              // drums
    m.transform(t);
    p.mesh = std::move(m);
    p.closed = true;
    p.clearance = (i % 10 == 0) ? 2.0 : 0.0;
    sc.triangles += p.mesh.triangle_count();
    sc.parts.push_back(std::move(p));
  }
  for (int c = 0; c < n_cables; ++c) {
    const double len = (1000 + 2000 * U(rng)) * std::min(scale, 1.0 + 0.0 * scale);
    const Vec3 a(U(rng) * (extent.x() - len), U(rng) * extent.y(), U(rng) * extent.z());
    const Vec3 b = a + Vec3(len * 0.9, (U(rng) - 0.5) * 200, (U(rng) - 0.5) * 200);
    std::vector<Vec3> pts;
    const int k = 5;
    for (int i = 0; i <= k; ++i) {
      Vec3 q = a + (b - a) * (static_cast<double>(i) / k);
      if (i > 0 && i < k) q += Vec3(0, (U(rng) - 0.5) * 150, (U(rng) - 0.5) * 150);
      pts.push_back(q);
    }
    CableInput in;
    in.id = "W" + std::to_string(c);
    in.curve = cubic_from_controls(pts);
    in.radius = 1.0 + 4.0 * U(rng);
    in.min_bend_radius = 6.0 * in.radius;
    sc.cables.push_back(std::move(in));
  }
  return sc;
}

}  // namespace loom::bench
