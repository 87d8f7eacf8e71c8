#include "index/simplify/alpha_sim.hpp"

#include "core/stopwatch.hpp"
#include "core/io/file_stems.hpp"

#include "core/error.hpp"
#include "index/embree_index.hpp"
#include "index/simplify/extrusion.hpp"
#include "index/simplify/lost_space.hpp"

// CGAL before OpenCASCADE, whose macro Handle breaks CGAL's headers.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Pln.hxx>

#include <boost/sort/spreadsort/integer_sort.hpp>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <cstring>
#include <cmath>
#include <iterator>
#include <limits>
#include <mutex>
#include <random>
#include <stdexcept>
#include <tuple>

namespace loom {

const char* projection_status_name(ProjectionStatus s) {
  switch (s) {
    case ProjectionStatus::Ok: return "ok";
    case ProjectionStatus::Repaired: return "repaired";
    case ProjectionStatus::Empty: return "empty";
    case ProjectionStatus::Torn: return "torn";
    case ProjectionStatus::Eroded: return "eroded";
  }
  return "?";
}

const char* alpha_sim_status_name(AlphaSimStatus s) {
  switch (s) {
    case AlphaSimStatus::Ok: return "ok";
    case AlphaSimStatus::HullFallback: return "hull_fallback";
    case AlphaSimStatus::Thin: return "thin";
    case AlphaSimStatus::Blocked: return "blocked";
    case AlphaSimStatus::Failed: return "failed";
    case AlphaSimStatus::EmptyInput: return "empty_input";
    case AlphaSimStatus::TooFine: return "too_fine";
  }
  return "?";
}

const char* alpha_sim_fallback_name(AlphaSimFallback f) {
  switch (f) {
    case AlphaSimFallback::None: return "none";
    case AlphaSimFallback::ConvexHull: return "convex_hull";
    case AlphaSimFallback::Original: return "original";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------
// Implicit solid

AlphaSimSolid::AlphaSimSolid(std::vector<AlphaSimPrism> prisms) : prisms_(std::move(prisms)) {}

bool AlphaSimSolid::contains(const Vec3& p, double tol) const {
  if (prisms_.empty()) return false;
  for (const auto& pr : prisms_) {
    const double d = p.dot(pr.n);
    if (d < pr.depth_min - tol || d > pr.depth_max + tol) return false;
    if (!pr.shape->contains(pr.project(p), tol)) return false;
  }
  return true;
}

double AlphaSimSolid::distance_bound(const Vec3& p) const {
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& pr : prisms_) {
    const double d = p.dot(pr.n);
    const double dz = std::max(pr.depth_min - d, d - pr.depth_max);  // > 0 outside the slab
    const double d2 = pr.shape->signed_distance(pr.project(p));
    double sd;
    if (d2 <= 0.0 && dz <= 0.0) sd = std::max(d2, dz);
    else sd = std::hypot(std::max(d2, 0.0), std::max(dz, 0.0));
    best = std::max(best, sd);
  }
  return prisms_.empty() ? std::numeric_limits<double>::infinity() : best;
}

// ---------------------------------------------------------------------------------------
// Sampling

namespace {

/// Sorts (key, value) pairs by key, then by value: Boost's spreadsort (radix passes on the
/// 64-bit key, comparisons within small buckets) takes about half the time of std::sort
/// on the 10^4–10^5 keys of a part.
template <class V>
void sort_pairs(std::vector<std::pair<std::uint64_t, V>>& v) {
  boost::sort::spreadsort::integer_sort(
      v.begin(), v.end(), [](const std::pair<std::uint64_t, V>& x, unsigned shift) { return x.first >> shift; },
      [](const std::pair<std::uint64_t, V>& x, const std::pair<std::uint64_t, V>& y) { return x < y; });
}

/// std::floor and std::ceil of x as an integer, inline: without SSE4.1 they are libm
/// calls, ~10% of the sampling's own time. For |x| < 2^62 (plane coordinates over L_max;
/// a larger value would not fit the long either).
long floor_to_long(double x) {
  const long i = static_cast<long>(x);  // toward zero
  return x < static_cast<double>(i) ? i - 1 : i;
}
long ceil_to_long(double x) {
  const long i = static_cast<long>(x);
  return x > static_cast<double>(i) ? i + 1 : i;
}

/// std::round(x) inline (halves away from zero, the sign of a zero kept): the same value.
double round_half_away(double x) {
  if (!(std::abs(x) < 0x1p62)) return std::round(x);  // integral already (or NaN)
  const long t = static_cast<long>(x);
  const double d = x - static_cast<double>(t);  // exact: t lies within 1 of x
  const double r = static_cast<double>(d >= 0.5 ? t + 1 : d <= -0.5 ? t - 1 : t);
  return r == 0.0 ? std::copysign(0.0, x) : r;
}

/// One edge of a mesh (a < b) and the third corners of the triangles that share it.
struct MeshEdge {
  std::uint32_t a = 0, b = 0;
  std::array<std::uint32_t, 2> opposite{};  ///< valid for the first min(triangles, 2)
  std::uint32_t triangles = 0;              ///< triangles sharing the edge
  std::uint32_t forward = 0;                ///< of those, the ones that run a → b
};

/// Unique edges of a mesh's triangles (a < b), sorted, each with its opposite corners in
/// increasing order: shared edges are subdivided once.
std::vector<MeshEdge> unique_edges(const Mesh& mesh) {
  // (a << 32 | b, opposite << 1 | backward): two 64-bit words compare faster than three
  // indices (this sort was ~3% of a simplification), in the same order.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> half;
  half.reserve(mesh.triangles.size() * 3);
  for (const auto& f : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      std::uint64_t a = f[k], b = f[(k + 1) % 3];
      const bool backward = b < a;
      if (backward) std::swap(a, b);
      half.emplace_back(a << 32 | b, std::uint64_t(f[(k + 2) % 3]) << 1 | std::uint64_t(backward));
    }
  sort_pairs(half);
  std::vector<MeshEdge> edges;
  for (const auto& [key, opp] : half) {
    const auto a = static_cast<std::uint32_t>(key >> 32), b = static_cast<std::uint32_t>(key);
    if (edges.empty() || edges.back().a != a || edges.back().b != b) edges.push_back({a, b, {}, 0, 0});
    MeshEdge& e = edges.back();
    if (e.triangles < 2) e.opposite[e.triangles] = static_cast<std::uint32_t>(opp >> 1);
    ++e.triangles;
    e.forward += (opp & 1) ? 0 : 1;
  }
  return edges;
}

/// True if `mesh` is closed as analyse_topology() says (every edge used by two triangles
/// in opposite directions), read off its unique edges: the edge sort is not done twice.
/// A triangle with a repeated corner index is left out there, not here, so such a mesh
/// goes to analyse_topology().
bool closed_mesh(const Mesh& mesh, const std::vector<MeshEdge>& edges) {
  for (const auto& f : mesh.triangles)
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return analyse_topology(mesh).closed;
  return !edges.empty() &&
         std::all_of(edges.begin(), edges.end(), [](const MeshEdge& e) { return e.triangles == 2 && e.forward == 1; });
}

/// dense_surface_samples() with the mesh's unique edges given (when fixed_points): each
/// edge's midpoint is taken once, not once per triangle that shares it (a closed mesh's
/// edges are shared by two: 1.5 points per triangle fewer, the same set of points).
/// `source`, if given, gets the triangle of each sample (kNoTriangle for the vertices and
/// edge midpoints, which several triangles share).
constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();
std::vector<Vec3> dense_surface_samples(const Mesh& mesh, const std::vector<MeshEdge>& edges, double spacing,
                                        double density, std::size_t max_samples, std::uint64_t seed,
                                        bool fixed_points, std::vector<std::uint32_t>* source = nullptr) {
  std::vector<Vec3> out;
  const std::size_t nt = mesh.triangles.size();
  if (fixed_points) {
    std::vector<char> used(mesh.vertices.size(), 0);
    for (const auto& f : mesh.triangles)
      for (auto i : f) used[i] = 1;
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
      if (used[i]) out.push_back(mesh.vertices[i]);
    for (const MeshEdge& e : edges) out.push_back((mesh.vertices[e.a] + mesh.vertices[e.b]) / 2.0);
  }
  if (source) source->assign(out.size(), kNoTriangle);
  // Random points: ≥ 2 per triangle, ≈ density per spacing² of area, capped.
  const double cell = spacing > 0.0 ? spacing * spacing : 1.0;
  std::vector<std::size_t> count(nt);
  std::size_t total = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const auto c = mesh.corners(t);
    const double area = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).norm();
    count[t] = 2 + static_cast<std::size_t>(std::min(1e6, density * area / cell));
    total += count[t];
  }
  const double scale = total > max_samples && total > 0 ? static_cast<double>(max_samples) / total : 1.0;
  // The random points number at most total·scale + nt (each count rounded down, at least 1).
  const std::size_t random_bound = static_cast<std::size_t>(static_cast<double>(total) * scale) + nt;
  out.reserve(out.size() + random_bound + (fixed_points ? nt : 0));
  if (source) source->reserve(out.capacity());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto c = mesh.corners(t);
    const std::size_t k = std::max<std::size_t>(1, static_cast<std::size_t>(count[t] * scale));
    if (fixed_points) out.push_back((c[0] + c[1] + c[2]) / 3.0);
    if (source) source->resize(out.size() + k, static_cast<std::uint32_t>(t));
    for (std::size_t s = 0; s < k; ++s) {
      double a = uni(rng), b = uni(rng);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      out.push_back(c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]));
    }
  }
  return out;
}

}  // namespace

std::vector<Vec3> dense_surface_samples(const Mesh& mesh, double spacing, double density,
                                        std::size_t max_samples, std::uint64_t seed, bool fixed_points) {
  return dense_surface_samples(mesh, fixed_points ? unique_edges(mesh) : std::vector<MeshEdge>(), spacing, density,
                               max_samples, seed, fixed_points);
}

