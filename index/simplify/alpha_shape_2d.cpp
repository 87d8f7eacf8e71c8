#include "index/simplify/alpha_shape_2d.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <queue>
#include <stdexcept>
#include <tuple>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace loom {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_2<K>;
using Fb = CGAL::Triangulation_face_base_with_info_2<int, K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using DT = CGAL::Delaunay_triangulation_2<K, Tds>;
using CPoint = K::Point_2;
using Face = DT::Face_handle;

Vec2 to_vec(const CPoint& p) { return Vec2(p.x(), p.y()); }

double tri_area(const std::array<Vec2, 3>& t) {
  return 0.5 * ((t[1] - t[0]).x() * (t[2] - t[0]).y() - (t[1] - t[0]).y() * (t[2] - t[0]).x());
}

double point_segment_distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0.0 ? (p - a).dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (a + t * ab - p).norm();
}

/// The x-range of the part of segment ab with y in [s0, s1] (both within ab's y-range),
/// widened by err where the slab cuts the segment (the interpolation's rounding).
std::array<double, 2> slab_x_range(const Vec2& a, const Vec2& b, double s0, double s1, double err) {
  const double ymin = std::min(a.y(), b.y()), ymax = std::max(a.y(), b.y());
  const double xmin = std::min(a.x(), b.x()), xmax = std::max(a.x(), b.x());
  if (!(s0 > ymin || s1 < ymax)) return {xmin, xmax};
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const double xa = a.x() + dx * ((s0 - a.y()) / dy), xb = a.x() + dx * ((s1 - a.y()) / dy);
  return {std::max(xmin, std::min(xa, xb) - err), std::min(xmax, std::max(xa, xb) + err)};
}

/// Uniform bucket grid over triangles and segments (CSR storage).
struct BucketGrid {
  Vec2 origin = Vec2::Zero();
  double cell = 1.0;
  int nx = 0, ny = 0;
  std::vector<std::uint32_t> start, items;

  bool empty() const { return nx == 0; }
  int cx(double x) const { return std::clamp(static_cast<int>(std::floor((x - origin.x()) / cell)), 0, nx - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>(std::floor((y - origin.y()) / cell)), 0, ny - 1); }

  /// Builds the grid over `boxes` (min, max per item) covering `lo`..`hi`, with about
  /// `boxes_per_cell` boxes per cell of the bounding box (more cells when smaller).
  void build(const std::vector<std::array<Vec2, 2>>& boxes, const Vec2& lo, const Vec2& hi, double boxes_per_cell) {
    if (!size_for(boxes.size(), lo, hi, boxes_per_cell)) return;
    // Cell ranges of the boxes, computed once for both passes.
    std::vector<std::array<int, 4>> range(boxes.size());
    for (std::size_t k = 0; k < boxes.size(); ++k)
      range[k] = {cx(boxes[k][0].x()), cx(boxes[k][1].x()), cy(boxes[k][0].y()), cy(boxes[k][1].y())};
    std::vector<std::uint32_t> count(static_cast<std::size_t>(nx) * ny + 1, 0);
    for (const auto& g : range)
      for (int y = g[2]; y <= g[3]; ++y)
        for (int x = g[0]; x <= g[1]; ++x) ++count[static_cast<std::size_t>(y) * nx + x + 1];
    for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
    start = count;
    items.resize(count.back());
    for (std::uint32_t k = 0; k < boxes.size(); ++k) {
      const auto& g = range[k];
      for (int y = g[2]; y <= g[3]; ++y)
        for (int x = g[0]; x <= g[1]; ++x) items[count[static_cast<std::size_t>(y) * nx + x]++] = k;
    }
  }
  /// Clears the grid and sizes it over lo..hi for `count` items (none: empty, false).
  bool size_for(std::size_t count, const Vec2& lo, const Vec2& hi, double boxes_per_cell) {
    start.clear();
    items.clear();
    nx = ny = 0;
    if (count == 0) return false;
    const Vec2 ext = (hi - lo).cwiseMax(Vec2::Constant(1e-300));
    // At most 2^22 cells.
    const double target = std::clamp(static_cast<double>(count) / boxes_per_cell, 1.0, 4194304.0);
    cell = std::sqrt(ext.x() * ext.y() / target);
    if (!(cell > 0.0) || !std::isfinite(cell)) cell = std::max(ext.x(), ext.y());
    cell = std::max(cell, std::max(ext.x(), ext.y()) / 2048.0);
    origin = lo;
    nx = std::max(1, static_cast<int>(std::ceil(ext.x() / cell)));
    ny = std::max(1, static_cast<int>(std::ceil(ext.y() / cell)));
    return true;
  }
  /// Builds the grid over triangles like build() over their boxes, but lists each
  /// triangle only in the cells its area meets (for_triangle_cells): a long thin triangle
  /// across a grid is listed along itself, not over its box.
  void build_triangles(const std::vector<std::array<Vec2, 3>>& tris, const Vec2& lo, const Vec2& hi,
                       double boxes_per_cell) {
    if (!size_for(tris.size(), lo, hi, boxes_per_cell)) return;
    std::vector<std::uint32_t> count(static_cast<std::size_t>(nx) * ny + 1, 0);
    for (const auto& c : tris)
      for_triangle_cells(c, [&](int x, int y) { ++count[static_cast<std::size_t>(y) * nx + x + 1]; });
    for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
    start = count;
    items.assign(count.back(), 0);
    for (std::uint32_t k = 0; k < tris.size(); ++k)
      for_triangle_cells(tris[k], [&](int x, int y) { items[count[static_cast<std::size_t>(y) * nx + x]++] = k; });
  }
  /// Calls f(i, j) for each cell (i, j) that the closed triangle c meets, and perhaps a
  /// cell it only comes within rounding of (row by row: the x-range of the triangle's part
  /// in the row's slab, which its edges' parts there span, widened by the rounding).
  template <class F>
  void for_triangle_cells(const std::array<Vec2, 3>& c, F&& f) const {
    if (empty()) return;
    const double ymin = std::min({c[0].y(), c[1].y(), c[2].y()}), ymax = std::max({c[0].y(), c[1].y(), c[2].y()});
    const double xmin = std::min({c[0].x(), c[1].x(), c[2].x()}), xmax = std::max({c[0].x(), c[1].x(), c[2].x()});
    // A triangle whose box spans at most two cells each way is listed over its box (as
    // build() lists boxes): exact, and without the rounding margin below, which would
    // list most of the many small triangles in three cells instead of one.
    const int bx0 = cx(xmin), bx1 = cx(xmax), by0 = cy(ymin), by1 = cy(ymax);
    if (bx1 - bx0 <= 1 && by1 - by0 <= 1) {
      for (int j = by0; j <= by1; ++j)
        for (int i = bx0; i <= bx1; ++i) f(i, j);
      return;
    }
    // Widens each row's x-range beyond the rounding of its interpolation and of cx(), far
    // below a cell: a whole cell each side would list a long triangle three cells wide.
    const double pad = 1e-12 * (std::abs(xmin) + std::abs(xmax) + std::abs(origin.x())) + 1e-9 * cell;
    for (int j = by0; j <= by1; ++j) {
      const double s0 = std::max(origin.y() + j * cell, ymin), s1 = std::min(origin.y() + (j + 1) * cell, ymax);
      double xl = std::numeric_limits<double>::infinity(), xr = -xl;
      for (int e = 0; e < 3; ++e) {
        const Vec2& a = c[e];
        const Vec2& b = c[(e + 1) % 3];
        const double ey0 = std::min(a.y(), b.y()), ey1 = std::max(a.y(), b.y());
        if (ey1 < s0 || ey0 > s1) continue;
        const auto r = slab_x_range(a, b, std::max(s0, ey0), std::min(s1, ey1), 0.0);
        xl = std::min(xl, r[0]);
        xr = std::max(xr, r[1]);
      }
      if (!(xl <= xr)) {  // the row's slab meets the triangle only within rounding
        xl = xmin;
        xr = xmax;
      }
      for (int i = cx(xl - pad), i1 = cx(xr + pad); i <= i1; ++i) f(i, j);
    }
  }
  /// The items listed in every cell within `pad` of the segment ab (row by row: the
  /// x-range of the segment's part in the row's padded slab); an item in several of those
  /// cells is listed as often.
  void items_near_segment(const Vec2& a, const Vec2& b, double pad, std::vector<std::uint32_t>& out) const {
    out.clear();
    if (empty()) return;
    const double ymin = std::min(a.y(), b.y()), ymax = std::max(a.y(), b.y());
    for (int j = cy(ymin - pad), j1 = cy(ymax + pad); j <= j1; ++j) {
      const double s0 = std::clamp(origin.y() + j * cell - pad, ymin, ymax);
      const double s1 = std::clamp(origin.y() + (j + 1) * cell + pad, ymin, ymax);
      const auto [xl, xr] = slab_x_range(a, b, s0, s1, 0.0);
      // One more cell each side: the cell index of a rounded x may be one off.
      for (int i = std::max(0, cx(xl - pad) - 1), i1 = std::min(nx - 1, cx(xr + pad) + 1); i <= i1; ++i)
        for_cell(i, j, [&](std::uint32_t k) { out.push_back(k); });
    }
  }
  /// Calls f(item) for the items listed in each cell that the box lo..hi meets (clamped
  /// to the grid): an item in several of those cells, once per cell.
  template <class F>
  void for_box(const Vec2& lo, const Vec2& hi, F&& f) const {
    if (empty()) return;
    for (int j = cy(lo.y()), j1 = cy(hi.y()); j <= j1; ++j)
      for (int i = cx(lo.x()), i1 = cx(hi.x()); i <= i1; ++i) for_cell(i, j, f);
  }
  template <class F>
  void for_cell(int x, int y, F&& f) const {
    const std::size_t c = static_cast<std::size_t>(y) * nx + x;
    for (std::uint32_t i = start[c]; i < start[c + 1]; ++i) f(items[i]);
  }
};

