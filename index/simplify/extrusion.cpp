#include "index/simplify/extrusion.hpp"

#include "index/simplify/ring_triangulation.hpp"

#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace loom {
namespace {

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

/// Sets each face's info to its nesting depth: the number of constraints crossed from the
/// unbounded face (odd: inside the constrained rings).

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

namespace {

/// extrusion_mesh with face labels: one per wall (ring edge), one per cap of each polygon.
FacedMesh labelled_extrusion_mesh(const Extrusion& e) {
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
  FacedMesh out;
  Mesh& m = out.mesh;
  int label = 0;
  auto tri = [&](int a, int b, int c) {
    m.triangles.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(c)});
    out.face.push_back(label);
  };
  for (const auto& poly : e.polygons) {
    if (poly.outer.size() < 3) throw std::runtime_error("extrusion: a polygon has fewer than 3 vertices");
    std::vector<std::vector<int>> rings;
    auto add_ring = [&](const std::vector<Vec2>& ring) {
      std::vector<int> ids;
      for (const Vec2& q : ring) ids.push_back(vertex(q));
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const int a = ids[i], b = ids[(i + 1) % ids.size()];
        if (a == b) continue;
        // Wall quad (a, b) swept from depth_min to depth_max: outward for CCW outer rings
        // and CW holes alike (the region lies to the left of every ring edge).
        tri(2 * a, 2 * b, 2 * b + 1);
        tri(2 * a, 2 * b + 1, 2 * a + 1);
        ++label;
      }
      rings.push_back(std::move(ids));
    };
    add_ring(poly.outer);
    for (const auto& h : poly.holes) add_ring(h);
    std::vector<std::array<int, 3>> cap;
    try {
      cap = triangulate_rings(points, rings);
    } catch (const std::runtime_error&) {
      throw std::runtime_error("extrusion: the rings of a polygon cross");
    }
    const int top = label, bottom = label + 1;
    for (const auto& [a, b, c] : cap) {
      label = top;
      tri(2 * a + 1, 2 * b + 1, 2 * c + 1);  // CCW in (u, v): normal +n on the top cap
      label = bottom;
      tri(2 * a, 2 * c, 2 * b);              // reversed on the bottom cap
    }
    label = bottom + 1;
  }
  if (points.empty()) throw std::runtime_error("extrusion: the region is empty");
  m.vertices.reserve(2 * points.size());
  for (const Vec2& q : points) {
    const Vec3 p = e.u * q.x() + e.v * q.y();
    m.vertices.push_back(p + e.n * e.depth_min);
    m.vertices.push_back(p + e.n * e.depth_max);
  }
  out.faces = extrusion_faces(e);
  return out;
}

}  // namespace

Mesh extrusion_mesh(const Extrusion& e) { return labelled_extrusion_mesh(e).mesh; }

namespace {

/// A region edge in world coordinates (p: the in-plane axis other than c; g: along c),
/// g0 < g1 (edges at one height bound no slab and are left out).
struct SliceEdge {
  double p0, g0, p1, g1;
  /// Heights where the edge crosses a depth bound of the other extrusion, and that bound.
  std::array<double, 2> cross_g = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  std::array<double, 2> cross_p = {0.0, 0.0};
  /// p at height g: exactly an end's p at that end's height and exactly the bound at a
  /// crossing height, so that the pieces meeting there (an edge on one side, the bound on
  /// the other) share their vertices.
  double at(double g) const {
    if (g == g0) return p0;
    if (g == g1) return p1;
    for (int i = 0; i < 2; ++i)
      if (g == cross_g[i]) return cross_p[i];
    return p0 + (g - g0) * (p1 - p0) / (g1 - g0);
  }
};

/// One end of a slice interval: a region edge, or a depth bound of the other extrusion.
struct SliceBound {
  const SliceEdge* edge = nullptr;
  double constant = 0.0;
  double at(double g) const { return edge ? edge->at(g) : constant; }
};
struct SliceInterval {
  SliceBound lo, hi;
};

/// An extrusion's region as edges in (p, g) = (world axis ip, world axis ig).
std::vector<SliceEdge> slice_edges(const Extrusion& e, int ip, int ig) {
  std::vector<SliceEdge> out;
  auto ring = [&](const std::vector<Vec2>& r) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Vec3 x0 = e.u * r[i].x() + e.v * r[i].y();
      const Vec3 x1 = e.u * r[(i + 1) % r.size()].x() + e.v * r[(i + 1) % r.size()].y();
      if (x0[ig] < x1[ig]) out.push_back({x0[ip], x0[ig], x1[ip], x1[ig]});
      else if (x1[ig] < x0[ig]) out.push_back({x1[ip], x1[ig], x0[ip], x0[ig]});
    }
  };
  for (const auto& poly : e.polygons) {
    ring(poly.outer);
    for (const auto& h : poly.holes) ring(h);
  }
  return out;
}