namespace {

/// True if the projected edge pa–pb lies inside the projection of its two triangles:
/// exactly two share it and their third corners project strictly to opposite sides.
/// Such an edge is no part of the projection's outline, and the lattice nodes of the two
/// triangles already sample the area around it; every other edge (an outline or fold
/// seen in this plane, a border of an open mesh, a non-manifold or an edge-on one) is
/// subdivided.
bool interior_in_projection(const MeshEdge& e, const std::vector<Vec2>& proj) {
  if (e.triangles != 2) return false;
  const Vec2 pa = proj[e.a], pb = proj[e.b], ab = pb - pa;
  auto side = [&](std::uint32_t c) {
    const Vec2 ac = proj[c] - pa;
    const double o = ab.x() * ac.y() - ab.y() * ac.x();
    // Orientation well above its rounding error, or "on the line" (0).
    const double scale = (std::abs(ab.x()) + std::abs(ab.y())) * (std::abs(ac.x()) + std::abs(ac.y()));
    return o > 1e-12 * scale ? 1 : o < -1e-12 * scale ? -1 : 0;
  };
  return side(e.opposite[0]) * side(e.opposite[1]) < 0;
}

/// Calls emit(i, j) for each lattice point ((i + offset)·h, (j + offset)·h) of spacing h
/// (offset 0: nodes, 0.5: cell centres) in the closed triangle abc (boundary within rounding).
template <class F>
void lattice_in_triangle(const Vec2& a, const Vec2& b, const Vec2& c, double h, double offset, F&& emit) {
  const double ymin = std::min({a.y(), b.y(), c.y()}), ymax = std::max({a.y(), b.y(), c.y()});
  const long j0 = ceil_to_long(ymin / h - offset), j1 = floor_to_long(ymax / h - offset);
  const Vec2 v[3] = {a, b, c};
  for (long j = j0; j <= j1; ++j) {
    const double y = (static_cast<double>(j) + offset) * h;
    double xl = std::numeric_limits<double>::infinity(), xr = -xl;
    for (int e = 0; e < 3; ++e) {
      const Vec2& p = v[e];
      const Vec2& q = v[(e + 1) % 3];
      if ((p.y() - y) * (q.y() - y) > 0.0) continue;  // edge entirely above or below the row
      if (p.y() == q.y()) {
        xl = std::min({xl, p.x(), q.x()});
        xr = std::max({xr, p.x(), q.x()});
        continue;
      }
      const double x = p.x() + (q.x() - p.x()) * (y - p.y()) / (q.y() - p.y());
      xl = std::min(xl, x);
      xr = std::max(xr, x);
    }
    if (!(xl <= xr)) continue;
    const long i0 = ceil_to_long(xl / h - offset), i1 = floor_to_long(xr / h - offset);
    for (long i = i0; i <= i1; ++i) emit(i, j);
  }
}

/// Upper bound on the samples of one plane (before removing duplicates).
double plane_sample_estimate(const Mesh& mesh, const std::vector<MeshEdge>& edges,
                             const std::vector<Vec2>& proj, double l_max) {
  double n = static_cast<double>(mesh.vertices.size());
  for (const auto& e : edges) n += std::ceil((proj[e.a] - proj[e.b]).norm() / l_max);
  for (const auto& f : mesh.triangles) {
    const Vec2 a = proj[f[0]], b = proj[f[1]], c = proj[f[2]];
    const Vec2 lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
    const double area = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    // Lattice rows crossed times nodes per row is at most area/h² plus one per row and column.
    // Divided twice: h² underflows to 0 for h < ~1e-154 (0/0 would be NaN for a triangle
    // seen edge-on, and NaN passes every comparison with the limit).
    n += area / l_max / l_max + (hi - lo).sum() / l_max + 1.0;
  }
  return n;
}

/// Lattice points of spacing l_max in the convex hull of the vertices of `mesh`'s triangles
/// projected to `proj` (plane coordinates), by the hull's area and perimeter as
/// plane_sample_estimate counts a triangle's. The α-shape's Delaunay triangulation spans
/// that hull whatever the samples cover: open triangles far apart (sheets seen edge-on, a
/// truncated file) leave it nearly empty, and the long triangles across the emptiness, all
/// kept when the projection falls back to its hull, cost what its lattice would.
double hull_lattice_estimate(const Mesh& mesh, const std::vector<Vec2>& proj, double l_max) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  // Each vertex once (a closed mesh names each about six times): the hull's sort is most
  // of the cost.
  std::vector<char> is_used(proj.size(), 0);
  for (const auto& f : mesh.triangles)
    for (const auto i : f) is_used[i] = 1;
  std::vector<Kernel::Point_2> used, hull;
  used.reserve(proj.size());
  for (std::size_t i = 0; i < proj.size(); ++i)
    if (is_used[i]) used.emplace_back(proj[i].x(), proj[i].y());
  CGAL::convex_hull_2(used.begin(), used.end(), std::back_inserter(hull));
  double twice_area = 0.0, perimeter = 0.0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Kernel::Point_2& a = hull[i];
    const Kernel::Point_2& b = hull[(i + 1) % hull.size()];
    twice_area += a.x() * b.y() - a.y() * b.x();
    perimeter += std::hypot(b.x() - a.x(), b.y() - a.y());
  }
  // Divided twice, as in plane_sample_estimate (l_max² underflows for l_max < ~1e-154).
  return 0.5 * std::abs(twice_area) / l_max / l_max + perimeter / l_max + 1.0;
}

/// Counts in too_fine_reason beyond this are said as "more than" the limit: a double
/// prints integers exactly up to 2^53, and l_max² far below the part's area gives +inf.
constexpr double kLargestPrintedCount = 1e15;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// What one projection plane would cost: its samples (plane_sample_estimate) and the
/// lattice of its convex hull (hull_lattice_estimate).
struct PlaneWork {
  double samples = 0.0;
  double hull = 0.0;
};

/// The reason a part is too fine for α-SIM (status TooFine), or empty if every plane's
/// samples and hull lattice stay within `limit` points. NaN (not expected) counts as too
/// many; a count from kLargestPrintedCount (up to +inf) is said as "more than" the limit:
/// no output of loom holds "inf" or "nan".
std::string too_fine_reason(const std::vector<PlaneWork>& planes, double l_max, std::size_t limit) {
  double samples = 0.0, hull = 0.0;
  for (const PlaneWork& w : planes) {
    samples = std::isnan(w.samples) || std::isnan(samples) ? kNaN : std::max(samples, w.samples);
    hull = std::isnan(w.hull) || std::isnan(hull) ? kNaN : std::max(hull, w.hull);
  }
  const double cap = static_cast<double>(limit);
  const std::string most = std::to_string(limit);
  // "about N ... > limit", or "more than limit ..." when N does not print as a count.
  auto count = [&](double n, const std::string& what) {
    return n < kLargestPrintedCount ? "about " + full_precision(std::round(n)) + " " + what + " > " + most
                                    : "more than " + most + " " + what;
  };
  const std::string at = "sampling at L_max = " + full_precision(l_max);
  if (!(samples <= cap))
    return at + " needs " + count(samples, "points in a plane") + ": original kept (raise dim_pre)";
  if (!(hull <= cap))
    return at + ", the convex hull of a projection spans " + count(hull, "lattice points") + ", which its about " +
           full_precision(std::round(samples)) +
           " samples leave mostly empty (triangles far apart): original kept (raise dim_pre, or split the part)";
  return "";
}

/// The lattice points of one offset met by the triangles of a projection, deduplicated on
/// a bitmap over their index box (overlapping triangles, front and back faces, meet the
/// same nodes many times) instead of sorting every copy. Lattice points are exact
/// multiples of the spacing, so equal points have equal indices.
class LatticeBitmap {
 public:
  /// Bitmap over the lattice indices of the box lo..hi (plane coordinates), if it has at
  /// most max_bits bits; otherwise active() is false and the caller sorts the points.
  LatticeBitmap(const Vec2& lo, const Vec2& hi, double h, double offset, std::size_t max_bits) : h_(h), offset_(offset) {
    // One index of margin: rounding in lattice_in_triangle cannot move a point further.
    const double i0 = std::floor(lo.x() / h - offset) - 1.0, j0 = std::floor(lo.y() / h - offset) - 1.0;
    const double nx = std::ceil(hi.x() / h - offset) + 2.0 - i0, ny = std::ceil(hi.y() / h - offset) + 2.0 - j0;
    // Indices far beyond the bitmap's reach (or not finite): sort instead.
    constexpr double kMaxIndex = 1e15;
    if (!(std::abs(i0) < kMaxIndex && std::abs(j0) < kMaxIndex && nx * ny <= static_cast<double>(max_bits))) return;
    i0_ = static_cast<long>(i0);
    j0_ = static_cast<long>(j0);
    nx_ = static_cast<long>(nx);
    ny_ = static_cast<long>(ny);
    bits_.assign((static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) + 63) / 64, 0);
  }
  bool active() const { return !bits_.empty(); }
  /// Marks (i, j); false if it lies outside the box (the caller keeps the point itself).
  bool set(long i, long j) {
    const std::size_t k = bit(i, j);
    if (k == kOutside) return false;
    bits_[k / 64] |= std::uint64_t(1) << (k % 64);
    return true;
  }
  /// True if (i, j) is marked.
  bool test(long i, long j) const {
    const std::size_t k = bit(i, j);
    return k != kOutside && ((bits_[k / 64] >> (k % 64)) & 1u);
  }
  /// The marked points for which keep(i, j) holds, mapped by `point(i, j)`, in increasing
  /// (i, j), which is increasing (x, y) since the mapping is monotone in each index.
  template <class F, class K>
  std::vector<Vec2> points(F&& point, K&& keep) const {
    std::vector<Vec2> out;
    for (std::size_t w = 0; w < bits_.size(); ++w)
      for (std::uint64_t word = bits_[w]; word != 0; word &= word - 1) {
        const std::size_t k = w * 64 + static_cast<std::size_t>(__builtin_ctzll(word));
        const long i = i0_ + static_cast<long>(k / static_cast<std::size_t>(ny_)),
                   j = j0_ + static_cast<long>(k % static_cast<std::size_t>(ny_));
        if (keep(i, j)) out.push_back(point(i, j));
      }
    return out;
  }
  /// Lattice point (i, j) (unsnapped).
  Vec2 at(long i, long j) const {
    return Vec2((static_cast<double>(i) + offset_) * h_, (static_cast<double>(j) + offset_) * h_);
  }

 private:
  static constexpr std::size_t kOutside = ~std::size_t(0);
  /// Bit number of (i, j), or kOutside if it lies outside the box (or no bitmap).
  std::size_t bit(long i, long j) const {
    const long x = i - i0_, y = j - j0_;
    if (x < 0 || y < 0 || x >= nx_ || y >= ny_) return kOutside;
    return static_cast<std::size_t>(x) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(y);
  }
  double h_, offset_;
  long i0_ = 0, j0_ = 0, nx_ = 0, ny_ = 0;
  std::vector<std::uint64_t> bits_;
};

/// The rotations that map the coordinate axes onto themselves (signed permutation
/// matrices of determinant +1: 24), identity first; only the identity if `all` is false.
std::vector<Eigen::Matrix3d> axis_rotations(bool all) {
  std::vector<Eigen::Matrix3d> out{Eigen::Matrix3d::Identity()};
  if (!all) return out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& pm : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) R(r, pm[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (R.determinant() > 0.0 && !R.isIdentity()) out.push_back(R);
    }
  return out;
}

/// Most bits of one lattice bitmap (8 MiB; two per plane, planes in parallel). A larger
/// index box (a huge sparse projection) falls back to sorting the lattice points.
constexpr std::size_t kMaxLatticeBitmapBits = std::size_t(1) << 26;

/// Inside a projection, where a cell of 2·L_max has all nine lattice nodes, only its
/// corners are sampled (a quarter of the interior points and Delaunay triangles), but only
/// where those cells' circumradius √2·L_max is below this fraction of α: a Delaunay
/// triangle of the snapped nodes may be that much larger than the ideal one.
constexpr double kCoarseCellAlphaMargin = 0.9;

/// Seed offset (from AlphaSimOptions::seed) of the dense samples that the measure pass
/// checks containment on; the Hausdorff samples use seed + 1.
constexpr std::uint64_t kMeasureSeedOffset = 12;

/// Triangles seen edge-on (narrower than kEdgeOnWidthShare·tol in projection) are checked
/// by their longest edge within kEdgeOnTolShare·tol (edge_on_triangles): with the snap
/// (≤ tol/4, moving a point by ≤ 0.18·tol) that keeps every point of them within tol.
constexpr double kEdgeOnWidthShare = 0.25, kEdgeOnTolShare = 0.5;

void sort_unique(std::vector<Vec2>& v) {
  std::sort(v.begin(), v.end(), xy_less);
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// sort_unique() for points on the grid of spacing `snap` (snap_to_grid, snap a power of
/// two), in the same order: each point's grid indices, less the lowest, packed into one
/// 64-bit key (x high, y low), which sorts ~3× faster than the coordinates (this sort was
/// ~7% of a face-on plate's simplification). Back from the key, k·snap is the same value
/// as before (|k| < 2^53), except that −0 comes back as +0 (equal to it). Where the
/// indices span 2^32 or more, sort_unique().
void sort_unique_snapped(std::vector<Vec2>& v, double snap) {
  if (v.empty()) return;
  std::vector<std::int64_t> kx(v.size()), ky(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    kx[i] = static_cast<std::int64_t>(round_half_away(v[i].x() / snap));
    ky[i] = static_cast<std::int64_t>(round_half_away(v[i].y() / snap));
  }
  const auto [x_lo, x_hi] = std::minmax_element(kx.begin(), kx.end());
  const auto [y_lo, y_hi] = std::minmax_element(ky.begin(), ky.end());
  constexpr std::int64_t kSpan = std::int64_t(1) << 32;
  if (*x_hi - *x_lo >= kSpan || *y_hi - *y_lo >= kSpan) {
    sort_unique(v);
    return;
  }
  const std::int64_t x0 = *x_lo, y0 = *y_lo;
  std::vector<std::uint64_t> keys(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    keys[i] = static_cast<std::uint64_t>(kx[i] - x0) << 32 | static_cast<std::uint64_t>(ky[i] - y0);
  boost::sort::spreadsort::integer_sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  v.resize(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i)
    v[i] = Vec2(static_cast<double>(x0 + static_cast<std::int64_t>(keys[i] >> 32)) * snap,
                static_cast<double>(y0 + static_cast<std::int64_t>(keys[i] & 0xffffffffu)) * snap);
}

/// A 64-bit hash of `n` doubles by value (−0 as +0, so that values equal by == hash
/// equal): splitmix64's finaliser over each bit pattern in turn.
std::uint64_t hash_doubles(const double* x, std::size_t n) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = x[i] + 0.0;  // −0 + 0 = +0
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    h ^= h >> 31;
  }
  return h;
}