/// Membership fast path for the kept region R (the union of the closed kept triangles), on
/// a uniform grid of its own (cells of a few kept triangles, not the bucket grids' sizes).
/// A closed cell that no boundary segment touches lies wholly in the interior of R or
/// wholly outside R: the cell is connected, and a path from a point of R to a point
/// outside R crosses the topological boundary of R, which lies on the boundary segments
/// (edges between a kept and a non-kept or infinite face). One test of its centre thus
/// classifies the whole cell; the cells found inside are flagged, and a query that falls
/// in one is answered without a point location.
struct FlagGrid {
  Vec2 origin = Vec2::Zero();
  double cell = 1.0;
  int nx = 0, ny = 0;
  std::vector<char> inside_cell;  // row-major, 1 = all of the closed cell is in R

  /// True if p falls in a flagged cell. A point within rounding of a cell's border may be
  /// assigned to the neighbouring cell: boundary segments are marked with a pad far above
  /// that rounding (build_flags), so a flagged cell lies at least the pad inside R.
  bool inside(const Vec2& p) const {
    if (nx == 0) return false;
    const double fx = (p.x() - origin.x()) / cell, fy = (p.y() - origin.y()) / cell;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < nx && fy < ny)) return false;  // also NaN
    return inside_cell[static_cast<std::size_t>(fy) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(fx)] != 0;
  }
  /// True if every cell that the box lo..hi meets is flagged (the box lies in R).
  bool box_inside(const Vec2& lo, const Vec2& hi) const {
    if (nx == 0) return false;
    const double fx0 = (lo.x() - origin.x()) / cell, fy0 = (lo.y() - origin.y()) / cell;
    const double fx1 = (hi.x() - origin.x()) / cell, fy1 = (hi.y() - origin.y()) / cell;
    if (!(fx0 >= 0.0 && fy0 >= 0.0 && fx1 < nx && fy1 < ny)) return false;  // also NaN
    for (int j = static_cast<int>(fy0); j <= static_cast<int>(fy1); ++j)
      for (int i = static_cast<int>(fx0); i <= static_cast<int>(fx1); ++i)
        if (!inside_cell[static_cast<std::size_t>(j) * nx + i]) return false;
    return true;
  }
};

/// A convex polygon (CCW): a triangle and the pieces clipped from it.
using ClipPolygon = std::vector<Vec2>;

/// Keeps the part of `poly` where n·x ≥ c (closed); `scratch` is reused storage.
void clip_polygon(ClipPolygon& poly, const Vec2& n, double c, ClipPolygon& scratch) {
  scratch.clear();
  const std::size_t count = poly.size();
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % count];
    const double fp = n.dot(p) - c, fq = n.dot(q) - c;
    if (fp >= 0.0) scratch.push_back(p);
    if ((fp >= 0.0) != (fq >= 0.0)) scratch.push_back(p + (q - p) * (fp / (fp - fq)));
  }
  poly.swap(scratch);
}

/// The pieces (convex, CCW) of `poly` outside the convex polygon given by the half-planes
/// n·x ≥ c (appended to `out`), those of area above min_area only:
/// the part beyond the first half-plane, then beyond the second of what is inside the
/// first, and so on.
void subtract_convex(const ClipPolygon& poly, const std::array<Vec2, 8>& n, const std::array<double, 8>& c, int count,
                     double min_area, std::vector<ClipPolygon>& out, ClipPolygon& scratch) {
  ClipPolygon rest = poly, outside;
  for (int i = 0; i < count && rest.size() >= 3; ++i) {
    outside = rest;
    clip_polygon(outside, -n[i], -c[i], scratch);
    if (outside.size() >= 3 && ring_signed_area(outside) > min_area) out.push_back(outside);
    clip_polygon(rest, n[i], c[i], scratch);
  }
}

struct GapScratch;

}  // namespace

// Bucket densities: a point location scans the triangles listed in its cell, each box
// covering several cells (lists of ~4 boxes per cell at 0.5); a distance query scans rings of cells.
constexpr double kTriangleBoxesPerCell = 0.5;
constexpr double kSegmentBoxesPerCell = 2.0;

struct AlphaShape2D::Impl {
  double alpha = 0.0;
  double short_edge = 0.0;
  DT dt;
  std::vector<Face> faces;                  // finite faces, indexed by info()
  std::vector<std::array<Vec2, 3>> coords;  // their corners (CCW)
  std::vector<char> kept;
  // Derived (rebuilt by refresh()).
  std::vector<std::uint32_t> kept_list;
  std::vector<std::array<Vec2, 3>> kept_coords;  // corners of kept_list, contiguous
  std::vector<std::array<Vec2, 2>> segments;  // boundary edges, kept side on the left
  std::vector<std::array<int, 2>> segment_edge;  // (face id, edge index)
  // The finite faces not kept (the complement of R in the convex hull), their corners
  // (CCW) and, per edge e (opposite corner e), whether the face across it is kept.
  std::vector<std::array<Vec2, 3>> removed_coords;
  std::vector<std::array<bool, 3>> removed_kept_edge;
  Vec2 removed_lo, removed_hi;  // the removed faces' bounding box
  BucketGrid tri_grid, seg_grid;
  FlagGrid flags;
  double area = 0.0;

  /// Numbers the finite faces and keeps those of the α rule (circumradius < α or longest
  /// edge ≤ short_edge); then refresh().
  void classify();

  bool is_kept(Face f) const { return !dt.is_infinite(f) && kept[static_cast<std::size_t>(f->info())]; }

  void refresh() {
    kept_list.clear();
    kept_coords.clear();
    segments.clear();
    segment_edge.clear();
    area = 0.0;
    removed_coords.clear();
    removed_kept_edge.clear();
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity());
    Vec2 hi = -lo;
    removed_lo = lo;
    removed_hi = hi;
    std::vector<std::array<Vec2, 2>> seg_boxes;
    for (std::uint32_t i = 0; i < faces.size(); ++i) {
      if (!kept[i]) {
        const auto& c = coords[i];
        removed_coords.push_back(c);
        removed_kept_edge.push_back({is_kept(faces[i]->neighbor(0)), is_kept(faces[i]->neighbor(1)),
                                     is_kept(faces[i]->neighbor(2))});
        const Vec2 bl = c[0].cwiseMin(c[1]).cwiseMin(c[2]), bh = c[0].cwiseMax(c[1]).cwiseMax(c[2]);
        removed_lo = removed_lo.cwiseMin(bl);
        removed_hi = removed_hi.cwiseMax(bh);
        continue;
      }
      kept_list.push_back(i);
      kept_coords.push_back(coords[i]);
      const auto& c = coords[i];
      area += tri_area(c);
      Vec2 bl = c[0].cwiseMin(c[1]).cwiseMin(c[2]), bh = c[0].cwiseMax(c[1]).cwiseMax(c[2]);
      lo = lo.cwiseMin(bl);
      hi = hi.cwiseMax(bh);
      for (int e = 0; e < 3; ++e) {
        if (is_kept(faces[i]->neighbor(e))) continue;
        const Vec2 a = c[(e + 1) % 3], b = c[(e + 2) % 3];
        segments.push_back({a, b});
        segment_edge.push_back({static_cast<int>(i), e});
        seg_boxes.push_back({a.cwiseMin(b), a.cwiseMax(b)});
      }
    }
    // Each kept triangle is listed along itself, not over its box: a projection fallen back
    // to its hull keeps the long triangles across the gaps between far-apart samples, and
    // their boxes, each over much of the grid, made billions of entries.
    tri_grid.build_triangles(kept_coords, lo, hi, kTriangleBoxesPerCell);
    seg_grid.build(seg_boxes, lo, hi, kSegmentBoxesPerCell);
    build_flags(lo, hi);
  }

  /// Appends the gap points of triangle t (plane coordinates, inside the hull; CCW, with
  /// area; t_scale2 its longest edge squared) to `gaps` (see AlphaShape2D::triangle_gaps);
  /// `serial` is distinct per triangle of one scratch (marks the removed faces already
  /// listed for it).
  void triangle_gaps(const std::array<Vec2, 3>& t, double t_scale2, std::uint32_t serial,
                     const BucketGrid& removed_grid, double tol, double spacing, GapScratch& g,
                     std::vector<Vec2>& gaps) const;

  /// Replaces `poly` by its pieces (in `pieces`) outside every tol-rectangle of a boundary
  /// edge (the points within tol of the edge's line whose foot lies on the edge) and every
  /// tol-octagon inscribed in the disc around a boundary vertex, near it; pieces of area
  /// at most min_area are dropped. What it removes lies within tol of ∂R.
  void subtract_boundary_neighbourhood(const ClipPolygon& poly, double tol, double min_area,
                                       std::vector<ClipPolygon>& pieces, ClipPolygon& scratch) const;

  /// Fills `flags` over lo..hi (the kept triangles' bounding box); see FlagGrid.
  void build_flags(const Vec2& lo, const Vec2& hi);

  /// True if p lies in a closed kept triangle (relative slack 1e-12), answered in O(1)
  /// for points of an all-inside flag cell.
  bool in_kept_triangle(const Vec2& p) const { return flags.inside(p) || in_kept_triangle_slow(p); }

  bool in_kept_triangle_slow(const Vec2& p) const {
    if (tri_grid.empty()) return false;
    const double slack = 1e-12 * tri_grid.cell;
    if (p.x() < tri_grid.origin.x() - slack || p.y() < tri_grid.origin.y() - slack ||
        p.x() > tri_grid.origin.x() + tri_grid.nx * tri_grid.cell + slack ||
        p.y() > tri_grid.origin.y() + tri_grid.ny * tri_grid.cell + slack)
      return false;
    bool inside = false;
    tri_grid.for_cell(tri_grid.cx(p.x()), tri_grid.cy(p.y()), [&](std::uint32_t k) {
      if (inside) return;
      const auto& c = kept_coords[k];
      // Closed triangle, with a relative slack of 1e-12 (far below any tolerance of the
      // callers): points on shared edges and at vertices count as inside, without the
      // exact predicate, whose filter fails on exactly such degenerate cases (samples at
      // triangulation vertices) and falls back to slow exact arithmetic.
      for (int e = 0; e < 3; ++e) {
        const Vec2 a = c[e], b = c[(e + 1) % 3];
        const double o = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
        const double scale = (std::abs(b.x() - a.x()) + std::abs(b.y() - a.y())) *
                             (std::abs(p.x() - a.x()) + std::abs(p.y() - a.y()));
        if (o < -1e-12 * scale) return;  // right of an edge: outside
      }
      inside = true;
    });
    return inside;
  }

  double boundary_distance(const Vec2& p, double stop_below = -1.0) const {
    double best = std::numeric_limits<double>::infinity();
    if (seg_grid.empty()) return best;
    const int x0 = seg_grid.cx(p.x()), y0 = seg_grid.cy(p.y());
    const int max_ring = std::max(seg_grid.nx, seg_grid.ny);
    for (int r = 0; r <= max_ring; ++r) {
      for (int y = y0 - r; y <= y0 + r; ++y) {
        if (y < 0 || y >= seg_grid.ny) continue;
        const bool edge_row = (y == y0 - r || y == y0 + r);
        for (int x = x0 - r; x <= x0 + r; x += (edge_row ? 1 : 2 * r)) {
          if (x >= 0 && x < seg_grid.nx)
            seg_grid.for_cell(x, y, [&](std::uint32_t k) {
              best = std::min(best, point_segment_distance(p, segments[k][0], segments[k][1]));
            });
          if (r == 0) break;
        }
      }
      if (best <= stop_below) return best;
      if (best <= r * seg_grid.cell) return best;
    }
    return best;
  }
};