/// The region's slice inside the slab [h0, h1], clipped to the depth range [d.lo, d.hi]:
/// even-odd pairs of the edges spanning it. Valid across the slab because slabs end at
/// every vertex and depth crossing. Spanning is decided from the edges' ends and the order
/// from the mean of their values at h0 and h1 (the value at the true middle): a slab one
/// rounding step thick has no double strictly inside, and two edges meeting at one end
/// are told apart by the other.
std::vector<SliceInterval> slice_at(const std::vector<SliceEdge>& edges, double h0, double h1, const Slab& d) {
  std::vector<std::pair<double, const SliceEdge*>> crossing;
  for (const SliceEdge& e : edges)
    if (e.g0 <= h0 && h1 <= e.g1) crossing.emplace_back(0.5 * (e.at(h0) + e.at(h1)), &e);
  std::sort(crossing.begin(), crossing.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<SliceInterval> out;
  for (std::size_t i = 0; i + 1 < crossing.size(); i += 2) {
    const double lv = crossing[i].first, hv = crossing[i + 1].first;
    if (hv <= d.lo || lv >= d.hi) continue;
    SliceInterval iv;
    iv.lo = lv < d.lo ? SliceBound{nullptr, d.lo} : SliceBound{crossing[i].second, 0.0};
    iv.hi = hv > d.hi ? SliceBound{nullptr, d.hi} : SliceBound{crossing[i + 1].second, 0.0};
    out.push_back(iv);
  }
  return out;
}

/// Records in each edge, and adds to `heights`, where it crosses the depth bounds d.lo
/// (slot 0) and d.hi (slot 1) strictly between its ends.
void add_crossings(std::vector<SliceEdge>& edges, const Slab& d, std::vector<double>& heights) {
  for (SliceEdge& e : edges)
    for (int i = 0; i < 2; ++i) {
      const double bound = i == 0 ? d.lo : d.hi;
      if ((e.p0 - bound) * (e.p1 - bound) >= 0.0) continue;
      e.cross_g[i] = e.g0 + (bound - e.p0) * (e.g1 - e.g0) / (e.p1 - e.p0);
      e.cross_p[i] = bound;
      heights.push_back(e.cross_g[i]);
    }
}

bool covers(const std::vector<SliceInterval>& ivs, double g, double x) {
  for (const auto& iv : ivs)
    if (iv.lo.at(g) < x && x < iv.hi.at(g)) return true;
  return false;
}

/// lo, the grid values strictly between, hi (one point if lo == hi).
std::vector<double> chain(const std::vector<double>& grid, double lo, double hi) {
  std::vector<double> c{lo};
  for (double v : grid)
    if (lo < v && v < hi) c.push_back(v);
  if (hi > lo) c.push_back(hi);
  return c;
}

}  // namespace