/// hash_doubles of a triangle's six coordinates (corners in the order given).
std::uint64_t hash_triangle(const std::array<Vec2, 3>& t) {
  const double c[6] = {t[0].x(), t[0].y(), t[1].x(), t[1].y(), t[2].x(), t[2].y()};
  return hash_doubles(c, 6);
}

/// Drops repeats from `items`: of the items that `same` says are equal (their `hash`
/// must be equal too), the first is kept, in its place among the first occurrences, and
/// `merge(kept, repeat)` is called for the others. One pass over an open-addressing table
/// of indices (load ≤ 1/2): for wide items whose order does not matter (projected edges,
/// triangles: 40–48 bytes) ~3× faster than sorting them, and 2× faster than sorting
/// (hash, index) pairs.
template <class T, class Hash, class Same, class Merge>
void dedupe_by_hash(std::vector<T>& items, Hash hash, Same same, Merge merge) {
  constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  std::size_t cap = 16;
  while (cap < 2 * items.size()) cap <<= 1;
  std::vector<std::uint32_t> slot(cap, kEmpty);
  std::vector<T> out;
  out.reserve(items.size());
  for (const T& item : items) {
    for (std::size_t h = hash(item) & (cap - 1);; h = (h + 1) & (cap - 1)) {
      if (slot[h] == kEmpty) {
        slot[h] = static_cast<std::uint32_t>(out.size());
        out.push_back(item);
        break;
      }
      if (same(out[slot[h]], item)) {
        merge(out[slot[h]], item);
        break;
      }
    }
  }
  items = std::move(out);
}

/// sorted ∪ more (both sorted and unique) → sorted, unique.
void merge_unique(std::vector<Vec2>& sorted, const std::vector<Vec2>& more) {
  std::vector<Vec2> out;
  out.reserve(sorted.size() + more.size());
  std::merge(sorted.begin(), sorted.end(), more.begin(), more.end(), std::back_inserter(out), xy_less);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  sorted = std::move(out);
}

/// The paper's point cloud (step 1), sampled directly in one projection plane (step 2):
/// the projected vertices, the projected outline edges subdivided to pieces ≤ L_max (an
/// edge inside the projection of its two triangles is not: the lattice covers it), and the nodes
/// of a lattice of spacing L_max (aligned to the plane origin, so that overlapping
/// triangles share nodes) inside each projected triangle. The projected surface is then
/// sampled about as densely as by a 3D subdivision of edge ≤ L_max (projection only
/// shortens distances), but a face seen edge-on costs only its silhouette and a long
/// sliver triangle only its area, not (longest edge / L_max)². Vertices and subdivision
/// points in a lattice cell whose four corners are nodes are left out (in_covered_cell).
/// Checks (points the α-shape must cover) are the sub-edge midpoints, the centres of the
/// lattice cells inside each triangle and its centroid.
/// Coordinates are snapped to the grid `snap`; points and checks are sorted and unique.
/// lattice_bitmap = false sorts every point (no LatticeBitmap): the same sets, slower.
/// q moved to the nearest point of the grid of spacing `snap` (plane coordinates).
Vec2 snap_to_grid(const Vec2& q, double snap) {
  return Vec2(round_half_away(q.x() / snap) * snap, round_half_away(q.y() / snap) * snap);
}

/// The vertices of `mesh` in the plane of `pr` (u, v coordinates), once per plane for its
/// several passes over the triangles.
std::vector<Vec2> project_vertices(const Mesh& mesh, const AlphaSimPrism& pr) {
  std::vector<Vec2> proj(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) proj[i] = pr.project(mesh.vertices[i]);
  return proj;
}

/// The checks of an outline edge pa → pb (n pieces): its sub-edge midpoints, snapped,
/// each passed to f until f returns true; true if it did.
template <class F>
bool outline_checks_until(const Vec2& pa, const Vec2& pb, int n, double snap, F&& f) {
  for (int k = 0; k < n; ++k)
    if (f(snap_to_grid(pa + (pb - pa) * ((k + 0.5) / n), snap))) return true;
  return false;
}

/// Pieces an edge of projected length `len` is cut into: each ≤ l_max.
int outline_pieces(double len, double l_max) { return std::max(1, static_cast<int>(std::ceil(len / l_max))); }

/// A plane's outline checks before they are listed (exact mode): most planes never use
/// them (exact_projection), and listing and sorting them was most of their cost (a
/// spar's face-on plane: 79k checks from its hole rims). `edges` as (pa.x, pa.y, pb.x,
/// pb.y), in the order sample_projection met them.
struct DeferredChecks {
  std::vector<std::array<double, 4>> edges;
  double l_max = 0.0, snap = 0.0;
  bool listed = true;  ///< true once `checks` holds them all, sorted and unique
  /// f(check) for each check in the order they would be listed, until f returns true;
  /// true if it did.
  template <class F>
  bool until(F&& f) const {
    for (const auto& e : edges) {
      const Vec2 pa(e[0], e[1]), pb(e[2], e[3]);
      if (outline_checks_until(pa, pb, outline_pieces((pb - pa).norm(), l_max), snap, f)) return true;
    }
    return false;
  }
  /// f(check) for every `stride`-th check in the order they would be listed, until f
  /// returns true; true if it did.
  template <class F>
  bool any_of_every(std::size_t stride, F&& f) const {
    std::size_t i = 0;
    return until([&](const Vec2& q) { return i++ % stride == 0 && f(q); });
  }
  /// Appends them to `checks`, sorts those (sort_unique_snapped) and marks them listed.
  void list(std::vector<Vec2>& checks) {
    if (listed) return;
    until([&](const Vec2& q) {
      checks.push_back(q);
      return false;
    });
    sort_unique_snapped(checks, snap);
    edges.clear();
    listed = true;
  }
};

/// `proj`: the mesh's vertices projected (project_vertices). With `deferred`, the
/// outline's checks are left to it (DeferredChecks; only without all_checks, where they
/// are all the checks) and `checks` is empty.
AlphaSimPlaneSamples sample_projection(const Mesh& mesh,
                                       const std::vector<MeshEdge>& edges,
                                       const std::vector<Vec2>& proj, double l_max, double snap, bool lattice_bitmap,
                                       bool coarse_interior, bool all_checks, DeferredChecks* deferred = nullptr) {
  AlphaSimPlaneSamples s;
  auto snapped = [snap](const Vec2& q) { return snap_to_grid(q, snap); };
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& f : mesh.triangles)
    for (auto i : f) used[i] = 1;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!used[i]) continue;
    lo = lo.cwiseMin(proj[i]);
    hi = hi.cwiseMax(proj[i]);
  }
  const std::size_t max_bits = lattice_bitmap ? kMaxLatticeBitmapBits : 0;
  LatticeBitmap nodes(lo, hi, l_max, 0.0, max_bits), centres(lo, hi, l_max, 0.5, all_checks ? max_bits : 0);
  // Without the bitmaps: every node and cell centre met, sorted below.
  std::vector<std::pair<long, long>> node_list, centre_list;
  for (const auto& f : mesh.triangles) {
    const Vec2 a = proj[f[0]], b = proj[f[1]], c = proj[f[2]];
    lattice_in_triangle(a, b, c, l_max, 0.0, [&](long i, long j) {
      if (!nodes.active() || !nodes.set(i, j)) node_list.emplace_back(i, j);
    });
    if (!all_checks) continue;
    lattice_in_triangle(a, b, c, l_max, 0.5, [&](long i, long j) {
      if (!centres.active() || !centres.set(i, j)) centre_list.emplace_back(i, j);
    });
    s.checks.push_back(snapped((a + b + c) / 3.0));
  }
  std::sort(node_list.begin(), node_list.end());
  node_list.erase(std::unique(node_list.begin(), node_list.end()), node_list.end());
  auto has_node = [&](long i, long j) {
    return (nodes.active() && nodes.test(i, j)) || std::binary_search(node_list.begin(), node_list.end(), std::make_pair(i, j));
  };
  // Deep inside the projection the lattice may be twice as coarse: the cells of spacing
  // 2·L_max whose nine nodes are all met keep only their corners (even i and j), whose
  // triangles have circumradius √2·L_max < α (the caller asks for this only then), so the
  // α-shape keeps them; every cell of spacing L_max with four corner nodes lies in such a
  // cell or keeps its corners, so the region the nodes cover does not shrink, and points
  // near the outline (where a node is missing within two cells) are all kept. A face-on
  // plate costs a quarter of the nodes and of their Delaunay triangles.
  auto complete_coarse_cell = [&](long ci, long cj) {  // (ci, cj): its lower-left node, even
    for (long a = 0; a <= 2; ++a)
      for (long b = 0; b <= 2; ++b)
        if (!has_node(ci + a, cj + b)) return false;
    return true;
  };
  auto keep_node = [&](long i, long j) {
    const bool i_odd = (i & 1) != 0, j_odd = (j & 1) != 0;  // two's complement: -1 is odd
    if (!coarse_interior || (!i_odd && !j_odd)) return true;
    if (i_odd && j_odd) return !complete_coarse_cell(i - 1, j - 1);
    if (i_odd) return !(complete_coarse_cell(i - 1, j - 2) && complete_coarse_cell(i - 1, j));
    return !(complete_coarse_cell(i - 2, j - 1) && complete_coarse_cell(i, j - 1));
  };
  for (const auto& [i, j] : node_list)
    if (keep_node(i, j)) s.points.push_back(snapped(nodes.at(i, j)));
  // A cell centre in a complete cell of 2·L_max is in the region (its two triangles are
  // kept): no check.
  auto keep_centre = [&](long i, long j) {
    return !coarse_interior || !complete_coarse_cell(i - ((i & 1) != 0), j - ((j & 1) != 0));
  };
  for (const auto& [i, j] : centre_list)
    if (keep_centre(i, j)) s.checks.push_back(snapped(centres.at(i, j)));
  // A point in a lattice cell whose four corners are nodes adds nothing to the region: the
  // corners already give the α-shape that cell (two triangles of circumradius L_max/√2,
  // below α = 1.9·L_max at the default factors), and the checks, all kept, repair it
  // where the triangulation differs. Projected vertices and subdivision points there are
  // left out: where a face-on surface covers faces seen edge-on (a spar's web behind its
  // flanges) they outnumber the lattice nodes ~10×.
  auto in_covered_cell = [&](const Vec2& q) {
    const long ci = floor_to_long(q.x() / l_max), cj = floor_to_long(q.y() / l_max);
    return has_node(ci, cj) && has_node(ci + 1, cj) && has_node(ci, cj + 1) && has_node(ci + 1, cj + 1);
  };
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (used[i] && !in_covered_cell(proj[i])) s.points.push_back(snapped(proj[i]));
  // Edges with the same projected ends in the same direction (front and back faces of a
  // plate seen edge-on) give the same points: each is subdivided once.
  // The fifth entry is 1 when the edge is to be subdivided (see interior_in_projection);
  // of equal ends, the one kept says whether any of them is (the order does not matter:
  // the points and checks are sorted after).
  std::vector<std::array<double, 5>> ends;
  // An edge inside the projection gives only checks, and none without all_checks.
  ends.reserve(edges.size());
  for (const auto& e : edges) {
    const bool interior = interior_in_projection(e, proj);
    if (interior && !all_checks) continue;
    ends.push_back({proj[e.a].x(), proj[e.a].y(), proj[e.b].x(), proj[e.b].y(), interior ? 0.0 : 1.0});
  }
  dedupe_by_hash(
      ends, [](const auto& e) { return hash_doubles(e.data(), 4); },
      [](const auto& x, const auto& y) { return std::equal(x.begin(), x.begin() + 4, y.begin()); },
      [](auto& kept, const auto& repeat) { kept[4] = std::max(kept[4], repeat[4]); });
  const bool defer = deferred != nullptr && !all_checks;
  if (defer) {
    deferred->edges.clear();
    deferred->l_max = l_max;
    deferred->snap = snap;
    deferred->listed = false;
  }
  for (const auto& e : ends) {
    const Vec2 pa(e[0], e[1]), pb(e[2], e[3]);
    const int n = outline_pieces((pb - pa).norm(), l_max);
    if (e[4] != 0.0)
      for (int k = 1; k < n; ++k) {
        const Vec2 q = pa + (pb - pa) * (static_cast<double>(k) / n);
        if (!in_covered_cell(q)) s.points.push_back(snapped(q));
      }
    if (defer && e[4] != 0.0) deferred->edges.push_back({e[0], e[1], e[2], e[3]});
    else if (e[4] != 0.0 || all_checks)
      outline_checks_until(pa, pb, n, snap, [&](const Vec2& q) {
        s.checks.push_back(q);
        return false;
      });
  }
  sort_unique_snapped(s.points, snap);
  sort_unique_snapped(s.checks, snap);
  if (nodes.active())
    merge_unique(s.points, nodes.points([&](long i, long j) { return snapped(nodes.at(i, j)); }, keep_node));
  if (centres.active())
    merge_unique(s.checks, centres.points([&](long i, long j) { return snapped(centres.at(i, j)); }, keep_centre));
  return s;
}

