#include "index/extrusion.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace loom {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Fbb = CGAL::Triangulation_face_base_with_info_2<int, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbb>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Crossing constraints throw instead of inserting constructed points: a cap must use the
// rings' own vertices, or the walls and caps would not share them.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_requiring_constructions_tag>;

/// World axis of a frame vector that is exactly ± a unit axis: {axis, sign}; axis -1 if not.
std::pair<int, double> world_axis(const Vec3& w) {
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    if (w[b] == 0.0 && w[c] == 0.0 && (w[a] == 1.0 || w[a] == -1.0)) return {a, w[a]};
  }
  return {-1, 0.0};
}

/// A range of one world coordinate.
struct Slab {
  int axis = -1;
  double lo = 0.0, hi = 0.0;
};

/// The world-coordinate range of p·w ∈ [lo, hi] for a frame vector w = ±axis.
Slab slab_of(const Vec3& w, double lo, double hi) {
  const auto [axis, sign] = world_axis(w);
  return sign > 0.0 ? Slab{axis, lo, hi} : Slab{axis, -hi, -lo};
}

/// Bounding box of an extrusion's region in its own (u, v) coordinates.
std::array<double, 4> region_box(const Extrusion& e) {
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const auto& p : e.polygons)
    for (const Vec2& q : p.outer) {  // holes lie inside their outer ring
      x0 = std::min(x0, q.x());
      x1 = std::max(x1, q.x());
      y0 = std::min(y0, q.y());
      y1 = std::max(y1, q.y());
    }
  return {x0, x1, y0, y1};
}

/// World-axis range of e's region along in-plane axis `axis`, if u or v is that axis.
std::optional<Slab> in_plane_extent(const Extrusion& e, int axis) {
  const auto b = region_box(e);
  if (world_axis(e.u).first == axis) return slab_of(e.u, b[0], b[1]);
  if (world_axis(e.v).first == axis) return slab_of(e.v, b[2], b[3]);
  return std::nullopt;
}

/// Replaces a box's rectangle by its bounds [x0, x1] × [y0, y1] (CCW).
void set_rectangle(Extrusion& e, double x0, double x1, double y0, double y1) {
  e.polygons.assign(1, PolygonWithHoles2{});
  e.polygons[0].outer = {Vec2(x0, y0), Vec2(x1, y0), Vec2(x1, y1), Vec2(x0, y1)};
}

/// Intersects a frame-coordinate range [lo, hi] of p·w with the world slab s (w = ±s.axis);
/// false if nothing is left.
bool clip_range(const Vec3& w, const Slab& s, double& lo, double& hi) {
  const Slab here = slab_of(w, lo, hi);
  const double wlo = std::max(here.lo, s.lo), whi = std::min(here.hi, s.hi);
  // Back to p·w: for a negative axis the world range [wlo, whi] is p·w ∈ [-whi, -wlo].
  if (world_axis(w).second > 0.0) {
    lo = wlo;
    hi = whi;
  } else {
    lo = -whi;
    hi = -wlo;
  }
  return wlo < whi;
}

/// How the kept extrusions took a world slab.
enum class Absorbed { Yes, No, Empty };

/// Makes the kept extrusions imply the world slab s, if one can: Yes when s is implied by
/// one's extent (within slack) or was applied by clipping one; Empty when that clip left
/// nothing (the intersection is empty).
Absorbed absorb_slab(std::vector<Extrusion>& kept, const Slab& s, double slack) {
  for (const Extrusion& k : kept) {
    const auto ext = in_plane_extent(k, s.axis);
    if (ext && ext->lo >= s.lo - slack && ext->hi <= s.hi + slack) return Absorbed::Yes;
  }
  for (Extrusion& k : kept)
    if (world_axis(k.n).first == s.axis)
      return clip_range(k.n, s, k.depth_min, k.depth_max) ? Absorbed::Yes : Absorbed::Empty;
  for (Extrusion& k : kept)
    if (is_axis_box(k)) {
      auto b = region_box(k);
      const bool left = world_axis(k.u).first == s.axis ? clip_range(k.u, s, b[0], b[1]) : clip_range(k.v, s, b[2], b[3]);
      if (!left) return Absorbed::Empty;
      set_rectangle(k, b[0], b[1], b[2], b[3]);
      return Absorbed::Yes;
    }
  return Absorbed::No;
}

}  // namespace

bool axis_aligned(const Extrusion& e) {
  return world_axis(e.u).first >= 0 && world_axis(e.v).first >= 0 && world_axis(e.n).first >= 0;
}

bool is_axis_box(const Extrusion& e) {
  if (!axis_aligned(e) || e.polygons.size() != 1 || !e.polygons[0].holes.empty() || e.polygons[0].outer.size() != 4)
    return false;
  const auto& r = e.polygons[0].outer;
  // Each side runs along u or v: consecutive vertices share x or y, alternately.
  const bool x_first = r[0].y() == r[1].y();
  for (int i = 0; i < 4; ++i) {
    const Vec2 &a = r[i], &b = r[(i + 1) % 4];
    const bool along_x = (i % 2 == 0) == x_first;
    if (along_x ? (a.y() != b.y() || a.x() == b.x()) : (a.x() != b.x() || a.y() == b.y())) return false;
  }
  return true;
}