void AlphaShape2D::Impl::build_flags(const Vec2& lo, const Vec2& hi) {
  // About this many kept triangles (of the mean area) per flag cell: most queries are
  // samples deep inside, and the cells along the boundary stay few (~ perimeter / cell).
  constexpr double kTrianglesPerFlagCell = 2.0;
  // At most this many cells along an axis (≤ 2^22 cells, one byte each).
  constexpr double kMaxFlagCellsPerAxis = 2048.0;
  // Pads of the boundary marking: relative to the cell, and in ulps of the coordinates
  // (the rounding of the cell index and of the segment clipping below is a few ulps).
  constexpr double kPadPerCell = 1e-9;
  constexpr double kPadUlps = 64.0;
  flags = FlagGrid();
  if (kept_list.empty() || segments.empty()) return;
  const Vec2 ext = hi - lo;
  double cell = std::max(std::sqrt(kTrianglesPerFlagCell * area / static_cast<double>(kept_list.size())),
                         std::max(ext.x(), ext.y()) / kMaxFlagCellsPerAxis);
  if (!(cell > 0.0) || !std::isfinite(cell)) return;  // degenerate region: slow path only
  FlagGrid g;
  g.origin = lo;
  g.cell = cell;
  g.nx = std::max(1, static_cast<int>(std::ceil(ext.x() / cell)));
  g.ny = std::max(1, static_cast<int>(std::ceil(ext.y() / cell)));
  const double eps = std::numeric_limits<double>::epsilon();
  const double magnitude = lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).maxCoeff() + cell;
  const double pad = kPadPerCell * cell + kPadUlps * eps * magnitude;
  auto index = [&](double v, double o, int n) {
    return std::clamp(static_cast<int>(std::floor((v - o) / cell)), 0, n - 1);
  };
  // Cells within pad of a boundary segment: for each row crossed, the x-range of the
  // segment's part inside the row's padded slab, widened by its rounding error and pad.
  std::vector<char> touched(static_cast<std::size_t>(g.nx) * g.ny, 0);
  for (const auto& sgm : segments) {
    const Vec2 a = sgm[0], b = sgm[1];
    const double ymin = std::min(a.y(), b.y()), ymax = std::max(a.y(), b.y());
    const double dx = b.x() - a.x(), dy = b.y() - a.y();
    // Rounding of the interpolated x (only used where the slab cuts the segment, dy ≠ 0).
    const double err = dy != 0.0 ? std::abs(dx) * 4.0 * eps * magnitude / std::abs(dy) + 4.0 * eps * magnitude : 0.0;
    const int j0 = index(ymin - pad, g.origin.y(), g.ny), j1 = index(ymax + pad, g.origin.y(), g.ny);
    for (int j = j0; j <= j1; ++j) {
      const double s0 = std::clamp(g.origin.y() + j * cell - pad, ymin, ymax);
      const double s1 = std::clamp(g.origin.y() + (j + 1) * cell + pad, ymin, ymax);
      const auto [xl, xr] = slab_x_range(a, b, s0, s1, err);
      const int i0 = index(xl - pad, g.origin.x(), g.nx), i1 = index(xr + pad, g.origin.x(), g.nx);
      std::fill(touched.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(j) * g.nx + i0),
                touched.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(j) * g.nx + i1 + 1), 1);
    }
  }
  g.inside_cell.assign(touched.size(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * g.nx + i;
      if (!touched[c]) g.inside_cell[c] = in_kept_triangle_slow(g.origin + Vec2(i + 0.5, j + 0.5) * cell) ? 1 : 0;
    }
  flags = std::move(g);
}

AlphaShape2D::AlphaShape2D(const std::vector<Vec2>& points, double alpha, double short_edge)
    : impl_(std::make_unique<Impl>()) {
  impl_->alpha = alpha;
  impl_->short_edge = short_edge;
  std::vector<CPoint> pts;
  pts.reserve(points.size());
  for (const auto& p : points) pts.emplace_back(p.x(), p.y());
  impl_->dt.insert(pts.begin(), pts.end());
  impl_->classify();
}

void AlphaShape2D::Impl::classify() {
  faces.clear();
  coords.clear();
  kept.clear();
  int id = 0;
  const double a2 = alpha * alpha;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    f->info() = id++;
    faces.push_back(f);
    const auto& p0 = f->vertex(0)->point();
    const auto& p1 = f->vertex(1)->point();
    const auto& p2 = f->vertex(2)->point();
    coords.push_back({to_vec(p0), to_vec(p1), to_vec(p2)});
    const double r2 = CGAL::squared_radius(p0, p1, p2);
    const auto& c = coords.back();
    const double longest2 =
        std::max({(c[1] - c[0]).squaredNorm(), (c[2] - c[1]).squaredNorm(), (c[0] - c[2]).squaredNorm()});
    kept.push_back(r2 < a2 || longest2 <= short_edge * short_edge ? 1 : 0);
  }
  refresh();
}

std::size_t AlphaShape2D::refine(const std::vector<Vec2>& points, double tol, const std::vector<Vec2>& exact) {
  Impl& m = *impl_;
  std::vector<CPoint> add;
  for (const auto& p : points)
    if (!contains(p, tol)) add.emplace_back(p.x(), p.y());
  for (const auto& p : exact)
    if (!contains(p, 0.0)) add.emplace_back(p.x(), p.y());
  if (add.empty()) return 0;
  m.dt.insert(add.begin(), add.end());
  m.classify();
  return add.size();
}

AlphaShape2D::~AlphaShape2D() = default;
AlphaShape2D::AlphaShape2D(AlphaShape2D&&) noexcept = default;
AlphaShape2D& AlphaShape2D::operator=(AlphaShape2D&&) noexcept = default;

double AlphaShape2D::alpha() const { return impl_->alpha; }
bool AlphaShape2D::degenerate() const { return impl_->dt.dimension() < 2; }
std::size_t AlphaShape2D::delaunay_triangle_count() const { return impl_->faces.size(); }
std::size_t AlphaShape2D::kept_triangle_count() const { return impl_->kept_list.size(); }
double AlphaShape2D::area() const { return impl_->area; }

double AlphaShape2D::hull_area() const {
  double a = 0.0;
  for (const auto& c : impl_->coords) a += tri_area(c);
  return a;
}