/// The triangles a plane sees edge-on, and what is checked in place of their samples.
struct EdgeOnTriangles {
  std::vector<char> flag;                       ///< per triangle: 1 if seen edge-on
  std::vector<std::array<Vec2, 2>> segments;    ///< their longest projected edges, snapped, unique
};

/// Triangles whose projection in `pr` is narrower than `width` (twice its area over its
/// longest edge). Such a projection
/// lies within `width` of its longest edge (the foot of the opposite corner falls on that
/// edge, whose end angles are at most 90°), so the
/// region covering that edge within tol − width − snap covers the triangle within tol: one
/// exact segment test (AlphaShape2D::segment_gaps) replaces the triangle's. A CAD part's faces along an axis are seen edge-on by the other two
/// planes (~50–90% of a wing part's samples per plane), and their samples all fall on the
/// outline, where each point test is slowest; hundreds of triangles along an extrusion
/// share one segment.
EdgeOnTriangles edge_on_triangles(const Mesh& mesh, const std::vector<Vec2>& proj, double width, double snap) {
  EdgeOnTriangles out;
  out.flag.assign(mesh.triangles.size(), 0);
  // The segment pq snapped, ends in lexicographic order (so that equal segments compare equal).
  auto snapped_segment = [snap](const Vec2& p, const Vec2& q) {
    Vec2 a = snap_to_grid(p, snap), b = snap_to_grid(q, snap);
    if (xy_less(b, a)) std::swap(a, b);
    return std::array<Vec2, 2>{a, b};
  };
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const std::array<Vec2, 3> q = {proj[f[0]], proj[f[1]], proj[f[2]]};
    int longest = 0;
    double l2 = -1.0;
    for (int e = 0; e < 3; ++e) {
      const double d2 = (q[(e + 1) % 3] - q[e]).squaredNorm();
      if (d2 > l2) {
        l2 = d2;
        longest = e;
      }
    }
    const Vec2 ab = q[1] - q[0], ac = q[2] - q[0];
    const double twice_area = std::abs(ab.x() * ac.y() - ab.y() * ac.x());
    if (!(twice_area <= width * std::sqrt(l2))) continue;
    out.flag[t] = 1;
    out.segments.push_back(snapped_segment(q[longest], q[(longest + 1) % 3]));
  }
  auto less = [](const auto& x, const auto& y) {
    return std::tie(x[0].x(), x[0].y(), x[1].x(), x[1].y()) < std::tie(y[0].x(), y[0].y(), y[1].x(), y[1].y());
  };
  std::sort(out.segments.begin(), out.segments.end(), less);
  out.segments.erase(std::unique(out.segments.begin(), out.segments.end()), out.segments.end());
  // Axis-parallel segments on one line (exact after snapping: a face along an axis seen
  // edge-on, cut into many triangles) are merged where they overlap or touch; the others
  // are kept as they are.
  std::vector<std::array<Vec2, 2>> merged, other;
  std::vector<std::array<double, 4>> axial;  // (axis, line coordinate, from, to)
  for (const auto& sg : out.segments) {
    if (sg[0].y() == sg[1].y())
      axial.push_back({0.0, sg[0].y(), sg[0].x(), sg[1].x()});
    else if (sg[0].x() == sg[1].x())
      axial.push_back({1.0, sg[0].x(), sg[0].y(), sg[1].y()});
    else
      other.push_back(sg);
  }
  std::sort(axial.begin(), axial.end());
  for (std::size_t i = 0; i < axial.size();) {
    std::array<double, 4> run = axial[i];
    std::size_t j = i + 1;
    for (; j < axial.size() && axial[j][0] == run[0] && axial[j][1] == run[1] && axial[j][2] <= run[3]; ++j)
      run[3] = std::max(run[3], axial[j][3]);
    merged.push_back(run[0] == 0.0 ? std::array<Vec2, 2>{Vec2(run[2], run[1]), Vec2(run[3], run[1])}
                                   : std::array<Vec2, 2>{Vec2(run[1], run[2]), Vec2(run[1], run[3])});
    i = j;
  }
  merged.insert(merged.end(), other.begin(), other.end());
  out.segments = std::move(merged);
  return out;
}

/// The points of the edge-on segments that `shape` leaves farther than tol (see
/// AlphaShape2D::segment_gaps), spaced ≤ spacing.
std::vector<Vec2> edge_on_gaps(const AlphaShape2D& shape, const EdgeOnTriangles& eo, double tol, double spacing) {
  std::vector<Vec2> gaps;
  for (const auto& sg : eo.segments) {
    const auto g = shape.segment_gaps(sg[0], sg[1], tol, spacing);
    gaps.insert(gaps.end(), g.begin(), g.end());
  }
  return gaps;
}

/// Orthonormal frame (u, v, n = u × v) for a plane normal.
AlphaSimPrism frame_for(const Vec3& normal) {
  AlphaSimPrism p;
  p.n = normal.normalized();
  Vec3 axis = Vec3::UnitX();
  if (std::abs(p.n.x()) > 0.9) axis = Vec3::UnitY();
  p.u = p.n.cross(axis).normalized();
  p.v = p.n.cross(p.u);
  // Ensure u × v = n.
  if (p.u.cross(p.v).dot(p.n) < 0.0) p.v = -p.v;
  return p;
}

struct PlaneSpec {
  std::string name;
  AlphaSimPrism frame;
};

std::vector<PlaneSpec> planes_for(const AlphaSimOptions& opt) {
  std::vector<PlaneSpec> out;
  if (opt.coordinate_planes) {
    AlphaSimPrism xy, xz, yz;
    xy.u = Vec3::UnitX(); xy.v = Vec3::UnitY(); xy.n = Vec3::UnitZ();
    xz.u = Vec3::UnitX(); xz.v = Vec3::UnitZ(); xz.n = -Vec3::UnitY();
    yz.u = Vec3::UnitY(); yz.v = Vec3::UnitZ(); yz.n = Vec3::UnitX();
    out.push_back({"XY", xy});
    out.push_back({"XZ", xz});
    out.push_back({"YZ", yz});
  }
  for (std::size_t i = 0; i < opt.extra_planes.size(); ++i) {
    const Vec3& n = opt.extra_planes[i];
    if (!n.allFinite() || n.norm() == 0.0)
      throw std::invalid_argument("alpha-sim: user plane normal " + std::to_string(i) + " is zero or not finite");
    out.push_back({"user" + std::to_string(i), frame_for(n)});
  }
  if (out.empty()) throw std::invalid_argument("alpha-sim: no projection plane");
  return out;
}

// --- Mesh queries for the measures (Embree) ---------------------------------------------

/// Rounds every vertex of m to the nearest float32 (what a binary STL stores) and returns
/// the largest distance a vertex moved (scene units). Coordinate by coordinate: GCC 12.2
/// at -O2/-O3 (SLP vectorizer) dropped the store of `v = Vec3(float(x), float(y),
/// float(z))` in this loop for the first vertex (checked with a stand-alone copy).
double round_vertices_to_float(Mesh& m) {
  double moved2 = 0.0;
  for (Vec3& v : m.vertices) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double f = static_cast<double>(static_cast<float>(v[k]));
      d2 += (f - v[k]) * (f - v[k]);
      v[k] = f;
    }
    moved2 = std::max(moved2, d2);
  }
  return std::sqrt(moved2);
}

/// Largest share of the containment tolerance kept for float32 rounding of the output
/// (float32_vertices).
constexpr double kMaxFloatRoundingShare = 0.5;

/// The prisms run this far past the part (scene units; simplify_part), so that no cap of
/// one coincides with a face of another.
double prism_margin(const AlphaSimOptions& opt, double tol) { return std::max(10.0 * tol, 1e-3 * opt.dim_pre); }

/// Bound on how far rounding to float32 moves a vertex of the simplified mesh of a part
/// with bounding box `box` (scene units): rounding a coordinate x moves it by at most
/// 2^-24·|x|, and the mesh lies within the box grown by the prisms' margin and tol (its
/// outlines may grow further: the rounding is checked after).
double float_rounding_bound(const AABB& box, const AlphaSimOptions& opt, double tol) {
  const double m = std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff()) + prism_margin(opt, tol) + tol;
  return std::sqrt(3.0) * std::ldexp(m, -24);
}

/// The part of the containment tolerance tol kept for rounding the simplified mesh of a
/// part with bounding box `box` to float32 (scene units; 0 without float32_vertices):
/// opt.float_rounding_reserve, or where that is < 0 float_rounding_bound(), at most
/// kMaxFloatRoundingShare·tol (far from the origin only vertices that are float32 already,
/// like the corners of a box read from an STL file, stay within it).
double float_rounding_reserve(const AABB& box, const AlphaSimOptions& opt, double tol) {
  if (!opt.float32_vertices) return 0.0;
  const double reserve = opt.float_rounding_reserve >= 0.0 ? opt.float_rounding_reserve : float_rounding_bound(box, opt, tol);
  return std::min(reserve, kMaxFloatRoundingShare * tol);
}

/// The mesh as a list of one part (for an EmbreeIndex).
std::vector<Part> one_part(Mesh m, bool closed) {
  std::vector<Part> parts(1);
  parts[0].name = "alpha-sim";
  parts[0].mesh = std::move(m);
  parts[0].closed = closed;
  return parts;
}

/// One closed or open mesh as a one-part EmbreeIndex: exact (double) distances and
/// ray-parity inside tests (DESIGN §9: Embree for BVH queries). `watertight`: checked to
/// have no boundary and no misoriented edge, so one ray that grazes nothing decides an
/// inside test exactly (inside_rays = 1); the default majority of three guards real
/// meshes with holes, at three times the rays.
EmbreeIndex mesh_index(Mesh m, bool closed, bool watertight = false) {
  EmbreeOptions eo;
  if (watertight) eo.inside_rays = 1;
  return EmbreeIndex(one_part(std::move(m), closed), eo);
}

/// Number of `samples` inside or within tol of the closed mesh indexed by q (parallel).
/// The distance test comes first: a sample within tol of the surface is "on" it, and one
/// farther away is clear of the surface by tol, where the ray-parity test is robust.
std::size_t count_contained_mesh(const EmbreeIndex& q, const std::vector<Vec3>& samples, double tol) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, samples.size(), 1024), std::size_t(0),
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t acc) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
          if (q.any_within(samples[i], tol) || q.inside(samples[i])) ++acc;
        return acc;
      },
      std::plus<std::size_t>());
}