ExtrusionsMesh extrusion_pair_mesh(const Extrusion& a, const Extrusion& b) {
  const int ia = world_axis(a.n).first, ib = world_axis(b.n).first;
  if (!axis_aligned(a) || !axis_aligned(b) || ia == ib)
    throw std::runtime_error("extrusion pair: the frames are not axis-aligned with different normals");
  const int ic = 3 - ia - ib;
  // a's region lies in (axis ib, axis ic), its depth along ia; b's in (ia, ic), depth along ib.
  const Slab da = slab_of(a.n, a.depth_min, a.depth_max), db = slab_of(b.n, b.depth_min, b.depth_max);
  std::vector<SliceEdge> ea = slice_edges(a, ib, ic), eb = slice_edges(b, ia, ic);
  std::vector<double> heights;
  for (const auto* es : {&ea, &eb})
    for (const SliceEdge& e : *es) {
      heights.push_back(e.g0);
      heights.push_back(e.g1);
    }
  add_crossings(ea, db, heights);
  add_crossings(eb, da, heights);
  std::sort(heights.begin(), heights.end());
  heights.erase(std::unique(heights.begin(), heights.end()), heights.end());
  const std::size_t slabs = heights.size() < 2 ? 0 : heights.size() - 1;
  // Slab k spans [heights[k], heights[k + 1]]: U = slices of b (along ia), V = of a (along ib).
  std::vector<std::vector<SliceInterval>> us(slabs), vs(slabs);
  for (std::size_t k = 0; k < slabs; ++k) {
    us[k] = slice_at(eb, heights[k], heights[k + 1], da);
    vs[k] = slice_at(ea, heights[k], heights[k + 1], db);
  }
  // The grid at each height: every bound of the slabs below and above, evaluated there.
  std::vector<std::vector<double>> grid_u(heights.size()), grid_v(heights.size());
  for (std::size_t h = 0; h < heights.size(); ++h) {
    for (std::size_t k : {h - 1, h}) {
      if (k >= slabs) continue;  // h - 1 wraps below 0
      for (const auto& iv : us[k]) grid_u[h].insert(grid_u[h].end(), {iv.lo.at(heights[h]), iv.hi.at(heights[h])});
      for (const auto& iv : vs[k]) grid_v[h].insert(grid_v[h].end(), {iv.lo.at(heights[h]), iv.hi.at(heights[h])});
    }
    for (auto* g : {&grid_u[h], &grid_v[h]}) {
      std::sort(g->begin(), g->end());
      g->erase(std::unique(g->begin(), g->end()), g->end());
    }
  }

  ExtrusionsMesh out;
  Mesh& m = out.mesh;
  auto point = [&](double pa, double pb, double g) {
    Vec3 x;
    x[ia] = pa;
    x[ib] = pb;
    x[ic] = g;
    return x;
  };
  // Faces by plane: a bound (edge or depth constant) and which side of the pieces it is
  // (0–3), or a slice height facing up (4) or down (5).
  using FaceKey = std::tuple<const void*, double, int>;
  std::map<FaceKey, int> planes;
  // Appends triangle pqr on face `key` facing `outward` (its normal's component along it
  // is positive).
  auto tri = [&](const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& outward, const FaceKey& key) {
    const double s = (q - p).cross(r - p).dot(outward);
    if (s == 0.0) return;
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {p, q, r});
    if (s > 0.0) m.triangles.push_back({base, base + 1, base + 2});
    else m.triangles.push_back({base, base + 2, base + 1});
    out.face.push_back(planes.emplace(key, static_cast<int>(planes.size())).first->second);
  };
  Vec3 axis_a = Vec3::Zero(), axis_b = Vec3::Zero(), axis_c = Vec3::Zero();
  axis_a[ia] = 1.0;
  axis_b[ib] = 1.0;
  axis_c[ic] = 1.0;
  // A side face between two chains at heights g0 < g1, each a run of values along the
  // face; `at(x, g)` places value x of the chain at height g. Zipped into triangles.
  auto side = [&](const std::vector<double>& c0, const std::vector<double>& c1, double g0, double g1, auto at,
                  const Vec3& outward, const SliceBound& bound, int which) {
    const FaceKey key{bound.edge, bound.constant, which};
    const double l0 = c0.back() - c0.front(), l1 = c1.back() - c1.front();
    std::size_t i = 0, j = 0;
    while (i + 1 < c0.size() || j + 1 < c1.size()) {
      // Advance along the chain whose next point comes first (by fraction of its length).
      const bool step0 = j + 1 >= c1.size() ||
                         (i + 1 < c0.size() && (l0 > 0 ? (c0[i + 1] - c0.front()) / l0 : 1.0) <=
                                                   (l1 > 0 ? (c1[j + 1] - c1.front()) / l1 : 1.0));
      if (step0) {
        tri(at(c0[i], g0), at(c0[i + 1], g0), at(c1[j], g1), outward, key);
        ++i;
      } else {
        tri(at(c0[i], g0), at(c1[j + 1], g1), at(c1[j], g1), outward, key);
        ++j;
      }
    }
  };
  // A hexahedron whose four bounds are the same in the next slab continues there: it is
  // emitted once over its whole run, so a height where only other pieces change does not
  // split its faces (no face of that height touches them).
  auto same = [](const SliceInterval& x, const SliceInterval& y) {
    return x.lo.edge == y.lo.edge && x.lo.constant == y.lo.constant && x.hi.edge == y.hi.edge &&
           x.hi.constant == y.hi.constant;
  };
  auto continues = [&](std::size_t k, const SliceInterval& u, const SliceInterval& v) {
    const bool has_u = std::any_of(us[k].begin(), us[k].end(), [&](const auto& x) { return same(x, u); });
    return has_u && std::any_of(vs[k].begin(), vs[k].end(), [&](const auto& y) { return same(y, v); });
  };
  for (std::size_t k = 0; k < slabs; ++k) {
    for (const auto& u : us[k])
      for (const auto& v : vs[k]) {
        if (k > 0 && continues(k - 1, u, v)) continue;
        std::size_t last = k;
        while (last + 1 < slabs && continues(last + 1, u, v)) ++last;
        const double g0 = heights[k], g1 = heights[last + 1];
        const auto &grid_v0 = grid_v[k], &grid_v1 = grid_v[last + 1], &grid_u0 = grid_u[k], &grid_u1 = grid_u[last + 1];
        const double u00 = u.lo.at(g0), u01 = u.hi.at(g0), u10 = u.lo.at(g1), u11 = u.hi.at(g1);
        const double v00 = v.lo.at(g0), v01 = v.hi.at(g0), v10 = v.lo.at(g1), v11 = v.hi.at(g1);
        // Faces on the u bounds run along v, and the other way round.
        const auto cv0 = chain(grid_v0, v00, v01), cv1 = chain(grid_v1, v10, v11);
        const auto cu0 = chain(grid_u0, u00, u01), cu1 = chain(grid_u1, u10, u11);
        side(cv0, cv1, g0, g1, [&](double y, double g) { return point(g == g0 ? u00 : u10, y, g); }, -axis_a, u.lo, 0);
        side(cv0, cv1, g0, g1, [&](double y, double g) { return point(g == g0 ? u01 : u11, y, g); }, axis_a, u.hi, 1);
        side(cu0, cu1, g0, g1, [&](double x, double g) { return point(x, g == g0 ? v00 : v10, g); }, -axis_b, v.lo, 2);
        side(cu0, cu1, g0, g1, [&](double x, double g) { return point(x, g == g0 ? v01 : v11, g); }, axis_b, v.hi, 3);
      }
  }
  // At each height: grid cells under material below only face up, above only face down.
  static const std::vector<SliceInterval> none;
  for (std::size_t h = 0; h < heights.size(); ++h) {
    const double g = heights[h];
    const auto &ub = h > 0 ? us[h - 1] : none, &vb = h > 0 ? vs[h - 1] : none;
    const auto &ua = h < slabs ? us[h] : none, &va = h < slabs ? vs[h] : none;
    const auto& gu = grid_u[h];
    const auto& gv = grid_v[h];
    for (std::size_t p = 0; p + 1 < gu.size(); ++p)
      for (std::size_t q = 0; q + 1 < gv.size(); ++q) {
        const double xm = 0.5 * (gu[p] + gu[p + 1]), ym = 0.5 * (gv[q] + gv[q + 1]);
        const bool below = covers(ub, g, xm) && covers(vb, g, ym), above = covers(ua, g, xm) && covers(va, g, ym);
        if (below == above) continue;
        const Vec3 outward = below ? axis_c : -axis_c;
        const FaceKey key{nullptr, g, below ? 4 : 5};
        const Vec3 c00 = point(gu[p], gv[q], g), c10 = point(gu[p + 1], gv[q], g), c11 = point(gu[p + 1], gv[q + 1], g),
                   c01 = point(gu[p], gv[q + 1], g);
        tri(c00, c10, c11, outward, key);
        tri(c00, c11, c01, outward, key);
      }
  }
  if (m.triangles.empty()) throw std::runtime_error("extrusion pair: the intersection is empty");
  weld_identical_vertices(m);
  // Every triangle has a nonzero area (tri() drops the others), so welding equal vertices
  // removes none and the labels stay aligned; checked, since a lost one would shift them.
  if (m.triangles.size() != out.face.size())
    throw std::runtime_error("extrusion pair: welding removed a triangle (labels would not match)");
  out.faces = static_cast<int>(planes.size());
  return out;
}

