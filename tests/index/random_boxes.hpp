// Box fixtures shared by the box tree and broad-phase tests: a box from two corners and
// random boxes with a fixed seed.
#pragma once

#include "core/geometry.hpp"

#include <random>
#include <vector>

namespace loom::test {

/// The box with corners lo and hi.
inline AABB box(const Vec3& lo, const Vec3& hi) {
  AABB b;
  b.min = lo;
  b.max = hi;
  return b;
}

/// n boxes with centres uniform in [0, extent]³ (+ offset) and half sizes up to `half`.
inline std::vector<AABB> random_boxes(unsigned seed, int n, double extent, double half,
                                      const Vec3& offset = Vec3::Zero()) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<AABB> out;
  for (int i = 0; i < n; ++i) {
    const Vec3 c = offset + extent * Vec3(U(rng), U(rng), U(rng));
    const Vec3 h = half * Vec3(U(rng), U(rng), U(rng));
    out.push_back(box(c - h, c + h));
  }
  return out;
}

}  // namespace loom::test