// --- OpenCASCADE prisms ∩ -----------------------------------------------------------------
gp_Pnt to_gp(const Extrusion& e, const Vec2& q, double depth) {
  const Vec3 p = e.u * q.x() + e.v * q.y() + e.n * depth;
  return gp_Pnt(p.x(), p.y(), p.z());
}

TopoDS_Wire ring_wire(const Extrusion& e, const std::vector<Vec2>& ring, double depth) {
  BRepBuilderAPI_MakePolygon poly;
  for (const auto& q : ring) poly.Add(to_gp(e, q, depth));
  poly.Close();
  if (!poly.IsDone()) throw std::runtime_error("polygon wire failed");
  return poly.Wire();
}

/// The extrusion as an OpenCASCADE solid (a compound of one prism per polygon).
TopoDS_Shape prism_shape(const Extrusion& e) {
  BRep_Builder builder;
  TopoDS_Compound comp;
  builder.MakeCompound(comp);
  const double d0 = e.depth_min, len = e.depth_max - e.depth_min;
  const gp_Vec dir(e.n.x() * len, e.n.y() * len, e.n.z() * len);
  const Vec3 o = e.n * d0;
  const gp_Pln plane(gp_Pnt(o.x(), o.y(), o.z()), gp_Dir(e.n.x(), e.n.y(), e.n.z()));
  int count = 0;
  for (const auto& poly : e.polygons) {
    BRepBuilderAPI_MakeFace mf(plane, ring_wire(e, poly.outer, d0), true);
    for (const auto& h : poly.holes) mf.Add(ring_wire(e, h, d0));
    if (!mf.IsDone()) throw std::runtime_error("planar face failed");
    BRepPrimAPI_MakePrism prism(mf.Face(), dir);
    prism.Build();
    if (!prism.IsDone()) throw std::runtime_error("prism failed");
    builder.Add(comp, prism.Shape());
    ++count;
  }
  if (count == 0) throw std::runtime_error("no polygon");
  return comp;
}

TopoDS_Shape common(const TopoDS_Shape& a, const TopoDS_Shape& b, double fuzzy) {
  TopTools_ListOfShape args, tools;
  args.Append(a);
  tools.Append(b);
  // Serial (parts are simplified in parallel already); no check of the inputs for
  // inverted solids (prisms of valid faces never are) and no history (only the result is
  // used). With the fuzzy value (tol) only if the exact run fails.
  auto run = [&](double fuzzy_value) {
    BRepAlgoAPI_Common op;
    op.SetArguments(args);
    op.SetTools(tools);
    op.SetRunParallel(false);
    op.SetCheckInverted(false);
    op.SetToFillHistory(false);
    if (fuzzy_value > 0.0) op.SetFuzzyValue(fuzzy_value);
    op.Build();
    return op.IsDone() && !op.HasErrors() ? op.Shape() : TopoDS_Shape();
  };
  TopoDS_Shape out = run(0.0);
  if (out.IsNull()) out = run(fuzzy);
  if (out.IsNull()) throw std::runtime_error("Boolean common failed");
  return out;
}

Mesh mesh_shape(const TopoDS_Shape& shape, double deflection, int* face_count) {
  BRepMesh_IncrementalMesh mesher(shape, deflection, false, 0.5, false);
  Mesh m;
  int faces_n = 0;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
    const TopoDS_Face& face = TopoDS::Face(ex.Current());
    ++faces_n;
    TopLoc_Location loc;
    const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
    if (tri.IsNull()) throw std::runtime_error("face without triangulation");
    const gp_Trsf trsf = loc.Transformation();
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (int i = 1; i <= tri->NbNodes(); ++i) {
      const gp_Pnt p = tri->Node(i).Transformed(trsf);
      m.vertices.emplace_back(p.X(), p.Y(), p.Z());
    }
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    for (int i = 1; i <= tri->NbTriangles(); ++i) {
      int a, b, c;
      tri->Triangle(i).Get(a, b, c);
      if (reversed) std::swap(b, c);
      m.triangles.push_back({base + static_cast<std::uint32_t>(a - 1), base + static_cast<std::uint32_t>(b - 1),
                             base + static_cast<std::uint32_t>(c - 1)});
    }
  }
  if (face_count) *face_count = faces_n;
  return m;
}

void write_step_atomic(const TopoDS_Shape& shape, const std::filesystem::path& path) {
  std::filesystem::create_directories(path.parent_path().empty() ? "." : path.parent_path());
  const std::filesystem::path tmp = path.string() + ".tmp";
  // OpenCASCADE's STEP writer is not thread-safe (its translation tables and static
  // parameters are process-wide): two parts written at once by simplify_parts' threads
  // failed now and then ("cannot write STEP file"). One writer at a time.
  static std::mutex step_writer;
  const std::lock_guard<std::mutex> lock(step_writer);
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone ||
      writer.Write(tmp.string().c_str()) != IFSelect_RetDone) {
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot write STEP file " + path.string());
  }
  std::filesystem::rename(tmp, path);
}

/// True for the statuses whose projection was replaced by its convex hull.
bool is_hull(ProjectionStatus s) {
  return s == ProjectionStatus::Empty || s == ProjectionStatus::Torn || s == ProjectionStatus::Eroded;
}

/// Densifies `shape` where it misses `checks` by more than tol or `exact` at all (refine),
/// keeps the Delaunay triangles that still hold one (cover), and records the outcome in
/// rep: Repaired, or Torn (replaced by the convex hull) when the added area exceeds
/// torn_fraction of the region. `exact` are gap points of segments checked within less
/// than tol (edge_on_gaps): a gap point between that tolerance and tol must be covered
/// too, or the same gap is found again.
void repair_projection(AlphaShape2D& shape, const std::vector<Vec2>& checks, const std::vector<Vec2>& exact, double tol,
                       double torn_fraction, ProjectionReport& rep) {
  // When refine finds no check outside, every one is within tol of the region already:
  // cover() then only has to attach isolated vertices (it need not test the checks again).
  const bool changed = shape.refine(checks, tol, exact) > 0;
  double added = shape.cover(changed ? checks : std::vector<Vec2>(), tol);
  if (changed && !exact.empty()) added += shape.cover(exact, 0.0);
  if (added > torn_fraction * shape.area()) {
    rep.status = ProjectionStatus::Torn;
    shape.keep_all();
  } else if (added > 0.0) {
    rep.status = ProjectionStatus::Repaired;
  }
}

using ShapeSnapshot = std::vector<std::pair<std::array<Vec2, 3>, char>>;

/// Boxes (min, max) of the triangles that are in one snapshot and not in the other
/// (corners and kept flag compared exactly; a hash only groups the candidates).
std::vector<std::array<Vec2, 2>> changed_boxes(const ShapeSnapshot& a, const ShapeSnapshot& b) {
  // (hash, index << 1 | side): equal triangles share a run of equal hashes.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> keys;
  keys.reserve(a.size() + b.size());
  auto hash = [](const std::pair<std::array<Vec2, 3>, char>& t) {
    return hash_triangle(t.first) ^ std::uint64_t(t.second) * 0x9e3779b97f4a7c15ull;
  };
  for (std::size_t i = 0; i < a.size(); ++i) keys.emplace_back(hash(a[i]), std::uint64_t(i) << 1);
  for (std::size_t i = 0; i < b.size(); ++i) keys.emplace_back(hash(b[i]), std::uint64_t(i) << 1 | 1u);
  sort_pairs(keys);
  auto item = [&](std::uint64_t k) -> const std::pair<std::array<Vec2, 3>, char>& { return (k & 1) ? b[k >> 1] : a[k >> 1]; };
  std::vector<std::array<Vec2, 2>> out;
  std::vector<char> matched;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j].first == keys[i].first) ++j;
    // Within the run, pair each entry of one side with an equal one of the other.
    matched.assign(j - i, 0);
    for (std::size_t p = i; p < j; ++p) {
      if (matched[p - i]) continue;
      for (std::size_t q = p + 1; q < j; ++q)
        if (!matched[q - i] && (keys[q].second & 1) != (keys[p].second & 1) && item(keys[q].second) == item(keys[p].second)) {
          matched[p - i] = matched[q - i] = 1;
          break;
        }
      if (!matched[p - i]) {
        const auto& c = item(keys[p].second).first;
        out.push_back({c[0].cwiseMin(c[1]).cwiseMin(c[2]), c[0].cwiseMax(c[1]).cwiseMax(c[2])});
      }
    }
    i = j;
  }
  return out;
}

/// For each of `boxes`, 1 if it comes within `pad` of one of `near` (boxes as (min, max),
/// plane coordinates): `near` sorted by lower x is searched over the x-window that can
/// reach the box. All 1 when that search would visit more than a few candidates per box
/// (changes spread over the whole shape: testing everything is then as cheap).
std::vector<char> near_any(const std::vector<std::array<Vec2, 2>>& boxes, std::vector<std::array<Vec2, 2>> near, double pad) {
  std::vector<char> out(boxes.size(), 0);
  if (near.empty()) return out;
  std::sort(near.begin(), near.end(), [](const auto& x, const auto& y) { return x[0].x() < y[0].x(); });
  double width = 0.0;
  for (const auto& n : near) width = std::max(width, n[1].x() - n[0].x());
  constexpr std::size_t kVisitsPerBox = 16;
  std::size_t visits = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const auto& bx = boxes[i];
    auto it = std::lower_bound(near.begin(), near.end(), bx[0].x() - pad - width,
                               [](const auto& n, double x) { return n[0].x() < x; });
    for (; it != near.end() && (*it)[0].x() <= bx[1].x() + pad; ++it) {
      if (++visits > kVisitsPerBox * boxes.size() + near.size()) return std::vector<char>(boxes.size(), 1);
      const auto& n = *it;
      if (n[1].x() >= bx[0].x() - pad && n[0].y() <= bx[1].y() + pad && n[1].y() >= bx[0].y() - pad) {
        out[i] = 1;
        break;
      }
    }
  }
  return out;
}