int extrusion_faces(const Extrusion& e) {
  int faces = 0;
  for (const auto& p : e.polygons) {
    faces += 2 + static_cast<int>(p.outer.size());
    for (const auto& h : p.holes) faces += static_cast<int>(h.size());
  }
  return faces;
}

namespace {

/// The pair slicer takes two axis extrusions whose normals are different axes.
bool sliceable(const Extrusion& a, const Extrusion& b) {
  return axis_aligned(a) && axis_aligned(b) && a.n.dot(b.n) == 0.0;
}

/// A share of tol for removing, before a Boolean, the vertices the slicing left on the
/// sliced pair's straight edges (where the slab planes cut them: on the edge lines up to
/// rounding): half the triangles for the corefinement to cut, which then takes half the
/// time (the bunny's 1,164 -> 584 triangles, 90 -> 40 ms). The rest of tol is used after.
constexpr double kSliceMergeShare = 1e-3;

/// The first operand of `kept` in this order: its first two sliced (far cheaper than a
/// general Boolean, so they go through the slicer whenever it can take them), else the
/// first alone.
ExtrusionsMesh first_operand(const std::vector<Extrusion>& kept) {
  ExtrusionsMesh acc;
  if (kept.size() >= 2 && sliceable(kept[0], kept[1])) acc = extrusion_pair_mesh(kept[0], kept[1]);
  else static_cast<FacedMesh&>(acc) = labelled_extrusion_mesh(kept[0]);
  return acc;
}

/// first_operand() ∩ the rest of `kept` (CGAL corefinement), faces merged within tol.
/// `meshes`, if given, holds labelled_extrusion_mesh() of kept[i] at i where the caller
/// built it already (an empty mesh elsewhere).
ExtrusionsMesh intersect_rest(ExtrusionsMesh acc, const std::vector<Extrusion>& kept, double tol,
                              const std::vector<FacedMesh>* meshes = nullptr) {
  const bool pair = kept.size() >= 2 && sliceable(kept[0], kept[1]);
  if (pair && kept.size() > 2) {
    // Only fewer triangles for the Boolean to cut: where merge_face_vertices refuses a
    // face it throws and leaves the mesh as it was, sliced, for the Boolean.
    try {
      merge_face_vertices(acc, kSliceMergeShare * tol);
    } catch (const std::runtime_error&) {
    }
  }
  for (std::size_t i = pair ? 2 : 1; i < kept.size(); ++i) {
    const bool built = meshes && i < meshes->size() && !(*meshes)[i].mesh.triangles.empty();
    FacedMesh own;
    const FacedMesh& operand = built ? (*meshes)[i] : (own = labelled_extrusion_mesh(kept[i]));
    static_cast<FacedMesh&>(acc) = mesh_intersection(acc, operand);
    ++acc.booleans;
  }
  if (acc.booleans > 0) merge_face_vertices(acc, (pair ? 1.0 - kSliceMergeShare : 1.0) * tol);
  return acc;
}

/// Pairs of triangles, one of `a` and one of `b`, whose bounding boxes meet (closed): the
/// candidates a corefinement of the two tests, a measure of its work.
std::size_t box_overlaps(const Mesh& a, const Mesh& b) {
  using Box = CGAL::Box_intersection_d::Box_d<double, 3>;
  auto boxes = [](const Mesh& m) {
    std::vector<Box> out;
    out.reserve(m.triangles.size());
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto c = m.corners(t);
      const Vec3 lo = c[0].cwiseMin(c[1]).cwiseMin(c[2]), hi = c[0].cwiseMax(c[1]).cwiseMax(c[2]);
      double l[3] = {lo.x(), lo.y(), lo.z()}, h[3] = {hi.x(), hi.y(), hi.z()};  // (Box_d takes non-const)
      out.emplace_back(l, h);
    }
    return out;
  };
  std::vector<Box> ba = boxes(a), bb = boxes(b);
  std::size_t n = 0;
  CGAL::box_intersection_d(ba.begin(), ba.end(), bb.begin(), bb.end(), [&n](const Box&, const Box&) { ++n; });
  return n;
}

}  // namespace