void AlphaShape2D::keep_all() {
  std::fill(impl_->kept.begin(), impl_->kept.end(), 1);
  impl_->refresh();
}

double AlphaShape2D::fill_pinches() {
  Impl& m = *impl_;
  const double before = m.area;
  // Filling the faces around one vertex can pinch a neighbour: a few rounds.
  constexpr int kMaxRounds = 8;
  std::vector<Face> ring;
  std::vector<DT::Vertex_handle> candidates;
  for (int round = 0; round < kMaxRounds; ++round) {
    bool changed = false;
    // A pinched vertex has kept faces on both sides of a gap: it ends boundary edges.
    candidates.clear();
    for (const auto& se : m.segment_edge) {
      const Face f = m.faces[static_cast<std::size_t>(se[0])];
      candidates.push_back(f->vertex(DT::ccw(se[1])));
    }
    // In the order of their points (not of their handles, which are heap addresses: the
    // fills around one vertex change the next, so the order must not follow the heap).
    std::sort(candidates.begin(), candidates.end(), [](const DT::Vertex_handle& a, const DT::Vertex_handle& b) {
      return xy_less(to_vec(a->point()), to_vec(b->point()));
    });
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    for (const auto& v : candidates) {
      ring.clear();
      auto fc = m.dt.incident_faces(v), done = fc;
      do ring.push_back(fc);
      while (++fc != done);
      const std::size_t n = ring.size();
      auto kept_at = [&](std::size_t i) { return m.is_kept(ring[i % n]); };
      std::size_t runs = 0;
      for (std::size_t i = 0; i < n; ++i) runs += kept_at(i) && !kept_at(i + n - 1) ? 1 : 0;
      if (runs < 2) continue;
      // The gaps (runs of faces not kept), each with its angle at v; the one the hull's
      // outside lies in (an infinite face) stays open, else the widest.
      struct Gap {
        std::size_t begin, count;
        double angle;
        bool outside;
      };
      std::vector<Gap> gaps;
      std::size_t start = 0;
      while (!(kept_at(start) && !kept_at(start + 1))) ++start;  // the end of a kept run
      for (std::size_t i = start + 1; i <= start + n; ++i) {
        if (kept_at(i)) continue;
        if (gaps.empty() || kept_at(i - 1)) gaps.push_back({i, 0, 0.0, false});
        Gap& g = gaps.back();
        ++g.count;
        const Face f = ring[i % n];
        if (m.dt.is_infinite(f)) {
          g.outside = true;
          continue;
        }
        const int j = f->index(v);
        const Vec2 p = to_vec(v->point()), a = to_vec(f->vertex(DT::ccw(j))->point()) - p,
                   b = to_vec(f->vertex(DT::cw(j))->point()) - p;
        g.angle += std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
      }
      std::size_t open = 0;
      for (std::size_t k = 1; k < gaps.size(); ++k)
        if (gaps[k].outside > gaps[open].outside ||
            (gaps[k].outside == gaps[open].outside && gaps[k].angle > gaps[open].angle))
          open = k;
      for (std::size_t k = 0; k < gaps.size(); ++k) {
        if (k == open) continue;
        for (std::size_t i = gaps[k].begin; i < gaps[k].begin + gaps[k].count; ++i) {
          const Face f = ring[i % n];
          if (!m.dt.is_infinite(f)) m.kept[static_cast<std::size_t>(f->info())] = 1;
        }
      }
      changed = true;
    }
    if (!changed) break;
    m.refresh();  // the region, and the boundary edges of the next round
  }
  return m.area - before;
}

double AlphaShape2D::cover(const std::vector<Vec2>& points, double tol, std::size_t* uncovered) {
  Impl& m = *impl_;
  const double before = m.area;
  if (m.faces.empty()) {
    if (uncovered) *uncovered = points.size();
    return 0.0;
  }
  bool changed = false;
  Face hint = m.faces.front();
  // Every triangulation vertex (a sample) must touch a kept triangle: checked on the
  // incidence structure, without point location.
  for (auto v = m.dt.finite_vertices_begin(); v != m.dt.finite_vertices_end(); ++v) {
    auto fc = m.dt.incident_faces(v), done = fc;
    Face best;
    double best_r2 = std::numeric_limits<double>::infinity();
    bool touched = false;
    do {
      if (m.dt.is_infinite(fc)) continue;
      if (m.kept[static_cast<std::size_t>(fc->info())]) {
        touched = true;
        break;
      }
      const double r2 = CGAL::squared_radius(fc->vertex(0)->point(), fc->vertex(1)->point(), fc->vertex(2)->point());
      if (r2 < best_r2) {
        best_r2 = r2;
        best = fc;
      }
    } while (++fc != done);
    if (!touched && best != Face()) {
      m.kept[static_cast<std::size_t>(best->info())] = 1;
      changed = true;
    }
  }
  for (const auto& p : points) {
    if (m.in_kept_triangle(p)) continue;
    if (tol > 0.0 && m.boundary_distance(p, tol) <= tol) continue;
    DT::Locate_type lt;
    int li = 0;
    const Face f = m.dt.locate(CPoint(p.x(), p.y()), lt, li, hint);
    auto keep = [&](Face g) {
      if (m.dt.is_infinite(g)) return;
      auto& k = m.kept[static_cast<std::size_t>(g->info())];
      if (!k) {
        k = 1;
        changed = true;
      }
      hint = g;
    };
    switch (lt) {
      case DT::FACE:
        keep(f);
        break;
      case DT::EDGE:
        keep(f);
        keep(f->neighbor(li));
        break;
      case DT::VERTEX: {
        // Keep the incident triangle with the smallest circumradius.
        auto fc = m.dt.incident_faces(f->vertex(li)), done = fc;
        Face best;
        double best_r2 = std::numeric_limits<double>::infinity();
        do {
          if (!m.dt.is_infinite(fc)) {
            const double r2 = CGAL::squared_radius(fc->vertex(0)->point(), fc->vertex(1)->point(),
                                                   fc->vertex(2)->point());
            if (r2 < best_r2) {
              best_r2 = r2;
              best = fc;
            }
          }
        } while (++fc != done);
        if (best != Face()) keep(best);
        break;
      }
      case DT::OUTSIDE_CONVEX_HULL:
        // Just outside the hull (within rounding): keep the finite face across the hull edge.
        keep(f->neighbor(f->index(m.dt.infinite_vertex())));
        break;
      default:
        break;
    }
  }
  if (changed) m.refresh();
  if (uncovered) {
    std::size_t n = 0;
    for (const auto& p : points)
      if (!contains(p, tol)) ++n;
    *uncovered = n;
  }
  return m.area - before;
}

bool AlphaShape2D::contains(const Vec2& p, double tol) const {
  if (impl_->in_kept_triangle(p)) return true;
  return tol > 0.0 && impl_->boundary_distance(p, tol) <= tol;
}

namespace {

/// Narrows [lo, hi] to the t where f0 + t·(f1 − f0) ≥ −slack (a half-plane along a line).
void clip_half_plane(double f0, double f1, double slack, double& lo, double& hi) {
  // Both ends inside: nothing is cut (the crossing would lie at t ≤ 0 or ≥ 1); both
  // outside: all is. Only a segment that crosses the line pays for the division.
  const bool in0 = f0 >= -slack, in1 = f1 >= -slack;
  if (in0 && in1) return;
  if (!in0 && !in1) {
    hi = lo - 1.0;  // empty
    return;
  }
  const double df = f1 - f0;
  const double t = (-slack - f0) / df;
  if (df > 0.0)
    lo = std::max(lo, t);
  else
    hi = std::min(hi, t);
}

/// Appends the centres of n equal pieces of the stretch a + t·d, t in [t0, t1], n the
/// fewest that keep them ≤ spacing apart (len = |d|).
void stretch_points(const Vec2& a, const Vec2& d, double len, double t0, double t1, double spacing,
                    std::vector<Vec2>& out) {
  const int n = std::max(1, static_cast<int>(std::ceil((t1 - t0) * len / spacing)));
  for (int i = 0; i < n; ++i) out.push_back(a + (t0 + (i + 0.5) * (t1 - t0) / n) * d);
}

/// The t where |a + t·d − c| ≤ r, or an empty range (lo > hi).
std::array<double, 2> disc_range(const Vec2& a, const Vec2& d, const Vec2& c, double r) {
  const Vec2 w = a - c;
  const double qa = d.squaredNorm(), qb = d.dot(w), qc = w.squaredNorm() - r * r;
  const double disc = qb * qb - qa * qc;
  if (!(qa > 0.0) || disc < 0.0) return {1.0, 0.0};
  const double root = std::sqrt(disc);
  return {(-qb - root) / qa, (-qb + root) / qa};
}

}  // namespace

