#pragma once
// A closed axis-aligned box as a triangle mesh (outward), for the benches that build their
// scenes from blocks.

#include "core/mesh.hpp"

#include <array>
#include <cstdint>

namespace loom::bench {

/// The box [lo, hi] (scene units), 12 triangles wound outward.
inline Mesh box_mesh(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  const Vec3 c = 0.5 * (lo + hi);
  for (const auto& q : quads) {
    for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      const Vec3 a = m.vertices[t[0]], b = m.vertices[t[1]], d = m.vertices[t[2]];
      const bool out = (b - a).cross(d - a).dot((a + b + d) / 3.0 - c) > 0.0;
      m.triangles.push_back({std::uint32_t(t[0]), std::uint32_t(out ? t[1] : t[2]), std::uint32_t(out ? t[2] : t[1])});
    }
  }
  return m;
}

}  // namespace loom::bench