/// Makes `shape` hold every triangle of `mesh` projected by `pr` within tol, exactly (up
/// to rounding), or replaces it by its convex hull (status Eroded, or Torn as
/// repair_projection decides): the regular checks first (repair_projection), then up to
/// kExactRepairs passes that find the gaps of every triangle — those seen edge-on by their
/// longest edge within tol/2 (edge_on_triangles), the others whole
/// (AlphaShape2D::triangle_gaps) — and repair them. The triangles are tested with their
/// corners snapped (to `snap`, as the samples are, so that they lie in the hull of the
/// samples) within tol − snap·√2/2: a point of the triangle lies within snap·√2/2 of the
/// same combination of the snapped corners. `edge_on` and `exact` (the gap points, kept
/// covered by later repairs) are filled for the caller. The outline checks are listed
/// into `checks` only if a repair uses them (`deferred`).
void exact_projection(const Mesh& mesh, const std::vector<Vec2>& projected, double snap, double tol, AlphaShape2D& shape,
                      std::vector<Vec2>& checks, DeferredChecks& deferred, EdgeOnTriangles& edge_on, std::vector<Vec2>& exact,
                      double torn_fraction, double l_max, ProjectionReport& rep) {
  // Passes of gap finding and repair; a plane with gaps after the last is replaced by its hull.
  constexpr int kExactRepairs = 3;
  // The first passes repair by inserting the gap points (a notch closes with small
  // triangles), the later ones by keeping the faces that hold them.
  constexpr int kRefinePasses = 1;
  auto sorted_checks = [&]() -> const std::vector<Vec2>& {
    deferred.list(checks);
    return checks;
  };
  const double edge_on_width = kEdgeOnWidthShare * tol, edge_on_tol = kEdgeOnTolShare * tol;
  const double triangle_tol = tol - snap * M_SQRT1_2;
  const double gap_spacing = l_max / 4.0;
  edge_on = edge_on_triangles(mesh, projected, edge_on_width, snap);
  rep.edge_on_triangles = static_cast<std::size_t>(std::count(edge_on.flag.begin(), edge_on.flag.end(), 1));
  rep.edge_on_segments = edge_on.segments.size();
  std::vector<Vec2> proj(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) proj[i] = snap_to_grid(projected[i], snap);
  std::vector<std::array<Vec2, 3>> tested;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (!edge_on.flag[t]) {
      const auto& f = mesh.triangles[t];
      tested.push_back({proj[f[0]], proj[f[1]], proj[f[2]]});
    }
  rep.exact_triangles = tested.size();
  // Front and back faces of a plate, and the walls of a hole seen along its axis, project
  // onto the same triangles: each is tested once (the spar's end view: 12,252 -> 632).
  // (AlphaShape2D::triangles_gaps sorts its gap points: the order of `tested` is free.)
  for (auto& t : tested) std::sort(t.begin(), t.end(), xy_less);
  dedupe_by_hash(
      tested, hash_triangle,
      [](const auto& x, const auto& y) { return x == y; }, [](auto&, const auto&) {});
  // After a repair only what lies near a change can have changed: a triangle or segment
  // whose box, widened by tol, meets no Delaunay triangle that the repair added, removed
  // or flipped (kept ↔ removed) and holds no gap point found before it sees the same
  // faces within tol, so it has no gaps again (it had none). The others are tested again
  // (`retest_*`; all of them at first): the gaps found are the same as if all were.
  auto box_of = [](const auto& corners) {
    std::array<Vec2, 2> b{corners[0], corners[0]};
    for (const Vec2& q : corners) {
      b[0] = b[0].cwiseMin(q);
      b[1] = b[1].cwiseMax(q);
    }
    return b;
  };
  std::vector<std::array<Vec2, 2>> tested_boxes, segment_boxes;
  std::vector<char> retest_tested(tested.size(), 1), retest_segments(edge_on.segments.size(), 1);
  std::vector<std::array<Vec2, 3>> tested_now;
  EdgeOnTriangles edge_on_now;
  auto find_gaps = [&]() {
    tested_now.clear();
    for (std::size_t i = 0; i < tested.size(); ++i)
      if (retest_tested[i]) tested_now.push_back(tested[i]);
    edge_on_now.segments.clear();
    for (std::size_t i = 0; i < edge_on.segments.size(); ++i)
      if (retest_segments[i]) edge_on_now.segments.push_back(edge_on.segments[i]);
    std::vector<Vec2> gaps = edge_on_gaps(shape, edge_on_now, edge_on_tol, gap_spacing);
    const std::vector<Vec2> inside = shape.triangles_gaps(tested_now, triangle_tol, gap_spacing);
    gaps.insert(gaps.end(), inside.begin(), inside.end());
    return gaps;  // in an order independent of the thread schedule (triangles_gaps sorts)
  };
  auto mark_changes = [&](const ShapeSnapshot& before, const std::vector<Vec2>& gaps) {
    std::vector<std::array<Vec2, 2>> near = changed_boxes(before, shape.snapshot());
    for (const Vec2& g : gaps) near.push_back({g, g});
    if (tested_boxes.empty()) {
      for (const auto& t : tested) tested_boxes.push_back(box_of(t));
      for (const auto& sg : edge_on.segments) segment_boxes.push_back(box_of(sg));
    }
    retest_tested = near_any(tested_boxes, near, tol);
    retest_segments = near_any(segment_boxes, near, tol);
  };
  // The first repair tests the checks (outline points, the slowest to test). Where the
  // α-shape as built has no gaps, every check (a point of the projected surface) lies
  // within tol of it and that repair would insert none: the shape is tested first and,
  // without gaps, repaired without them (isolated vertices are still attached), which
  // saves most of a CAD plate's plane (the spar: 71 -> 64 ms). Where every
  // kPreCheckStride-th check already misses (a curved part's silhouette), the shape has
  // gaps: the checks go first, as the exact test of an unrepaired shape costs more (the
  // bunny: 81 -> 94 ms without this guess, 90 with every 16th check and triangle tested).
  // Either way the same shape results.
  constexpr std::size_t kPreCheckStride = 4;
  const bool misses = deferred.any_of_every(kPreCheckStride, [&](const Vec2& q) { return !shape.contains(q, tol); });
  std::vector<Vec2> gaps;
  if (misses) {
    repair_projection(shape, sorted_checks(), exact, tol, torn_fraction, rep);
    if (is_hull(rep.status)) return;
  } else {
    gaps = find_gaps();
    if (gaps.empty()) {
      repair_projection(shape, {}, exact, tol, torn_fraction, rep);
      if (!is_hull(rep.status)) shape.fill_pinches();
      return;
    }
    const ShapeSnapshot before = shape.snapshot();
    repair_projection(shape, sorted_checks(), exact, tol, torn_fraction, rep);
    if (is_hull(rep.status)) return;
    mark_changes(before, gaps);
  }
  for (int pass = 0;; ++pass) {
    gaps = find_gaps();
    if (gaps.empty()) {
      shape.fill_pinches();
      return;
    }
    if (pass == kExactRepairs) break;
    rep.exact_gaps += gaps.size();
    const ShapeSnapshot before = shape.snapshot();
    if (pass < kRefinePasses) {
      exact.insert(exact.end(), gaps.begin(), gaps.end());
      repair_projection(shape, sorted_checks(), exact, tol, torn_fraction, rep);
    } else {
      // Then the removed faces that hold the gaps are kept: each gap point lies inside the
      // face that holds its piece, which then covers all of it, so one such pass closes
      // every gap (keeping faces only shrinks the others). Inserted points may not: around
      // a silhouette sliver their new triangles are thin, above α, and only those holding
      // a point are kept.
      const double added = shape.cover(gaps, 0.0);
      if (added > torn_fraction * shape.area()) {
        rep.status = ProjectionStatus::Torn;
        shape.keep_all();
      } else if (added > 0.0) {
        rep.status = ProjectionStatus::Repaired;
      }
    }
    if (is_hull(rep.status)) break;
    mark_changes(before, gaps);
  }
  if (is_hull(rep.status)) return;
  rep.status = ProjectionStatus::Eroded;
  shape.keep_all();
}

void keep_original(AlphaSimPart& out, const Part& part, AlphaSimStatus status, const std::string& reason) {
  out.mesh = part.mesh;
  out.solid.reset();
  auto& r = out.result;
  r.status = status;
  r.fallback = AlphaSimFallback::Original;
  r.reason = reason;
  r.triangles_after = r.triangles_before;
  r.faces_after = r.faces_before;
  r.closed_after = r.closed_before;
  r.volume_after = r.volume_before;
  r.containment = r.containment_implicit = 1.0;  // the same surface
  r.hausdorff = 0.0;
}

/// The projection reports of a part turned by R (an axis-mapping rotation), from those of
/// the part before the turn: the projection that had normal n is the turned part's
/// projection with normal ±R·n, reported in the order and under the names of `specs`.
/// Reports that do not cover every plane (a part kept early) are returned as they are.
std::vector<ProjectionReport> turned_projections(const std::vector<ProjectionReport>& before,
                                                 const Eigen::Matrix3d& R, const std::vector<PlaneSpec>& specs) {
  if (before.size() != specs.size()) return before;
  std::vector<ProjectionReport> out(specs.size());
  std::size_t matched = 0;
  for (const ProjectionReport& rep : before) {
    const Vec3 n = R * rep.normal;
    for (std::size_t k = 0; k < specs.size(); ++k)
      if (std::abs(std::abs(n.dot(specs[k].frame.n)) - 1.0) < 1e-9) {
        out[k] = rep;
        out[k].plane = specs[k].name;
        out[k].normal = specs[k].frame.n;
        ++matched;
      }
  }
  return matched == specs.size() ? out : before;
}

}  // namespace

AlphaSimPlaneSamples alpha_sim_plane_samples(const Mesh& mesh, const AlphaSimPrism& frame, double l_max, double snap,
                                             bool lattice_bitmap, bool coarse_interior, bool all_checks) {
  if (!(l_max > 0.0 && snap > 0.0)) throw std::invalid_argument("alpha-sim: l_max and snap must be > 0");
  return sample_projection(mesh, unique_edges(mesh), project_vertices(mesh, frame), l_max, snap, lattice_bitmap,
                           coarse_interior, all_checks);
}

// ---------------------------------------------------------------------------------------

namespace {

/// One run of simplify_part: the part, the options and what the stages share. Each stage
/// returns false when it has settled the result early (original kept, or nothing more to
/// do); run() calls them in order.
struct PartSimplification {
  PartSimplification(const Part& part_in, const AlphaSimOptions& opt_in, const std::string& stem);
  /// Runs the stages and returns the simplified part with its report.
  AlphaSimPart run();
  /// Empty and non-finite input, sheets, and sampling that would not fit in memory.
  bool check_input();
  /// α-SIM steps 1–3: samples, α-shape and exact containment repair of each projection.
  bool build_shapes();
  /// Step 4: the boundary polygons to extrude, simplified within the tolerance.
  void outline_polygons();
  /// Steps 5–6: the prisms intersected and meshed (CGAL, else OpenCASCADE).
  bool build_mesh();
  /// Containment of the original in the mesh and the implicit solid, Hausdorff distance,
  /// lost space.
  bool measure();
  /// The lost-space probe on the implicit solid (before any mesh is built: a blocked part
  /// keeps its original, so its Booleans would be wasted).
  bool probe_lost_space_first();
  /// The original part as a one-part index (built once, for the probe and the Hausdorff
  /// distance).
  const EmbreeIndex& original_index();
  /// The STEP file, when asked for.
  void write_step();

  const Part& part;
  const AlphaSimOptions& opt;
  const std::string& step_stem;
  const Stopwatch t0;
  std::vector<PlaneSpec> specs;
  AlphaSimPart out;
  AlphaSimResult& r = out.result;
  std::vector<MeshEdge> edges;
  AABB box;
  double rounding_reserve = 0.0;
  double tol = 0.0;  ///< the containment tolerance less the float32 rounding reserve
  std::vector<std::vector<Vec2>> projected;  ///< the vertices in each plane
  std::vector<AlphaSimPrism> prisms;
  std::vector<std::shared_ptr<AlphaShape2D>> shapes;
  std::shared_ptr<AlphaSimSolid> solid;
  std::vector<std::vector<PolygonWithHoles2>> polys;
  TopoDS_Shape result;  ///< OpenCASCADE's solid, when it ran the Booleans
  std::unique_ptr<EmbreeIndex> original;  ///< see original_index()
};

PartSimplification::PartSimplification(const Part& part_in, const AlphaSimOptions& opt_in, const std::string& stem)
    : part(part_in), opt(opt_in), step_stem(stem) {
  if (!(std::isfinite(opt.dim_pre) && opt.dim_pre > 0.0))
    throw std::invalid_argument("alpha-sim: dim_pre must be finite and > 0, got " + full_precision(opt.dim_pre));
  if (!(opt.sampling_factor > 0.0 && opt.alpha_factor > 0.0))
    throw std::invalid_argument("alpha-sim: sampling_factor and alpha_factor must be > 0");
  specs = planes_for(opt);

  r.name = part.name;
  r.dim_pre = opt.dim_pre;
  r.alpha = opt.alpha_factor * opt.dim_pre;
  r.l_max = opt.sampling_factor * opt.dim_pre;
  r.triangles_before = part.mesh.triangle_count();
  r.faces_before = part.source_faces;
  edges = unique_edges(part.mesh);
  r.closed_before = closed_mesh(part.mesh, edges);
  r.volume_before = r.closed_before ? std::abs(part.mesh.signed_volume()) : 0.0;
  box = part.mesh.bounds();
  const double size = opt.scene_size > 0.0 ? opt.scene_size : box.diagonal();
  r.tolerance = opt.containment_tolerance_factor * (size > 0.0 ? size : 1.0);
  // Rounding the output mesh to float32 (float32_vertices) may move its vertices by
  // rounding_reserve (checked once it is made): the shapes are built and checked within the
  // rest of the tolerance, tol.
  rounding_reserve = float_rounding_reserve(box, opt, r.tolerance);
  tol = r.tolerance - rounding_reserve;
}

AlphaSimPart PartSimplification::run() {
  if (check_input() && build_shapes()) {
    outline_polygons();
    r.shapes_ms = t0.ms();
    if (opt.build_mesh && probe_lost_space_first() && build_mesh() && measure()) write_step();
  }
  r.time_ms = t0.ms();
  return std::move(out);
}

bool PartSimplification::check_input() {
  if (part.mesh.empty()) {
    keep_original(out, part, AlphaSimStatus::EmptyInput, "the part has no triangles");
    return false;
  }
  if (first_non_finite_vertex(part.mesh) >= 0)
    throw std::invalid_argument("alpha-sim: part '" + part.name + "' has a non-finite vertex");

  // Too thin along a projection normal: the part is a sheet, extrusions would be flat. Thin
  // along every normal, it is smaller than the cable scale, not a sheet: the reason says so.
  const double thin = opt.thin_factor * opt.dim_pre;
  std::vector<double> extents;
  for (const auto& s : specs) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& f : part.mesh.triangles)
      for (auto i : f) {
        const double d = part.mesh.vertices[i].dot(s.frame.n);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
    extents.push_back(hi - lo);
  }
  const auto thinnest = std::min_element(extents.begin(), extents.end());
  if (thinnest != extents.end() && *thinnest < thin) {
    const bool small = std::all_of(extents.begin(), extents.end(), [&](double e) { return e < thin; });
    const std::string& plane = specs[static_cast<std::size_t>(thinnest - extents.begin())].name;
    keep_original(out, part, AlphaSimStatus::Thin,
                  small ? "extent along every projection normal is below " + full_precision(thin) +
                              " (the part is smaller than the cable scale, nothing to simplify): original kept"
                        : "extent along the " + plane + " normal is " + full_precision(*thinnest) + " < " +
                              full_precision(thin) + " (a sheet): original kept");
    return false;
  }