std::vector<Vec2> AlphaShape2D::segment_gaps(const Vec2& a, const Vec2& b, double tol, double spacing) const {
  if (!(spacing > 0.0)) throw std::invalid_argument("AlphaShape2D::segment_gaps: spacing must be > 0");
  const Impl& m = *impl_;
  const Vec2 d = b - a;
  const double len = d.norm();
  if (!(len > 0.0)) return contains(a, tol) ? std::vector<Vec2>() : std::vector<Vec2>{a};
  std::vector<Vec2> gaps;
  if (m.tri_grid.empty()) {  // no region: all of ab is one gap
    stretch_points(a, d, len, 0.0, 1.0, spacing, gaps);
    return gaps;
  }
  // Pieces no longer than a cell of the grids, so that each gathers a few candidates; a
  // piece whose box lies in cells of the flag grid (wholly inside the region) is covered.
  const FlagGrid& fg = m.flags;
  const double piece_len = std::min(m.tri_grid.cell, fg.nx > 0 ? fg.cell : m.tri_grid.cell);
  const int pieces = std::max(1, static_cast<int>(std::ceil(len / piece_len)));
  std::vector<std::array<double, 2>> ranges, open;
  std::vector<std::uint32_t> ids;
  for (int piece = 0; piece < pieces; ++piece) {
    const double t0 = static_cast<double>(piece) / pieces, t1 = static_cast<double>(piece + 1) / pieces;
    const Vec2 pa = a + t0 * d, pb = piece + 1 == pieces ? b : a + t1 * d, pd = pb - pa;
    if (fg.box_inside(pa.cwiseMin(pb), pa.cwiseMax(pb))) continue;
    // Covered parameter ranges of the piece (a candidate met twice only repeats its range):
    // each kept triangle it crosses (closed, the relative slack of in_kept_triangle_slow,
    // so that shared edges and vertices leave no crack), and, unless those cover it all,
    // each boundary edge's capsule of radius tol (R ⊕ tol = R ∪ (∂R ⊕ tol): the nearest
    // point of R to a point outside it lies on ∂R).
    ranges.clear();
    m.tri_grid.items_near_segment(pa, pb, 0.0, ids);
    for (std::uint32_t k : ids) {
      const auto& c = m.kept_coords[k];
      double lo = 0.0, hi = 1.0;
      for (int e = 0; e < 3 && lo <= hi; ++e) {
        const Vec2 p = c[e], q = c[(e + 1) % 3], pq = q - p;
        const double f0 = pq.x() * (pa.y() - p.y()) - pq.y() * (pa.x() - p.x());
        const double f1 = pq.x() * (pb.y() - p.y()) - pq.y() * (pb.x() - p.x());
        const double slack = 1e-12 * (std::abs(pq.x()) + std::abs(pq.y())) *
                             (std::abs(pa.x() - p.x()) + std::abs(pa.y() - p.y()) + std::abs(pd.x()) + std::abs(pd.y()));
        clip_half_plane(f0, f1, slack, lo, hi);
      }
      if (lo <= hi) ranges.push_back({lo, hi});
    }
    // The uncovered stretches of [0, 1] (relative length > 1e-12: shorter ones are rounding
    // between two touching ranges).
    auto uncovered = [&ranges](std::vector<std::array<double, 2>>& out) {
      out.clear();
      std::sort(ranges.begin(), ranges.end());
      double covered = 0.0;  // [0, covered] is covered
      for (const auto& r : ranges) {
        if (r[1] < covered) continue;
        if (r[0] > covered + 1e-12) out.push_back({covered, r[0]});
        covered = std::max(covered, r[1]);
        if (covered >= 1.0) break;
      }
      if (covered < 1.0 - 1e-12) out.push_back({covered, 1.0});
    };
    uncovered(open);
    if (open.empty()) continue;
    if (tol > 0.0) {
      m.seg_grid.items_near_segment(pa, pb, tol, ids);
      for (std::uint32_t k : ids) {
        const Vec2 s0 = m.segments[k][0], s1 = m.segments[k][1];
        for (const Vec2& c : {s0, s1}) {
          const auto r = disc_range(pa, pd, c, tol);
          if (r[0] <= r[1] && r[1] >= 0.0 && r[0] <= 1.0) ranges.push_back({std::max(r[0], 0.0), std::min(r[1], 1.0)});
        }
        const Vec2 u = s1 - s0;
        const double ul = u.norm();
        if (!(ul > 0.0)) continue;
        const Vec2 un = u / ul, n(-un.y(), un.x());
        // The rectangle 0 ≤ un·(P − s0) ≤ ul, |n·(P − s0)| ≤ tol.
        double lo = 0.0, hi = 1.0;
        const double ua = un.dot(pa - s0), ub = un.dot(pb - s0), na = n.dot(pa - s0), nb = n.dot(pb - s0);
        clip_half_plane(ua, ub, 0.0, lo, hi);
        clip_half_plane(ul - ua, ul - ub, 0.0, lo, hi);
        clip_half_plane(tol - na, tol - nb, 0.0, lo, hi);
        clip_half_plane(tol + na, tol + nb, 0.0, lo, hi);
        if (lo <= hi) ranges.push_back({lo, hi});
      }
      uncovered(open);
    }
    for (const auto& g : open) stretch_points(pa, pd, pd.norm(), g[0], g[1], spacing, gaps);
  }
  return gaps;
}

namespace {

/// True if d lies right of the line of one of t's edges or on it (t CCW; within a
/// relative 1e-12, the rounding of touching triangles): t ∩ d has no area. The cheap
/// rejection before clipping; called both ways.
bool separated_by_edge_of(const std::array<Vec2, 3>& t, const std::array<Vec2, 3>& d) {
  for (int e = 0; e < 3; ++e) {
    const Vec2 a = t[e], ab = t[(e + 1) % 3] - a;
    const double ab_scale = std::abs(ab.x()) + std::abs(ab.y());
    bool all_right = true;
    for (const Vec2& p : d) {
      const double o = ab.x() * (p.y() - a.y()) - ab.y() * (p.x() - a.x());
      all_right = all_right && o <= 1e-12 * ab_scale * (std::abs(p.x() - a.x()) + std::abs(p.y() - a.y()));
    }
    if (all_right) return true;
  }
  return false;
}

}  // namespace

void AlphaShape2D::Impl::subtract_boundary_neighbourhood(const ClipPolygon& poly, double tol, double min_area,
                                                         std::vector<ClipPolygon>& pieces, ClipPolygon& scratch) const {
  pieces.assign(1, poly);
  if (!(tol > 0.0) || seg_grid.empty()) return;
  Vec2 lo = poly[0], hi = poly[0];
  for (const Vec2& v : poly) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Vec2 pad = Vec2::Constant(tol);
  std::vector<std::uint32_t> near;
  seg_grid.for_box(lo - pad, hi + pad, [&](std::uint32_t k) { near.push_back(k); });
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  std::array<Vec2, 8> n;
  n.fill(Vec2::Zero());
  std::array<double, 8> c{};
  std::vector<ClipPolygon> next;
  auto subtract = [&](int count) {
    next.clear();
    for (const ClipPolygon& piece : pieces) subtract_convex(piece, n, c, count, min_area, next, scratch);
    pieces.swap(next);
  };
  for (std::uint32_t k : near) {
    if (pieces.empty()) return;
    const Vec2 a = segments[k][0], b = segments[k][1];
    const double len = (b - a).norm();
    if (!(len > 0.0)) continue;
    const Vec2 u = (b - a) / len, v(-u.y(), u.x());
    n[0] = u;
    n[1] = -u;
    n[2] = v;
    n[3] = -v;
    c[0] = u.dot(a);
    c[1] = -u.dot(b);
    c[2] = v.dot(a) - tol;
    c[3] = -v.dot(a) - tol;
    subtract(4);
  }
  // The discs around the vertices, by their inscribed octagons (apothem tol·cos(π/8)).
  const double apothem = tol * std::cos(M_PI / 8.0);
  for (std::uint32_t k : near)
    for (const Vec2& p : segments[k]) {
      if (pieces.empty()) return;
      for (int i = 0; i < 8; ++i) {
        const Vec2 d(std::cos(i * M_PI / 4.0), std::sin(i * M_PI / 4.0));
        n[i] = -d;
        c[i] = -d.dot(p) - apothem;
      }
      subtract(8);
    }
}

namespace {

/// Reused storage of the gap search of one thread (triangles_gaps).
struct GapScratch {
  std::vector<std::uint32_t> seen;  ///< per removed face: the last triangle that listed it
  std::vector<std::uint32_t> ids;
  ClipPolygon poly, clip;
  std::vector<ClipPolygon> pieces;
};

}  // namespace

