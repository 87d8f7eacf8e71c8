#pragma once
// An oracle for α-SIM's containment claim, independent of loom's indices: brute-force
// point–triangle distances and generalized winding numbers over every triangle, dense
// samples of every triangle (corners, edges, a barycentric grid), and a closedness check
// by directed-edge counts. Test-only (tests/index, tests/regressions).

#include "core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace loom::alpha_sim_oracle {

/// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection §5.1.5).
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double den = va + vb + vc;
  if (!(std::abs(den) > 0)) {  // zero-area triangle: nearest of its three edges
    Vec3 best = a;
    for (auto [s, e] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      const Vec3 d = e - s;
      const double l2 = d.squaredNorm();
      const double t = l2 > 0 ? std::clamp((p - s).dot(d) / l2, 0.0, 1.0) : 0.0;
      const Vec3 q = s + t * d;
      if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    }
    return best;
  }
  const double v = vb / den, w = vc / den;
  return a + ab * v + ac * w;
}

inline double distance_to_mesh(const Vec3& p, const Mesh& m) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    best = std::min(best, (closest_on_triangle(p, c[0], c[1], c[2]) - p).squaredNorm());
  }
  return std::sqrt(best);
}

/// Generalized winding number of m about p (van Oosterom–Strackee solid angles / 4π).
inline double winding_number(const Vec3& p, const Mesh& m) {
  double sum = 0.0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    const Vec3 a = c[0] - p, b = c[1] - p, d = c[2] - p;
    const double la = a.norm(), lb = b.norm(), ld = d.norm();
    const double num = a.dot(b.cross(d));
    const double den = la * lb * ld + a.dot(b) * ld + b.dot(d) * la + d.dot(a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * M_PI);
}

/// Dense samples of every triangle of m: a barycentric grid of order `grid` (its corners and
/// points along its edges included).
inline std::vector<Vec3> oracle_samples(const Mesh& m, int grid) {
  std::vector<Vec3> out;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    for (int i = 0; i <= grid; ++i)
      for (int j = 0; i + j <= grid; ++j) {
        const double a = static_cast<double>(i) / grid, b = static_cast<double>(j) / grid;
        out.push_back(c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]));
      }
  }
  return out;
}

/// Closed (every undirected edge used equally often in each direction, at least once each)
/// after welding equal positions: consistent orientation, no boundary.
inline bool closed_consistent(const Mesh& in, std::string* why) {
  Mesh m = in;
  weld_identical_vertices(m);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> dir;
  for (const auto& f : m.triangles)
    for (int k = 0; k < 3; ++k) ++dir[{f[k], f[(k + 1) % 3]}];
  for (const auto& [e, n] : dir) {
    const auto it = dir.find({e.second, e.first});
    const int back = it == dir.end() ? 0 : it->second;
    if (back != n) {
      *why = "edge " + std::to_string(e.first) + "-" + std::to_string(e.second) + " used " + std::to_string(n) +
             " times forward, " + std::to_string(back) + " backward";
      return false;
    }
  }
  return !m.triangles.empty();
}

/// Number of oracle samples (order `grid`) of `original` neither inside `simplified`
/// (winding number > 1/2) nor within tol of its surface.
inline std::size_t samples_outside(const Mesh& original, const Mesh& simplified, double tol, int grid) {
  std::size_t out = 0;
  for (const Vec3& p : oracle_samples(original, grid))
    if (!(distance_to_mesh(p, simplified) <= tol) && !(winding_number(p, simplified) > 0.5)) ++out;
  return out;
}

}  // namespace loom::alpha_sim_oracle