  // The work is known before sampling: refuse what would not fit in memory.
  projected.assign(specs.size(), {});  // the vertices in each plane
  {
    std::vector<PlaneWork> per_plane(specs.size());
    tbb::parallel_for(std::size_t(0), specs.size(), [&](std::size_t k) {
      projected[k] = project_vertices(part.mesh, specs[k].frame);
      per_plane[k] = {plane_sample_estimate(part.mesh, edges, projected[k], r.l_max),
                      hull_lattice_estimate(part.mesh, projected[k], r.l_max)};
    });
    const std::string why = too_fine_reason(per_plane, r.l_max, opt.max_cloud_points);
    if (!why.empty()) {
      keep_original(out, part, AlphaSimStatus::TooFine, why);
      return false;
    }
  }
  return true;
}

bool PartSimplification::build_shapes() {
  // 1–2. Sample each projection (L_max), 3. build its α-shape (planes in parallel).
  prisms.assign(specs.size(), AlphaSimPrism{});
  shapes.assign(specs.size(), nullptr);
  r.projections.resize(specs.size());
  std::atomic<bool> degenerate{false};
  std::vector<AlphaSimPlaneSamples> plane_samples(specs.size());
  // Snap projections to a grid of snap ≤ tol/4 and drop duplicates: points that are
  // equal up to rounding (the same 3D edge subdivided from either end, front and back
  // faces) would otherwise give sliver triangles and spurious boundary loops.
  // A power of two, so that coordinates on a binary grid (integers, halves) stay exact.
  const double snap = std::exp2(std::floor(std::log2(tol / 4.0)));
  // Interior lattice cells of 2·L_max (sample_projection) are kept by the α-shape only if
  // their circumradius √2·L_max stays below α, with a margin for the snapping.
  const bool coarse_interior = M_SQRT2 * r.l_max < kCoarseCellAlphaMargin * r.alpha;
  std::vector<EdgeOnTriangles> edge_on(specs.size());
  // The planes' outline checks, listed only where a repair uses them.
  std::vector<DeferredChecks> deferred(specs.size());
  // Gap points of the edge-on segments found so far, per plane: kept covered by every
  // later repair (with the checks).
  std::vector<std::vector<Vec2>> exact_checks(specs.size());
  tbb::parallel_for(std::size_t(0), specs.size(), [&](std::size_t k) {
    AlphaSimPrism pr = specs[k].frame;
    ProjectionReport& rep = r.projections[k];
    rep.plane = specs[k].name;
    rep.normal = pr.n;
    pr.depth_min = std::numeric_limits<double>::infinity();
    pr.depth_max = -pr.depth_min;
    for (const auto& f : part.mesh.triangles)
      for (auto i : f) {
        const double d = part.mesh.vertices[i].dot(pr.n);
        pr.depth_min = std::min(pr.depth_min, d);
        pr.depth_max = std::max(pr.depth_max, d);
      }
    AlphaSimPlaneSamples& smp = plane_samples[k];
    // The exact test finds what centroids and midpoints of interior edges would.
    smp = sample_projection(part.mesh, edges, projected[k], r.l_max, snap, true, coarse_interior, false, &deferred[k]);
    const std::vector<Vec2>& pts = smp.points;
    rep.points = pts.size();
    auto shape = std::make_shared<AlphaShape2D>(pts, r.alpha, std::min(opt.short_edge_factor * r.l_max, r.alpha));
    rep.delaunay_triangles = shape->delaunay_triangle_count();
    rep.alpha_area = shape->area();
    rep.hull_area = shape->hull_area();
    if (shape->degenerate()) degenerate = true;
    if (shape->kept_triangle_count() == 0) {
      rep.status = ProjectionStatus::Empty;
      shape->keep_all();
    } else {
      exact_projection(part.mesh, projected[k], snap, tol, *shape, smp.checks, deferred[k], edge_on[k], exact_checks[k],
                       opt.torn_fraction, r.l_max, rep);
    }
    pr.shape = shape;
    prisms[k] = pr;
    shapes[k] = shape;
  });
  for (const auto& rep : r.projections) r.sample_points += rep.points;
  if (degenerate) {
    keep_original(out, part, AlphaSimStatus::Thin, "a projection is degenerate (collinear points): original kept");
    return false;
  }

  plane_samples.clear();
  bool hull = false;
  for (std::size_t k = 0; k < specs.size(); ++k) {
    auto& rep = r.projections[k];
    rep.kept_triangles = shapes[k]->kept_triangle_count();
    rep.area = shapes[k]->area();
    hull = hull || is_hull(rep.status);
  }
  solid = std::make_shared<AlphaSimSolid>(prisms);
  out.solid = solid;
  if (hull) {
    r.status = AlphaSimStatus::HullFallback;
    r.fallback = AlphaSimFallback::ConvexHull;
    std::string planes;
    for (const auto& rep : r.projections)
      if (is_hull(rep.status))
        planes += (planes.empty() ? "" : ", ") + rep.plane + " (" + projection_status_name(rep.status) + ")";
    r.reason = "convex hull used for " + planes;
  }
  return true;
}

void PartSimplification::outline_polygons() {
  // 4. boundary polygons, merged collinear points (paper: included angle < 1e-6 deg).
  // Vertices within merge_tol (tol/4) of the chord replacing them are merged too: the
  // snapped projections of a straight edge are collinear only up to the snap grid. The
  // region may shrink by merge_tol, which the containment tolerance covers (verified below).
  constexpr double kCollinearAngle = 1e-6 * M_PI / 180.0;
  const double merge_tol = tol / 4.0;
  // merge_collinear looks at runs of at most 256 vertices: a second pass merges the chords
  // of a long straight edge (a 1.5 m spar flange has ~10⁴ samples). Half the tolerance
  // each, so that the total stays within merge_tol.
  auto merge = [&](std::vector<Vec2>& ring) {
    if (merge_collinear(ring, kCollinearAngle, merge_tol / 2.0) > 0) merge_collinear(ring, kCollinearAngle, merge_tol / 2.0);
  };
  polys.assign(specs.size(), {});
  for (std::size_t k = 0; k < specs.size(); ++k) {
    polys[k] = shapes[k]->polygons();
    auto& rep = r.projections[k];
    std::vector<PolygonWithHoles2> kept;
    for (auto& p : polys[k]) {
      merge(p.outer);
      if (p.outer.size() < 3) continue;
      std::vector<std::vector<Vec2>> holes;
      for (auto& h : p.holes) {
        merge(h);
        if (h.size() >= 3) holes.push_back(std::move(h));
      }
      p.holes = std::move(holes);
      rep.polygon_vertices += p.outer.size();
      for (const auto& h : p.holes) rep.polygon_vertices += h.size();
      rep.holes += p.holes.size();
      kept.push_back(std::move(p));
    }
    rep.polygons = kept.size();
    polys[k] = std::move(kept);
    // Coarser than the α-shape where it only adds material (notches, hole rims, convex
    // arcs): fewer prism faces for the Booleans and fewer output triangles; containment is
    // kept.
    rep.polygon_vertices -=
        grow_simplify(polys[k], opt.polygon_growth_factor * opt.dim_pre, opt.merge_convex_corners);
  }
}

bool PartSimplification::build_mesh() {
  const Stopwatch t_mesh;

  // 5–6. extrude and intersect, mesh the result. Each prism runs a margin past the part
  // so that no cap of one coincides with a face of another.
  const double margin = prism_margin(opt, r.tolerance);
  std::vector<Extrusion> extrusions(specs.size());
  for (std::size_t k = 0; k < specs.size(); ++k)
    extrusions[k] = {prisms[k].u, prisms[k].v, prisms[k].n, prisms[k].depth_min - margin,
                     prisms[k].depth_max + margin, polys[k]};
  // Prisms whose region is an axis-aligned rectangle are slabs the others can carry (the
  // spar seen from above and from the side): fewer OpenCASCADE Booleans, and none when one
  // prism is left. Slack tol: the result may stand off the exact intersection by that much
  // along an axis (it only grows, so containment holds), where projections of the same
  // part's extent differ by rounding.
  const ExtrusionReduction reduced = reduce_extrusions(extrusions, tol);
  r.prisms_absorbed = static_cast<int>(reduced.absorbed);
  // Watertight: no boundary and no misoriented edge. Edges shared by four triangles are
  // allowed: two pieces of the intersection may touch along an edge.
  // The vertices are rounded to float32 first (float32_vertices): rounding can fold a
  // sliver or merge two vertices, and the checks below must hold for the mesh as written.
  auto watertight_mesh = [&](Mesh& m, MeshTopology& t) {
    if (opt.float32_vertices) r.float_rounding = round_vertices_to_float(m);
    weld_identical_vertices(m);
    t = analyse_topology(m);
    return t.boundary_edges == 0 && t.misoriented_edges == 0;
  };
  MeshTopology otopo;
  bool watertight = false;
  if (!opt.step_dir.empty()) r.booleans_note = "--step";
  if (opt.step_dir.empty()) {
    // One prism is the result; two across each other (the rib's outline and its web) are
    // sliced along their common axis; a third is intersected by exact corefinement (CGAL).
    // No OpenCASCADE (and no STEP asked for).
    try {
      // Vertices the corefinement leaves on straight edges are removed within tol/4, as
      // the outlines' collinear points were (merge_tol): containment stays within tol.
      ExtrusionsMesh direct = mesh_extrusions(reduced.kept, tol / 4.0);
      out.mesh = std::move(direct.mesh);
      r.faces_after = direct.faces;
      r.booleans = direct.booleans;
      r.booleans_by = direct.booleans > 0 ? "cgal" : "none";
      watertight = watertight_mesh(out.mesh, otopo);
      if (!watertight) r.booleans_note = "loom's mesh is not closed";
    } catch (const std::runtime_error& e) {
      // e.g. rings that cross, pieces that touch: OpenCASCADE decides, and the report says why.
      watertight = false;
      r.booleans_note = e.what();
    }
  }
  if (!watertight) {
    try {
      std::vector<TopoDS_Shape> solids(reduced.kept.size());
      for (std::size_t k = 0; k < reduced.kept.size(); ++k) solids[k] = prism_shape(reduced.kept[k]);
      result = solids[0];
      for (std::size_t k = 1; k < solids.size(); ++k) result = common(result, solids[k], tol);
      r.booleans = static_cast<int>(solids.size()) - 1;
      r.booleans_by = r.booleans > 0 ? "opencascade" : "none";
      if (r.booleans == 0) r.booleans_note.clear();  // OpenCASCADE meshed one prism: no Boolean to explain
      out.mesh = mesh_shape(result, opt.dim_pre, &r.faces_after);
    } catch (const Standard_Failure& e) {
      keep_original(out, part, AlphaSimStatus::Failed,
                    std::string("OpenCASCADE failed: ") + (e.GetMessageString() ? e.GetMessageString() : "?") +
                        ": original kept");
      return false;
    } catch (const std::exception& e) {
      keep_original(out, part, AlphaSimStatus::Failed,
                    std::string("OpenCASCADE failed: ") + e.what() + ": original kept");
      return false;
    }
    watertight = watertight_mesh(out.mesh, otopo);
  }
  r.mesh_ms = t_mesh.ms();
  if (watertight && out.mesh.signed_volume() < 0.0)
    for (auto& f : out.mesh.triangles) std::swap(f[1], f[2]);
  if (r.float_rounding > rounding_reserve) {
    keep_original(out, part, AlphaSimStatus::Failed,
                  "rounding the simplified mesh to float32 (binary STL) moved a vertex by " +
                      full_precision(r.float_rounding) + " > the " + full_precision(rounding_reserve) +
                      " of the containment tolerance kept for it (the part lies far from the origin for its size): original kept");
    return false;
  }
  r.closed_after = watertight;
  r.triangles_after = out.mesh.triangle_count();
  r.volume_after = watertight ? std::abs(out.mesh.signed_volume()) : 0.0;
  if (!watertight || out.mesh.empty()) {
    keep_original(out, part, AlphaSimStatus::Failed,
                  "the OpenCASCADE result mesh is not closed (" + std::to_string(otopo.boundary_edges) +
                      " boundary, " + std::to_string(otopo.nonmanifold_edges) + " non-manifold, " +
                      std::to_string(otopo.misoriented_edges) + " misoriented edges): original kept");
    return false;
  }
  return true;
}