void AlphaShape2D::Impl::triangle_gaps(const std::array<Vec2, 3>& t, double t_scale2, std::uint32_t serial,
                                       const BucketGrid& removed_grid, double tol, double spacing, GapScratch& g,
                                       std::vector<Vec2>& gaps) const {
  const Vec2 lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]), hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
  // The removed faces listed in the cells t meets (both listed along their area only),
  // each once.
  g.ids.clear();
  removed_grid.for_triangle_cells(t, [&](int x, int y) {
    removed_grid.for_cell(x, y, [&](std::uint32_t k) {
      if (g.seen[k] == serial) return;
      g.seen[k] = serial;
      g.ids.push_back(k);
    });
  });
  for (std::uint32_t k : g.ids) {
    const auto& d = removed_coords[k];
    const Vec2 dlo = d[0].cwiseMin(d[1]).cwiseMin(d[2]), dhi = d[0].cwiseMax(d[1]).cwiseMax(d[2]);
    if ((dlo.array() > hi.array()).any() || (dhi.array() < lo.array()).any()) continue;
    if (separated_by_edge_of(t, d) || separated_by_edge_of(d, t)) continue;
    ClipPolygon& poly = g.poly;
    poly.assign(t.begin(), t.end());
    // t ∩ d, then less the strip along each edge of d that a kept face lies across: that
    // edge is on ∂R, and a point of d whose barycentric weight on the opposite corner r is
    // below tol / max(|r − p|, |r − q|) lies within tol of the edge pq (it is within that
    // weight times |r − y| of a point y of pq), i.e. closer to pq's line than w below.
    double d_scale2 = 0.0;
    for (int e = 0; e < 3 && poly.size() >= 3; ++e) {
      const Vec2 p = d[(e + 1) % 3], q = d[(e + 2) % 3], r = d[e];
      const Vec2 pq = q - p;
      d_scale2 = std::max(d_scale2, pq.squaredNorm());
      const Vec2 inward(-pq.y(), pq.x());  // left of p→q: d's side, d being CCW
      clip_polygon(poly, inward, inward.dot(p), g.clip);
      if (!removed_kept_edge[k][e] || !(tol > 0.0) || poly.size() < 3) continue;
      const double len = pq.norm();
      const double height = inward.dot(r - p) / len;
      const double w = tol * height / std::max((r - p).norm(), (r - q).norm());
      clip_polygon(poly, inward / len, (inward / len).dot(p) + w, g.clip);
    }
    // What is left lies in d, farther than the strips from d's edges on ∂R (a piece of no
    // area at the scale of the two triangles is rounding of the clipping).
    const double min_area = 1e-12 * std::max(t_scale2, d_scale2);
    if (poly.size() < 3 || !(ring_signed_area(poly) > min_area)) continue;
    // The strips are narrow where d is flat, and a piece near a corner of ∂R may be
    // covered by several edges: the piece less every boundary edge's tol-rectangle and
    // boundary vertex's inscribed tol-octagon nearby (all within R ⊕ tol) is what remains.
    subtract_boundary_neighbourhood(poly, tol, min_area, g.pieces, g.clip);
    for (const ClipPolygon& piece : g.pieces) {
      Vec2 c = Vec2::Zero();
      for (const Vec2& v : piece) c += v;
      c /= static_cast<double>(piece.size());
      gaps.push_back(c);
      // Points along the piece's sides longer than `spacing`, at most that apart and a
      // quarter of the way in (inside the convex piece), so that one repair closes a long
      // sliver.
      for (std::size_t i = 0; i < piece.size(); ++i) {
        const Vec2 p = piece[i], pq = piece[(i + 1) % piece.size()] - p;
        const double len = pq.norm();
        if (!(len > spacing)) continue;
        const std::size_t first = gaps.size();
        stretch_points(p, pq, len, 0.0, 1.0, spacing, gaps);
        for (std::size_t j = first; j < gaps.size(); ++j) gaps[j] += 0.25 * (c - gaps[j]);
      }
    }
  }
}

std::vector<Vec2> AlphaShape2D::triangles_gaps(const std::vector<std::array<Vec2, 3>>& triangles, double tol,
                                               double spacing) const {
  if (!(spacing > 0.0)) throw std::invalid_argument("AlphaShape2D::triangles_gaps: spacing must be > 0");
  if (triangles.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("AlphaShape2D::triangles_gaps: too many triangles");
  const Impl& m = *impl_;
  // The removed faces on a grid, listed along their area (built here, not with every
  // change of the region: most changes are followed by no such query).
  BucketGrid removed_grid;
  removed_grid.build_triangles(m.removed_coords, m.removed_lo, m.removed_hi, kTriangleBoxesPerCell);
  tbb::enumerable_thread_specific<std::vector<Vec2>> found;
  tbb::enumerable_thread_specific<GapScratch> scratch([&m] {
    GapScratch g;
    g.seen.assign(m.removed_coords.size(), std::numeric_limits<std::uint32_t>::max());
    return g;
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles.size(), 512), [&](const auto& rg) {
    auto& out = found.local();
    auto& g = scratch.local();
    for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
      std::array<Vec2, 3> t = triangles[i];
      const double t_scale2 =
          std::max({(t[1] - t[0]).squaredNorm(), (t[2] - t[1]).squaredNorm(), (t[0] - t[2]).squaredNorm()});
      const double t_area = tri_area(t);
      // A triangle without area (within rounding) is its longest edge: checked as a segment.
      if (!(std::abs(t_area) > 1e-12 * t_scale2)) {
        int longest = 0;
        for (int e = 1; e < 3; ++e)
          if ((t[(e + 1) % 3] - t[e]).squaredNorm() > (t[(longest + 1) % 3] - t[longest]).squaredNorm()) longest = e;
        const auto seg = segment_gaps(t[longest], t[(longest + 1) % 3], tol, spacing);
        out.insert(out.end(), seg.begin(), seg.end());
        continue;
      }
      if (t_area < 0.0) std::swap(t[1], t[2]);
      // Every finite face kept: the hull is the region.
      if (!removed_grid.empty())
        m.triangle_gaps(t, t_scale2, static_cast<std::uint32_t>(i), removed_grid, tol, spacing, g, out);
    }
  });
  std::vector<Vec2> gaps;
  for (const auto& f : found) gaps.insert(gaps.end(), f.begin(), f.end());
  // The same list whatever the thread schedule.
  std::sort(gaps.begin(), gaps.end(), xy_less);
  gaps.erase(std::unique(gaps.begin(), gaps.end()), gaps.end());
  return gaps;
}

std::vector<Vec2> AlphaShape2D::triangle_gaps(const Vec2& a, const Vec2& b, const Vec2& c, double tol,
                                              double spacing) const {
  return triangles_gaps({{a, b, c}}, tol, spacing);
}

bool AlphaShape2D::contains_unaccelerated(const Vec2& p, double tol) const {
  if (impl_->in_kept_triangle_slow(p)) return true;
  return tol > 0.0 && impl_->boundary_distance(p, tol) <= tol;
}

AlphaShape2D::InsideGrid AlphaShape2D::inside_grid() const {
  const FlagGrid& f = impl_->flags;
  InsideGrid g;
  if (f.nx == 0) return g;
  g.origin = f.origin;
  g.cell = f.cell;
  g.nx = f.nx;
  g.ny = f.ny;
  g.inside_cells = static_cast<std::size_t>(std::count(f.inside_cell.begin(), f.inside_cell.end(), 1));
  return g;
}

double AlphaShape2D::signed_distance(const Vec2& p) const {
  const double d = impl_->boundary_distance(p);
  return impl_->in_kept_triangle(p) ? -d : d;
}

std::vector<std::pair<std::array<Vec2, 3>, char>> AlphaShape2D::snapshot() const {
  const Impl& m = *impl_;
  std::vector<std::pair<std::array<Vec2, 3>, char>> out(m.coords.size());
  for (std::size_t i = 0; i < m.coords.size(); ++i) {
    auto c = m.coords[i];
    // From the lowest corner, so that a triangle compares equal whatever corner CGAL
    // starts it at (rotation keeps the orientation).
    std::rotate(c.begin(), std::min_element(c.begin(), c.end(), xy_less), c.end());
    out[i] = {c, m.kept[i] ? char(1) : char(0)};
  }
  return out;
}

std::vector<PolygonWithHoles2> AlphaShape2D::polygons() const {
  const Impl& m = *impl_;
  const std::size_t nseg = m.segments.size();
  // Boundary edge lookup: 3·face id + edge index → segment index (kNone: not a boundary edge).
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> seg_of(3 * m.faces.size(), kNone);
  for (std::size_t s = 0; s < nseg; ++s)
    seg_of[3 * static_cast<std::size_t>(m.segment_edge[s][0]) + static_cast<std::size_t>(m.segment_edge[s][1])] = s;
  std::vector<char> used(nseg, 0);
  struct Loop {
    std::vector<Vec2> ring;
    int face = -1;  // a kept face on the loop's left
    double area = 0.0;
  };
  std::vector<Loop> loops;
  for (std::size_t s0 = 0; s0 < nseg; ++s0) {
    if (used[s0]) continue;
    Loop loop;
    loop.face = m.segment_edge[s0][0];
    std::size_t s = s0;
    while (!used[s]) {
      used[s] = 1;
      Face f = m.faces[static_cast<std::size_t>(m.segment_edge[s][0])];
      const int e = m.segment_edge[s][1];
      loop.ring.push_back(m.segments[s][0]);
      // Next boundary edge leaving the target vertex v: rotate clockwise around v
      // through kept faces until the neighbour across the outgoing edge is not kept.
      const auto v = f->vertex(DT::cw(e));
      Face g = f;
      for (std::size_t guard = 0; guard < 1000000; ++guard) {
        const int j = g->index(v);
        const int out = DT::cw(j);  // edge of g from v to g->vertex(ccw(j))
        const Face n = g->neighbor(out);
        if (!m.is_kept(n)) {
          const std::size_t next = seg_of[3 * static_cast<std::size_t>(g->info()) + static_cast<std::size_t>(out)];
          s = next == kNone ? s0 : next;
          break;
        }
        g = n;
      }
    }
    loop.area = ring_signed_area(loop.ring);
    loops.push_back(std::move(loop));
  }
  std::vector<PolygonWithHoles2> out;
  std::vector<std::size_t> outer_ids;
  for (std::size_t i = 0; i < loops.size(); ++i)
    if (loops[i].area > 0.0) {
      outer_ids.push_back(i);
      PolygonWithHoles2 p;
      p.outer = loops[i].ring;
      out.push_back(std::move(p));
    }
  auto point_in_ring = [](const Vec2& p, const std::vector<Vec2>& r) {
    bool in = false;
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
      if ((r[i].y() > p.y()) != (r[j].y() > p.y()) &&
          p.x() < (r[j].x() - r[i].x()) * (p.y() - r[i].y()) / (r[j].y() - r[i].y()) + r[i].x())
        in = !in;
    }
    return in;
  };
  for (auto& loop : loops) {
    if (loop.area > 0.0) continue;
    // The owner is the smallest outer ring containing the centroid of a kept triangle
    // that borders the hole.
    const auto& c = m.coords[static_cast<std::size_t>(loop.face)];
    const Vec2 probe = (c[0] + c[1] + c[2]) / 3.0;
    int owner = -1;
    double owner_area = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < outer_ids.size(); ++k) {
      const double a = loops[outer_ids[k]].area;
      if (a < owner_area && point_in_ring(probe, out[k].outer)) {
        owner = static_cast<int>(k);
        owner_area = a;
      }
    }
    if (owner >= 0) out[static_cast<std::size_t>(owner)].holes.push_back(std::move(loop.ring));
  }
  return out;
}