ExtrusionReduction reduce_extrusions(const std::vector<Extrusion>& in, double slack) {
  ExtrusionReduction out;
  std::vector<const Extrusion*> boxes;
  for (const Extrusion& e : in) {
    if (is_axis_box(e)) boxes.push_back(&e);
    else out.kept.push_back(e);
  }
  // All boxes: the first carries the others' slabs (its rectangle and depth get clipped).
  std::size_t first = 0;
  if (out.kept.empty() && !boxes.empty()) out.kept.push_back(*boxes[first++]);
  for (std::size_t i = first; i < boxes.size(); ++i) {
    const Extrusion& b = *boxes[i];
    const auto r = region_box(b);
    const std::array<Slab, 3> slabs = {slab_of(b.u, r[0], r[1]), slab_of(b.v, r[2], r[3]),
                                       slab_of(b.n, b.depth_min, b.depth_max)};
    // A slab applied to a kept extrusion is valid even if the box stays: the intersection
    // lies in every slab of every box.
    bool all = true;
    for (const Slab& s : slabs) {
      const Absorbed a = absorb_slab(out.kept, s, slack);
      if (a == Absorbed::Empty) return {in, 0};
      all = all && a == Absorbed::Yes;
    }
    if (all) ++out.absorbed;
    else out.kept.push_back(b);
  }
  return out;
}

Mesh extrusion_mesh(const Extrusion& e) {
  if (!(e.depth_min < e.depth_max))
    throw std::runtime_error("extrusion: empty depth range [" + std::to_string(e.depth_min) + ", " +
                             std::to_string(e.depth_max) + "]");
  // One 2-D vertex per distinct ring point (rings may touch at a vertex); 3-D vertex 2i at
  // depth_min, 2i + 1 at depth_max.
  std::map<std::pair<double, double>, int> index_of;
  std::vector<Vec2> points;
  auto vertex = [&](const Vec2& q) {
    const auto [it, added] = index_of.emplace(std::make_pair(q.x(), q.y()), static_cast<int>(points.size()));
    if (added) points.push_back(q);
    return it->second;
  };
  Mesh m;
  auto tri = [&](int a, int b, int c) {
    m.triangles.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(c)});
  };
  for (const auto& poly : e.polygons) {
    if (poly.outer.size() < 3) throw std::runtime_error("extrusion: a polygon has fewer than 3 vertices");
    Cdt cdt;
    auto add_ring = [&](const std::vector<Vec2>& ring) {
      std::vector<Cdt::Vertex_handle> vh;
      for (const Vec2& q : ring) {
        auto h = cdt.insert(K::Point_2(q.x(), q.y()));
        h->info() = vertex(q);
        vh.push_back(h);
      }
      for (std::size_t i = 0; i < vh.size(); ++i) {
        const int a = vh[i]->info(), b = vh[(i + 1) % vh.size()]->info();
        if (a == b) continue;
        cdt.insert_constraint(vh[i], vh[(i + 1) % vh.size()]);
        // Wall quad (a, b) swept from depth_min to depth_max: outward for CCW outer rings
        // and CW holes alike (the region lies to the left of every ring edge).
        tri(2 * a, 2 * b, 2 * b + 1);
        tri(2 * a, 2 * b + 1, 2 * a + 1);
      }
    };
    try {
      add_ring(poly.outer);
      for (const auto& h : poly.holes) add_ring(h);
    } catch (const Cdt::Intersection_of_constraints_exception&) {
      throw std::runtime_error("extrusion: the rings of a polygon cross");
    }
    // Nesting depth across constraints from the unbounded face: odd is inside.
    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
    std::vector<Cdt::Face_handle> frontier{cdt.infinite_face()}, next;
    cdt.infinite_face()->info() = 0;
    for (int level = 0; !frontier.empty(); ++level) {
      // Flood the current level; faces across a constraint start the next one.
      while (!frontier.empty()) {
        const Cdt::Face_handle f = frontier.back();
        frontier.pop_back();
        for (int i = 0; i < 3; ++i) {
          const Cdt::Face_handle g = f->neighbor(i);
          if (g->info() != -1) continue;
          if (cdt.is_constrained(Cdt::Edge(f, i))) {
            next.push_back(g);
          } else {
            g->info() = level;
            frontier.push_back(g);
          }
        }
      }
      for (const auto& g : next)
        if (g->info() == -1) {
          g->info() = level + 1;
          frontier.push_back(g);
        }
      next.clear();
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
      if (f->info() % 2 != 1) continue;
      const int a = f->vertex(0)->info(), b = f->vertex(1)->info(), c = f->vertex(2)->info();
      tri(2 * a + 1, 2 * b + 1, 2 * c + 1);  // CCW in (u, v): normal +n on the top cap
      tri(2 * a, 2 * c, 2 * b);              // reversed on the bottom cap
    }
  }
  if (points.empty()) throw std::runtime_error("extrusion: the region is empty");
  m.vertices.reserve(2 * points.size());
  for (const Vec2& q : points) {
    const Vec3 p = e.u * q.x() + e.v * q.y();
    m.vertices.push_back(p + e.n * e.depth_min);
    m.vertices.push_back(p + e.n * e.depth_max);
  }
  return m;
}

int extrusion_faces(const Extrusion& e) {
  int faces = 0;
  for (const auto& p : e.polygons) {
    faces += 2 + static_cast<int>(p.outer.size());
    for (const auto& h : p.holes) faces += static_cast<int>(h.size());
  }
  return faces;
}

}  // namespace loom