bool PartSimplification::measure() {
  const Stopwatch t_measure;
  if (opt.measure) {
    // Containment of the original surface in the output mesh (what indices will use), on
    // a whole dense set (fixed and random points) of its own seed.
    const std::vector<Vec3> samples =
        dense_surface_samples(part.mesh, edges, r.l_max, opt.containment_density, opt.containment_max_samples,
                              opt.seed + kMeasureSeedOffset, true);
    r.containment_samples = samples.size();
    {
      // Contained by construction (exact_projection): verified here on the implicit solid,
      // independently of how the shapes were repaired.
      const std::size_t in = tbb::parallel_reduce(
          tbb::blocked_range<std::size_t>(0, samples.size(), 4096), std::size_t(0),
          [&](const auto& rg, std::size_t acc) {
            for (std::size_t i = rg.begin(); i != rg.end(); ++i) acc += solid->contains(samples[i], r.tolerance) ? 1 : 0;
            return acc;
          },
          std::plus<std::size_t>());
      r.containment_implicit = samples.empty() ? 1.0 : static_cast<double>(in) / samples.size();
    }
    const EmbreeIndex simplified = mesh_index(out.mesh, true, true);  // watertight: checked above
    // The mesh as written (float32 vertices) within the whole tolerance.
    const std::size_t in = count_contained_mesh(simplified, samples, r.tolerance);
    r.containment = samples.empty() ? 1.0 : static_cast<double>(in) / samples.size();
    if (in != samples.size() || r.containment_implicit < 1.0) {
      // Either model missing a sample is a failure: the implicit solid is a result too.
      const double c = r.containment, ci = r.containment_implicit;
      keep_original(out, part, AlphaSimStatus::Failed,
                    (in != samples.size() ? "output mesh" : "implicit solid") + std::string(" contains only ") +
                        full_precision(in != samples.size() ? c : ci) + " of the surface samples: original kept");
      r.containment = c;  // report what was measured before falling back
      r.containment_implicit = ci;
      return false;
    }
    // One-sided Hausdorff distance: output surface → original surface.
    r.hausdorff = 0.0;
    if (opt.hausdorff) {
      const auto surf = dense_surface_samples(out.mesh, r.l_max, 1.0, 200000, opt.seed + 1);
      for (const ClosestHit& h : original_index().closest_batch(surf, std::numeric_limits<double>::infinity()))
        r.hausdorff = std::max(r.hausdorff, h.distance);
    }
  }

  r.measure_ms += t_measure.ms();
  return true;
}

const EmbreeIndex& PartSimplification::original_index() {
  if (!original) original = std::make_unique<EmbreeIndex>(one_part(part.mesh, r.closed_before));
  return *original;
}

bool PartSimplification::probe_lost_space_first() {
  // Lost space (blocked projections): largest ball inside the simplified solid and
  // outside the original, probed on a grid. Only a closed original has an outside.
  if (!(opt.measure && opt.detect_lost_space && r.closed_before)) return true;
  const Stopwatch t_probe;
  const double r_lost = opt.lost_space_factor * opt.dim_pre;
  const LostSpace lost = probe_lost_space({solid.get()}, original_index(), box, r_lost / 2.0, opt.lost_space_max_samples);
  r.lost_space_radius = lost.radius;
  r.lost_space_center = lost.center;
  r.lost_space_resolution = lost.resolution;
  r.measure_ms += t_probe.ms();
  if (r.lost_space_radius < r_lost) return true;
  keep_original(out, part, AlphaSimStatus::Blocked,
                "a ball of radius " + full_precision(lost.radius) + " ≥ " + full_precision(r_lost) +
                    " outside the original fits inside the simplified part: a feature is hidden in every "
                    "projection; original kept");
  return false;
}

void PartSimplification::write_step() {
  if (!opt.step_dir.empty())
    write_step_atomic(result,
                      opt.step_dir / ((step_stem.empty() ? output_file_stems({part.name})[0] : step_stem) + ".step"));
}

}  // namespace

AlphaSimPart simplify_part(const Part& part, const AlphaSimOptions& opt, const std::string& step_stem) {
  return PartSimplification(part, opt, step_stem).run();
}

std::vector<Part> simplify_parts(const std::vector<Part>& parts, const AlphaSimOptions& opt,
                                 std::vector<AlphaSimResult>* results) {
  AlphaSimOptions o = opt;
  if (!(o.scene_size > 0.0)) {
    AABB all;
    for (const auto& p : parts) all.extend(p.mesh.bounds());
    o.scene_size = all.diagonal() > 0.0 ? all.diagonal() : 1.0;
  }
  // Parts that are copies of an earlier part (ribs, boxes placed along a span; a spar
  // turned end for end) are simplified once: the result is moved like the part, which keeps
  // containment (up to the rounding of the copy, far below the tolerance) and every
  // measure. A copy is the earlier part moved by a rotation that maps the coordinate axes
  // onto themselves (projection planes go to projection planes) and a translation. With
  // user planes only translations qualify: a rotation would turn those planes.
  const double copy_tol = 1e-2 * o.containment_tolerance_factor * o.scene_size;
  // Every part keeps the same share of the tolerance for float32 rounding: the bound of all
  // parts' box twice over, and the copies' deviation, so that a copy's mesh — the first
  // part's rounded mesh moved and rounded again — stays within it.
  if (o.float32_vertices && o.float_rounding_reserve < 0.0) {
    AABB all;
    for (const auto& p : parts) all.extend(p.mesh.bounds());
    const double tol = o.containment_tolerance_factor * o.scene_size;
    o.float_rounding_reserve = 2.0 * float_rounding_bound(all, o, tol) + copy_tol;
  }
  const std::vector<Eigen::Matrix3d> motions = axis_rotations(o.extra_planes.empty());
  std::vector<std::size_t> source(parts.size());
  std::vector<Eigen::Affine3d> move(parts.size(), Eigen::Affine3d::Identity());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    source[i] = i;
    const Mesh& mi = parts[i].mesh;
    // (Not when STEP files are written: each part gets its own OpenCASCADE solid.)
    for (std::size_t j = 0; j < i && source[i] == i && !mi.empty() && o.step_dir.empty(); ++j) {
      const Mesh& mj = parts[j].mesh;
      if (source[j] != j || mj.vertices.size() != mi.vertices.size() || mj.triangles != mi.triangles) continue;
      for (const Eigen::Matrix3d& R : motions) {
        const Vec3 t = mi.vertices[0] - R * mj.vertices[0];
        bool same = true;
        for (std::size_t v = 0; v < mi.vertices.size() && same; ++v)
          same = (mi.vertices[v] - R * mj.vertices[v] - t).cwiseAbs().maxCoeff() <= copy_tol;
        if (same) {
          source[i] = j;
          move[i].linear() = R;
          move[i].translation() = t;
          break;
        }
      }
    }
  }
  std::vector<std::size_t> unique;
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (source[i] == i) unique.push_back(i);
  std::vector<Part> out(parts.size());
  std::vector<AlphaSimResult> res(parts.size());
  ProgressCounter simplified(opt.progress, "simplify", parts.size(), "parts");
  std::vector<std::string> names;
  for (const auto& p : parts) names.push_back(p.name);
  const std::vector<std::string> stems = output_file_stems(names);
  // An exception must not leave a TBB task: it would cancel the task group, and with it
  // the nested parallel loops of the parts other threads are simplifying, which would then
  // go on with planes never built. Each part's exception is kept; the first (in part
  // order) is rethrown once every part has finished.
  std::vector<std::exception_ptr> failed(parts.size());
  // Part i simplified on its own: its result in out and res.
  auto store = [&](std::size_t i, AlphaSimPart sp) {
    Part p = parts[i];
    p.mesh = std::move(sp.mesh);
    p.closed = sp.result.closed_after;
    if (sp.result.fallback != AlphaSimFallback::Original) p.source_faces = sp.result.faces_after;
    out[i] = std::move(p);
    res[i] = std::move(sp.result);
    simplified.add();
  };
  tbb::parallel_for(std::size_t(0), unique.size(), [&](std::size_t u) {
    const std::size_t i = unique[u];
    AlphaSimPart sp;
    try {
      sp = simplify_part_split(parts[i], o, stems[i]);
    } catch (...) {
      failed[i] = std::current_exception();
      return;
    }
    store(i, std::move(sp));
  });
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (source[i] == i) continue;
    const Stopwatch t0;
    const std::size_t j = source[i];
    Part p = parts[i];
    double rounding = 0.0;
    if (res[j].fallback == AlphaSimFallback::Original) {
      p.mesh = parts[i].mesh;
    } else {
      p.mesh = out[j].mesh;
      for (auto& v : p.mesh.vertices) v = move[i] * v;  // a proper rotation: windings stay outward
      p.closed = out[j].closed;
      p.source_faces = out[j].source_faces;
      if (o.float32_vertices) {
        // The moved mesh is rounded to float32 again: with the rounding of the first part's
        // mesh and the copy's own deviation it must stay within the share of the tolerance
        // that the first part's shapes left for rounding, and closed; else the copy is
        // simplified on its own.
        rounding = round_vertices_to_float(p.mesh);
        const double budget = float_rounding_reserve(parts[j].mesh.bounds(), o, res[j].tolerance);
        weld_identical_vertices(p.mesh);
        const MeshTopology topo = analyse_topology(p.mesh);
        if (res[j].float_rounding + rounding + copy_tol > budget || topo.boundary_edges > 0 || topo.misoriented_edges > 0) {
          store(i, simplify_part_split(parts[i], o, stems[i]));
          continue;
        }
      }
    }
    const std::size_t triangles = p.mesh.triangle_count();
    const double volume = std::abs(p.mesh.signed_volume());
    out[i] = std::move(p);
    res[i] = res[j];
    if (res[j].fallback != AlphaSimFallback::Original && o.float32_vertices) {
      // Rounding may have merged vertices (and dropped a triangle): the report describes the copy's mesh.
      res[i].float_rounding = rounding;
      res[i].triangles_after = triangles;
      res[i].volume_after = volume;
    }
    if (!move[i].linear().isIdentity()) res[i].projections = turned_projections(res[j].projections, move[i].linear(), planes_for(o));
    res[i].name = parts[i].name;
    res[i].copy_of = parts[j].name;
    res[i].time_ms = t0.ms();
    res[i].shapes_ms = res[i].mesh_ms = res[i].measure_ms = 0.0;
    simplified.add();
  }
  simplified.finish();
  if (results) *results = std::move(res);
  return out;
}

}  // namespace loom