std::size_t merge_collinear(std::vector<Vec2>& ring, double angle_tol_rad, double dist_tol) {
  const std::size_t n0 = ring.size();
  // Drop exact repeats first.
  std::vector<Vec2> r;
  r.reserve(n0);
  for (const auto& p : ring)
    if (r.empty() || p != r.back()) r.push_back(p);
  while (r.size() > 1 && r.front() == r.back()) r.pop_back();
  if (r.size() < 3) {
    ring = std::move(r);
    return n0 - ring.size();
  }
  // Start at the lexicographically lowest vertex: an extreme point, hence a corner.
  std::size_t s0 = 0;
  for (std::size_t i = 1; i < r.size(); ++i)
    if (xy_less(r[i], r[s0])) s0 = i;
  std::rotate(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(s0), r.end());
  r.push_back(r.front());  // closed for the sweep
  const double sin_tol = std::sin(angle_tol_rad);
  // Greedy: extend the segment anchor → r[j] while every skipped vertex lies within
  // max(dist_tol, sin_tol·|segment|) of it, strictly between its ends.
  // The skipped vertices' offsets w from the anchor all pass when the extreme ones do:
  // along = w·d and the deviation d × w are linear in w, so their extremes over the
  // skipped vertices are reached at corners of their convex hull. The hull of a straight
  // run has two corners, so a long run costs O(1) per step instead of O(run); a hull
  // grown past kMaxHullCorners (a long gentle arc) falls back to testing every vertex.
  constexpr std::size_t kMaxHullCorners = 16;
  std::vector<Vec2> hull, grown;
  bool use_hull = true;
  // Adds w to the hull (CCW, no collinear corners), or gives up on it.
  auto add_to_hull = [&](const Vec2& w) {
    if (!use_hull) return;
    auto left_of = [](const Vec2& o, const Vec2& p, const Vec2& q) {
      return (p.x() - o.x()) * (q.y() - o.y()) - (p.y() - o.y()) * (q.x() - o.x());
    };
    if (hull.size() >= 3) {
      bool inside = true;
      for (std::size_t i = 0; i < hull.size() && inside; ++i)
        inside = left_of(hull[i], hull[(i + 1) % hull.size()], w) >= 0.0;
      if (inside) return;
    }
    // Andrew's monotone chain over the corners and w.
    grown = hull;
    grown.push_back(w);
    std::sort(grown.begin(), grown.end(), xy_less);
    grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
    hull.clear();
    if (grown.size() < 3) {
      hull = grown;
      return;
    }
    std::vector<Vec2> h(2 * grown.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < grown.size(); ++i) {
      while (k >= 2 && left_of(h[k - 2], h[k - 1], grown[i]) <= 0.0) --k;
      h[k++] = grown[i];
    }
    for (std::size_t i = grown.size() - 1, lower = k + 1; i-- > 0;) {
      while (k >= lower && left_of(h[k - 2], h[k - 1], grown[i]) <= 0.0) --k;
      h[k++] = grown[i];
    }
    h.resize(k - 1);
    hull = std::move(h);
    if (hull.size() > kMaxHullCorners) use_hull = false;
  };
  auto passes = [&](const Vec2& w, const Vec2& d, double len, double lim) {
    const double along = w.dot(d) / len;
    if (along <= 0.0 || along >= len) return false;
    return std::abs(d.x() * w.y() - d.y() * w.x()) / len <= lim;
  };
  auto fits = [&](std::size_t a, std::size_t j) {
    const Vec2 d = r[j] - r[a];
    const double len = d.norm();
    if (len == 0.0) return false;
    const double lim = std::max(dist_tol, sin_tol * len);
    if (use_hull) return std::all_of(hull.begin(), hull.end(), [&](const Vec2& w) { return passes(w, d, len, lim); });
    for (std::size_t k = a + 1; k < j; ++k)
      if (!passes(r[k] - r[a], d, len, lim)) return false;
    return true;
  };
  std::vector<Vec2> out;
  std::size_t a = 0;
  out.push_back(r[0]);
  while (a + 1 < r.size()) {
    std::size_t j = a + 1;
    // Runs are capped at kMaxRun vertices so that the check stays linear in the ring size.
    constexpr std::size_t kMaxRun = 256;
    hull.clear();
    use_hull = true;
    while (j + 1 < r.size() && j + 1 - a <= kMaxRun) {
      add_to_hull(r[j] - r[a]);  // the vertices a + 1 … j are skipped if j + 1 fits
      if (!fits(a, j + 1)) break;
      ++j;
    }
    if (j + 1 < r.size()) out.push_back(r[j]);
    a = j;
  }
  ring = std::move(out);
  return n0 - ring.size();
}

namespace {
/// Orientation of (p, q, r) as -1 (right turn), 0 (collinear), +1 (left turn); exact.
int orient(const Vec2& p, const Vec2& q, const Vec2& r) {
  const CGAL::Orientation o = CGAL::orientation(CPoint(p.x(), p.y()), CPoint(q.x(), q.y()), CPoint(r.x(), r.y()));
  return o == CGAL::LEFT_TURN ? 1 : o == CGAL::RIGHT_TURN ? -1 : 0;
}

/// True if the closed segments pq and rs share a point (CGAL, exact predicates).
bool closed_segments_meet(const Vec2& p, const Vec2& q, const Vec2& r, const Vec2& s) {
  return CGAL::do_intersect(K::Segment_2(CPoint(p.x(), p.y()), CPoint(q.x(), q.y())),
                            K::Segment_2(CPoint(r.x(), r.y()), CPoint(s.x(), s.y())));
}
}  // namespace

