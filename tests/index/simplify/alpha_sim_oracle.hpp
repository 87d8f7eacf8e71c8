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

#include "common/brute_geometry.hpp"

namespace loom::alpha_sim_oracle {


/// Unsigned distance from p to the surface of m (brute force over every triangle).
inline double distance_to_mesh(const Vec3& p, const Mesh& m) { return test_oracle::mesh_distance(m, p); }

/// Generalized winding number of m about p.
inline double winding_number(const Vec3& p, const Mesh& m) { return test_oracle::mesh_winding_number(m, p); }

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