ExtrusionsMesh mesh_extrusions(const std::vector<Extrusion>& kept, double tol) {
  if (kept.empty()) throw std::runtime_error("extrusions: nothing to intersect");
  if (kept.size() != 3) return intersect_rest(first_operand(kept), kept, tol);
  // Three: which two are sliced matters. The sliced pair's pieces may meet along an edge,
  // or the third outline's rings at a vertex, and CGAL's Boolean takes neither
  // (mesh_intersection refuses); another pair often has no such contact. And the
  // Boolean's cost follows the triangle pairs whose boxes meet, which differ between the
  // orders by up to 2× (featuretype: 1,546 / 1,272 / 880 pairs, 20 / 18 / 10 ms), while
  // slicing a pair costs 0.1–0.5 ms. So each order's pair is sliced and counted against
  // the third (before its slice vertices are merged: that costs more, and only the order
  // run needs it), and the orders are tried by fewest such pairs (ties, and orders the
  // slicer cannot take, in the fixed sequence): deterministic.
  const int orders[3][3] = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}};
  struct Candidate {
    std::vector<Extrusion> kept;
    ExtrusionsMesh first;
    std::vector<FacedMesh> meshes;  ///< at 2: the third prism's mesh, where counted
    std::size_t cost = 0;
    std::string error;  ///< why its operands could not be built
  };
  std::vector<Candidate> candidates(3);
  for (int k = 0; k < 3; ++k) {
    Candidate& c = candidates[static_cast<std::size_t>(k)];
    const auto& o = orders[k];
    c.kept = {kept[static_cast<std::size_t>(o[0])], kept[static_cast<std::size_t>(o[1])], kept[static_cast<std::size_t>(o[2])]};
    try {
      c.first = first_operand(c.kept);
      if (sliceable(c.kept[0], c.kept[1])) {
        c.meshes.resize(3);
        c.meshes[2] = labelled_extrusion_mesh(c.kept[2]);
        c.cost = box_overlaps(c.first.mesh, c.meshes[2].mesh);
      }
    } catch (const std::runtime_error& e) {
      c.error = e.what();
    }
  }
  std::vector<std::size_t> by_cost = {0, 1, 2};
  std::stable_sort(by_cost.begin(), by_cost.end(), [&](std::size_t x, std::size_t y) {
    const bool fx = candidates[x].error.empty(), fy = candidates[y].error.empty();
    return fx != fy ? fx : candidates[x].cost < candidates[y].cost;
  });
  std::string why;
  for (const std::size_t k : by_cost) {
    Candidate& c = candidates[k];
    try {
      if (!c.error.empty()) throw std::runtime_error(c.error);
      return intersect_rest(std::move(c.first), c.kept, tol, &c.meshes);
    } catch (const std::runtime_error& e) {
      why += std::string(why.empty() ? "" : "; ") + e.what();
    }
  }
  throw std::runtime_error("extrusions: no order of the three could be intersected: " + why);
}

}  // namespace loom