std::size_t grow_simplify(std::vector<PolygonWithHoles2>& polys, double max_dev, bool merge_corners) {
  // Every ring as a circular doubly linked list over one node array.
  struct Node {
    Vec2 p;
    std::uint32_t prev, next, ring;
    double dev;  // accumulated deviation of the edge node → next
    std::uint32_t version;
    bool alive;
  };
  std::vector<Node> nodes;
  std::vector<std::vector<Vec2>*> rings;
  for (auto& poly : polys) {
    rings.push_back(&poly.outer);
    for (auto& h : poly.holes) rings.push_back(&h);
  }
  std::vector<std::size_t> ring_start(rings.size()), ring_alive(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r) {
    const auto& ring = *rings[r];
    const auto base = static_cast<std::uint32_t>(nodes.size()), n = static_cast<std::uint32_t>(ring.size());
    ring_start[r] = base;
    ring_alive[r] = n;
    for (std::uint32_t i = 0; i < n; ++i)
      nodes.push_back({ring[i], base + (i + n - 1) % n, base + (i + 1) % n, static_cast<std::uint32_t>(r), 0.0, 0, true});
  }
  if (nodes.empty() || !(max_dev > 0.0)) return 0;

  // Uniform grid (about two vertices per cell) holding each vertex and each edge (node →
  // next) in the cells its box meets. A moved vertex or a new edge is added again; stale
  // entries are skipped or re-tested at their current geometry, so lookups stay complete.
  Vec2 lo = nodes[0].p, hi = nodes[0].p;
  for (const auto& nd : nodes) {
    lo = lo.cwiseMin(nd.p);
    hi = hi.cwiseMax(nd.p);
  }
  const Vec2 ext = (hi - lo).cwiseMax(Vec2::Constant(max_dev));
  const double cell = std::max(std::sqrt(ext.x() * ext.y() / (0.5 * static_cast<double>(nodes.size()))),
                               std::max(ext.x(), ext.y()) / 4096.0);
  const int nx = static_cast<int>(ext.x() / cell) + 1, ny = static_cast<int>(ext.y() / cell) + 1;
  auto cx = [&](double x) { return std::clamp(static_cast<int>((x - lo.x()) / cell), 0, nx - 1); };
  auto cy = [&](double y) { return std::clamp(static_cast<int>((y - lo.y()) / cell), 0, ny - 1); };
  std::vector<std::vector<std::uint32_t>> vertex_cells(static_cast<std::size_t>(nx) * ny), edge_cells;
  auto add_vertex = [&](std::uint32_t i) {
    vertex_cells[static_cast<std::size_t>(cy(nodes[i].p.y())) * nx + cx(nodes[i].p.x())].push_back(i);
  };
  for (std::uint32_t i = 0; i < nodes.size(); ++i) add_vertex(i);
  // Calls f(i) for every entry of `cells` in the cells meeting the box [blo, bhi].
  auto for_cells = [&](std::vector<std::vector<std::uint32_t>>& cells, const Vec2& blo, const Vec2& bhi, auto&& f) {
    for (int y = cy(blo.y()); y <= cy(bhi.y()); ++y)
      for (int x = cx(blo.x()); x <= cx(bhi.x()); ++x)
        for (const std::uint32_t i : cells[static_cast<std::size_t>(y) * nx + x])
          if (!f(i)) return false;
    return true;
  };
  auto add_edge = [&](std::uint32_t i) {
    const Vec2 &p = nodes[i].p, &q = nodes[nodes[i].next].p;
    for (int y = cy(std::min(p.y(), q.y())); y <= cy(std::max(p.y(), q.y())); ++y)
      for (int x = cx(std::min(p.x(), q.x())); x <= cx(std::max(p.x(), q.x())); ++x)
        edge_cells[static_cast<std::size_t>(y) * nx + x].push_back(i);
  };
  if (merge_corners) {
    // Only corner merges add new edges through free space; removing a notch vertex does
    // not need them (see corner_valid).
    edge_cells.resize(vertex_cells.size());
    for (std::uint32_t i = 0; i < nodes.size(); ++i) add_edge(i);
  }

  // True if no live vertex other than the excluded ones lies in the closed triangle
  // (p0, p1, p2) (clockwise: the added material lies right of the ring).
  auto triangle_empty = [&](const Vec2& p0, const Vec2& p1, const Vec2& p2, std::uint32_t x0, std::uint32_t x1,
                            std::uint32_t x2) {
    return for_cells(vertex_cells, p0.cwiseMin(p1).cwiseMin(p2), p0.cwiseMax(p1).cwiseMax(p2), [&](std::uint32_t q) {
      if (q == x0 || q == x1 || q == x2 || !nodes[q].alive) return true;
      const Vec2& pq = nodes[q].p;
      // Inside or on unless strictly left of a side.
      return orient(p0, p1, pq) > 0 || orient(p1, p2, pq) > 0 || orient(p2, p0, pq) > 0;
    });
  };

  // Move 1, notch: removing b adds the triangle (a, b, c); b must turn right (strictly).
  auto notch_deviation = [&](std::uint32_t b) {
    const Node& nb = nodes[b];
    const Node &na = nodes[nb.prev], &nc = nodes[nb.next];
    if (ring_alive[nb.ring] <= 3 || orient(na.p, nb.p, nc.p) >= 0) return std::numeric_limits<double>::infinity();
    const Vec2 ac = nc.p - na.p, ab = nb.p - na.p;
    const double h = std::abs(ac.x() * ab.y() - ac.y() * ab.x()) / ac.norm();
    return std::max(na.dev, nb.dev) + h;
  };
  // A triangle (a, b, c) whose sides ab and bc are ring edges is crossed by no other edge
  // unless a vertex lies in it (an edge cannot enter and leave through ac alone).
  auto notch_valid = [&](std::uint32_t b) {
    const std::uint32_t a = nodes[b].prev, c = nodes[b].next;
    return triangle_empty(nodes[a].p, nodes[b].p, nodes[c].p, a, b, c);
  };

  // Move 2, corner: two left turns b, c on the edge b → c are replaced by the point x where
  // the lines a → b and d → c meet beyond them; this adds the triangle (b, x, c).
  struct Corner {
    Vec2 x = Vec2::Zero();
    double h = std::numeric_limits<double>::infinity();  // x's distance from the edge bc
    double dev = std::numeric_limits<double>::infinity();
  };
  auto corner = [&](std::uint32_t b) {
    Corner out;
    const std::uint32_t a = nodes[b].prev, c = nodes[b].next, d = nodes[c].next;
    if (!merge_corners || ring_alive[nodes[b].ring] <= 3) return out;
    const Vec2 &pa = nodes[a].p, &pb = nodes[b].p, &pc = nodes[c].p, &pd = nodes[d].p;
    if (orient(pa, pb, pc) <= 0 || orient(pb, pc, pd) <= 0) return out;
    const Vec2 u = pb - pa, w = pc - pd, bc = pc - pb;
    const double den = u.x() * w.y() - u.y() * w.x();
    if (!(std::abs(den) > 0.0)) return out;
    const double t = (bc.x() * w.y() - bc.y() * w.x()) / den;
    const double s = (bc.x() * u.y() - bc.y() * u.x()) / den;
    if (!(t > 0.0) || !(s > 0.0)) return out;  // the lines meet behind b or c: turns sum to ≥ 180°
    out.x = pb + t * u;
    if (!out.x.allFinite() || orient(pb, pc, out.x) >= 0) return out;  // x must lie right of b → c
    out.h = point_segment_distance(out.x, pb, pc);
    out.dev = std::max({nodes[a].dev, nodes[c].dev, nodes[b].dev + out.h});
    return out;
  };
  // The added triangle holds no other vertex and its new sides b–x, x–c meet no edge but
  // the three it replaces (a long edge could cross both without a vertex inside).
  auto corner_valid = [&](std::uint32_t b, const Vec2& x) {
    const std::uint32_t a = nodes[b].prev, c = nodes[b].next;
    const Vec2 &pb = nodes[b].p, &pc = nodes[c].p;
    if (!triangle_empty(pb, pc, x, a, b, c)) return false;  // (b, c, x) is clockwise
    return for_cells(edge_cells, pb.cwiseMin(pc).cwiseMin(x), pb.cwiseMax(pc).cwiseMax(x), [&](std::uint32_t e) {
      if (e == a || e == b || e == c || !nodes[e].alive) return true;
      const Vec2 &p = nodes[e].p, &q = nodes[nodes[e].next].p;
      return !closed_segments_meet(pb, x, p, q) && !closed_segments_meet(x, pc, p, q);
    });
  };

  // Deterministic: smallest deviation first, ties by position, then node and move.
  using Entry = std::tuple<double, double, double, std::uint32_t, std::uint32_t, int>;  // dev, x, y, node, version, move
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  auto push = [&](std::uint32_t b) {
    const Node& nb = nodes[b];
    const double dn = notch_deviation(b);
    if (dn < max_dev) heap.emplace(dn, nb.p.x(), nb.p.y(), b, nb.version, 0);
    const double dc = corner(b).dev;
    if (dc < max_dev) heap.emplace(dc, nb.p.x(), nb.p.y(), b, nb.version, 1);
  };
  for (std::uint32_t i = 0; i < nodes.size(); ++i) push(i);
  std::size_t removed = 0;
  // After a change, the nodes whose moves read it get a new version and are pushed again.
  auto touch = [&](std::initializer_list<std::uint32_t> changed) {
    for (const std::uint32_t i : changed) ++nodes[i].version;
    for (const std::uint32_t i : changed) push(i);
  };
  while (!heap.empty()) {
    const auto [dev, px, py, b, version, move] = heap.top();
    heap.pop();
    (void)dev;
    (void)px;
    (void)py;
    Node& nb = nodes[b];
    if (!nb.alive || nb.version != version) continue;
    const std::uint32_t a = nb.prev, c = nb.next;
    if (move == 0) {
      const double dn = notch_deviation(b);
      if (!(dn < max_dev) || !notch_valid(b)) continue;
      nodes[a].dev = dn;
      nodes[a].next = c;
      nodes[c].prev = a;
      nb.alive = false;
      --ring_alive[nb.ring];
      ++removed;
      if (merge_corners) add_edge(a);
      // Notch moves read prev and next, corner moves also the node after next.
      touch({nodes[a].prev, a, c});
    } else {
      const Corner k = corner(b);
      if (!(k.dev < max_dev) || !corner_valid(b, k.x)) continue;
      const std::uint32_t dn = nodes[c].next;
      nodes[a].dev = std::max(nodes[a].dev, nb.dev + k.h);
      nb.dev = std::max(nodes[c].dev, nb.dev + k.h);
      nb.p = k.x;
      nb.next = dn;
      nodes[dn].prev = b;
      nodes[c].alive = false;
      --ring_alive[nb.ring];
      ++removed;
      add_vertex(b);
      add_edge(a);
      add_edge(b);
      touch({nodes[a].prev, a, b, dn});
    }
  }
  // Rebuild the rings from their first surviving vertex, in the original order.
  for (std::size_t r = 0; r < rings.size(); ++r) {
    auto& ring = *rings[r];
    const std::size_t n = ring.size();
    std::uint32_t s = static_cast<std::uint32_t>(ring_start[r]);
    while (!nodes[s].alive && s < ring_start[r] + n - 1) ++s;
    ring.clear();
    std::uint32_t k = s;
    do {
      ring.push_back(nodes[k].p);
      k = nodes[k].next;
    } while (k != s && ring.size() <= n);
  }
  return removed;
}

double ring_signed_area(const std::vector<Vec2>& ring) {
  double a = 0.0;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
    a += ring[j].x() * ring[i].y() - ring[i].x() * ring[j].y();
  return 0.5 * a;
}

}  // namespace loom
