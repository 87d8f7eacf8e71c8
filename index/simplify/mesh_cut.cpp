#include "index/simplify/mesh_cut.hpp"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace loom {

namespace {

/// One side's mesh, built from the input's vertices and the crossing points on demand.
class SideBuilder {
 public:
  explicit SideBuilder(std::size_t input_vertices) : from_input_(input_vertices, kNone) {}

  /// The side's index of input vertex v.
  std::uint32_t input(const Mesh& in, std::uint32_t v) {
    if (from_input_[v] == kNone) {
      from_input_[v] = static_cast<std::uint32_t>(mesh_.vertices.size());
      mesh_.vertices.push_back(in.vertices[v]);
    }
    return from_input_[v];
  }
  /// The side's index of the crossing point on edge key (both sides compute the same point).
  std::uint32_t crossing(std::uint64_t key, const Vec3& p) {
    const auto it = crossing_.find(key);
    if (it != crossing_.end()) return it->second;
    const auto i = static_cast<std::uint32_t>(mesh_.vertices.size());
    mesh_.vertices.push_back(p);
    crossing_.emplace(key, i);
    return i;
  }
  /// Appends the fan of a convex polygon (orientation kept); degenerate corners are skipped.
  void fan(const std::vector<std::uint32_t>& poly) {
    for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
      const std::array<std::uint32_t, 3> t{poly[0], poly[k], poly[k + 1]};
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) mesh_.triangles.push_back(t);
    }
  }
  Mesh take() { return std::move(mesh_); }

 private:
  static constexpr std::uint32_t kNone = ~std::uint32_t(0);
  Mesh mesh_;
  std::vector<std::uint32_t> from_input_;
  std::unordered_map<std::uint64_t, std::uint32_t> crossing_;
};

}  // namespace

MeshHalves cut_mesh(const Mesh& mesh, int axis, double at) {
  SideBuilder below(mesh.vertices.size()), above(mesh.vertices.size());
  // The crossing point of edge (a, b): from the lower index to the higher, so that the
  // two triangles sharing the edge get the same bits.
  auto crossing = [&](std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    const Vec3& pa = mesh.vertices[a];
    const Vec3& pb = mesh.vertices[b];
    const double da = pa[axis] - at, db = pb[axis] - at;
    Vec3 p = pa + (pb - pa) * (da / (da - db));
    p[axis] = at;
    return std::make_pair((static_cast<std::uint64_t>(a) << 32) | b, p);
  };
  std::vector<std::uint32_t> lo, hi;
  for (const auto& f : mesh.triangles) {
    double d[3];
    bool any_below = false, any_above = false;
    for (int k = 0; k < 3; ++k) {
      d[k] = mesh.vertices[f[k]][axis] - at;
      any_below |= d[k] < 0.0;
      any_above |= d[k] > 0.0;
    }
    if (!any_above) {  // below, or in the plane
      below.fan({below.input(mesh, f[0]), below.input(mesh, f[1]), below.input(mesh, f[2])});
      continue;
    }
    if (!any_below) {
      above.fan({above.input(mesh, f[0]), above.input(mesh, f[1]), above.input(mesh, f[2])});
      continue;
    }
    // Across: walk the corners in order, emitting each corner to its side (a corner on the
    // plane to both) and the crossing point of each edge whose ends lie strictly apart.
    lo.clear();
    hi.clear();
    for (int k = 0; k < 3; ++k) {
      const int n = (k + 1) % 3;
      if (d[k] <= 0.0) lo.push_back(below.input(mesh, f[k]));
      if (d[k] >= 0.0) hi.push_back(above.input(mesh, f[k]));
      if ((d[k] < 0.0 && d[n] > 0.0) || (d[k] > 0.0 && d[n] < 0.0)) {
        const auto [key, p] = crossing(f[k], f[n]);
        lo.push_back(below.crossing(key, p));
        hi.push_back(above.crossing(key, p));
      }
    }
    below.fan(lo);
    above.fan(hi);
  }
  return {below.take(), above.take()};
}

}  // namespace loom
