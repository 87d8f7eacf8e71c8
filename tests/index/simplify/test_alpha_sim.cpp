// α-SIM: the 2D α-shape, the simplified solid and its failure modes, checked
// against closed forms (plates, L-bracket, cylinder), an independent containment oracle
// (BruteForceIndex winding numbers) and real meshes from ../shared/data.
#include "core/io/mesh_read.hpp"
#include "index/simplify/alpha_shape_2d.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "index/brute_force_index.hpp"
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"

#include <gtest/gtest.h>
#include "common/shared_data.hpp"
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

using namespace loom;

namespace {

/// Closed mesh of an extruded occupancy grid: cell (i, j) of size s is filled when
/// filled(i, j); the slab spans z ∈ [0, t]. Walls between filled and empty cells.
template <class F>
Mesh extruded_grid(int nx, int ny, double s, double t, F filled) {
  Mesh m;
  auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {  // CCW seen from outside
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {a, b, c, d});
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  };
  auto in = [&](int i, int j) { return i >= 0 && j >= 0 && i < nx && j < ny && filled(i, j); };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      if (!in(i, j)) continue;
      const double x0 = i * s, x1 = (i + 1) * s, y0 = j * s, y1 = (j + 1) * s;
      quad({x0, y0, t}, {x1, y0, t}, {x1, y1, t}, {x0, y1, t});
      quad({x0, y0, 0}, {x0, y1, 0}, {x1, y1, 0}, {x1, y0, 0});
      if (!in(i - 1, j)) quad({x0, y0, 0}, {x0, y0, t}, {x0, y1, t}, {x0, y1, 0});
      if (!in(i + 1, j)) quad({x1, y0, 0}, {x1, y1, 0}, {x1, y1, t}, {x1, y0, t});
      if (!in(i, j - 1)) quad({x0, y0, 0}, {x1, y0, 0}, {x1, y0, t}, {x0, y0, t});
      if (!in(i, j + 1)) quad({x0, y1, 0}, {x0, y1, t}, {x1, y1, t}, {x1, y1, 0});
    }
  weld_identical_vertices(m);
  return m;
}

Mesh box_mesh(const Vec3& lo, const Vec3& hi) {
  Mesh m = extruded_grid(1, 1, 1.0, 1.0, [](int, int) { return true; });
  for (auto& v : m.vertices) v = lo + v.cwiseProduct(hi - lo);
  return m;
}

/// Closed polygonal cylinder along z: n sides, radius r, z ∈ [0, h].
Mesh cylinder_mesh(double r, double h, int n) {
  Mesh m;
  m.vertices.push_back({0, 0, 0});
  m.vertices.push_back({0, 0, h});
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    m.vertices.push_back({r * std::cos(a), r * std::sin(a), 0});
    m.vertices.push_back({r * std::cos(a), r * std::sin(a), h});
  }
  for (int k = 0; k < n; ++k) {
    const std::uint32_t b0 = 2 + 2 * k, t0 = b0 + 1, b1 = 2 + 2 * ((k + 1) % n), t1 = b1 + 1;
    m.triangles.push_back({0, b1, b0});
    m.triangles.push_back({1, t0, t1});
    m.triangles.push_back({b0, b1, t1});
    m.triangles.push_back({b0, t1, t0});
  }
  return m;
}

Part make_part(const std::string& name, Mesh m) {
  Part p;
  p.name = name;
  p.mesh = std::move(m);
  p.closed = analyse_topology(p.mesh).closed;
  return p;
}

AlphaSimOptions options(double dim_pre) {
  AlphaSimOptions o;
  o.dim_pre = dim_pre;
  return o;
}

/// Independent containment oracle: winding number (BruteForceIndex) or distance ≤ tol.
double oracle_containment(const Mesh& simplified, const std::vector<Vec3>& samples, double tol) {
  Part p = make_part("s", simplified);
  BruteForceIndex idx({p});
  std::size_t in = 0;
  for (const auto& s : samples)
    if (idx.inside(s) || idx.closest(s, 2 * tol).found()) ++in;
  return samples.empty() ? 1.0 : static_cast<double>(in) / samples.size();
}

std::vector<Vec2> grid_points(double x0, double y0, double x1, double y1, double step) {
  std::vector<Vec2> pts;
  for (double x = x0; x <= x1 + 1e-12; x += step)
    for (double y = y0; y <= y1 + 1e-12; y += step) pts.emplace_back(x, y);
  return pts;
}

}  // namespace

// ------------------------------------------------------------------------- 2D α-shape

TEST(AlphaShape2D, SquareGridIsTheSquare) {
  const auto pts = grid_points(0, 0, 10, 10, 0.5);
  AlphaShape2D s(pts, 0.95);
  EXPECT_FALSE(s.degenerate());
  EXPECT_NEAR(s.area(), 100.0, 1e-9);
  const auto polys = s.polygons();
  ASSERT_EQ(polys.size(), 1u);
  EXPECT_TRUE(polys[0].holes.empty());
  EXPECT_NEAR(ring_signed_area(polys[0].outer), 100.0, 1e-9);
  auto ring = polys[0].outer;
  merge_collinear(ring, 1e-8);
  EXPECT_EQ(ring.size(), 4u);
  EXPECT_TRUE(s.contains({5, 5}));
  EXPECT_TRUE(s.contains({0, 3}));      // on the boundary
  EXPECT_TRUE(s.contains({0.25, 0.25}));  // on an inner Delaunay edge
  EXPECT_FALSE(s.contains({-0.1, 5}));
  EXPECT_TRUE(s.contains({-0.1, 5}, 0.1 + 1e-12));
}

TEST(AlphaShape2D, SignedDistanceMatchesClosedForm) {
  AlphaShape2D s(grid_points(0, 0, 10, 10, 0.5), 0.95);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-5, 15);
  for (int i = 0; i < 2000; ++i) {
    const Vec2 p(u(rng), u(rng));
    const double dx = std::max({-p.x(), p.x() - 10, 0.0}), dy = std::max({-p.y(), p.y() - 10, 0.0});
    const bool inside = p.x() > 0 && p.x() < 10 && p.y() > 0 && p.y() < 10;
    const double expect = inside ? -std::min({p.x(), 10 - p.x(), p.y(), 10 - p.y()}) : std::hypot(dx, dy);
    ASSERT_NEAR(s.signed_distance(p), expect, 1e-9) << p.transpose();
  }
}

TEST(AlphaShape2D, HoleKeptOrFilledByAlpha) {
  // Annulus of grid points: square 0..20 minus the open square 6..14.
  std::vector<Vec2> pts;
  for (const auto& p : grid_points(0, 0, 20, 20, 0.5))
    if (!(p.x() > 6 && p.x() < 14 && p.y() > 6 && p.y() < 14)) pts.push_back(p);
  AlphaShape2D small_alpha(pts, 0.95);
  auto polys = small_alpha.polygons();
  ASSERT_EQ(polys.size(), 1u);
  ASSERT_EQ(polys[0].holes.size(), 1u);
  // The hole's corners are chamfered where no empty circle of radius α fits (α-shape
  // behaviour), so the hole is the 8 × 8 square minus at most four corner triangles.
  const double hole = -ring_signed_area(polys[0].holes[0]);
  EXPECT_LE(hole, 64.0 + 1e-9);
  EXPECT_GE(hole, 64.0 - 4 * 0.95 * 0.95);
  EXPECT_NEAR(small_alpha.area(), 400.0 - hole, 1e-9);
  EXPECT_FALSE(small_alpha.contains({10, 10}));
  EXPECT_NEAR(small_alpha.signed_distance({10, 10}), 4.0, 1e-9);
  AlphaShape2D big_alpha(pts, 6.0);  // the hole's circumradius is 4√2 < 6
  EXPECT_NEAR(big_alpha.area(), 400.0, 1e-9);
  EXPECT_TRUE(big_alpha.polygons()[0].holes.empty());
}

TEST(AlphaShape2D, TooSmallAlphaIsEmptyAndHullFallbackCovers) {
  const auto pts = grid_points(0, 0, 10, 10, 2.0);
  AlphaShape2D s(pts, 0.5);  // circumradius of the grid triangles is √2 > 0.5
  EXPECT_EQ(s.kept_triangle_count(), 0u);
  EXPECT_TRUE(s.polygons().empty());
  EXPECT_FALSE(s.contains({5, 5}));
  EXPECT_TRUE(std::isinf(s.signed_distance({5, 5})));
  s.keep_all();
  EXPECT_NEAR(s.area(), 100.0, 1e-9);
  EXPECT_NEAR(s.hull_area(), 100.0, 1e-9);
}

TEST(AlphaShape2D, CoverAddsOnlyTrianglesThatHoldPoints) {
  // Two clusters joined by a long sliver: the sliver triangles exceed α.
  std::vector<Vec2> pts = grid_points(0, 0, 2, 2, 0.5);
  for (const auto& p : grid_points(8, 0, 10, 2, 0.5)) pts.push_back(p);
  AlphaShape2D s(pts, 0.95);
  EXPECT_NEAR(s.area(), 8.0, 1e-9);
  ASSERT_EQ(s.polygons().size(), 2u);
  std::size_t uncovered = 99;
  const double added = s.cover({{5.0, 1.0}, {1.0, 1.0}}, 1e-9, &uncovered);
  EXPECT_EQ(uncovered, 0u);
  EXPECT_GT(added, 0.0);
  EXPECT_TRUE(s.contains({5.0, 1.0}));
  EXPECT_LT(s.area(), 20.0);  // only the triangle(s) holding the point, not the hull
  std::size_t outside = 0;
  s.cover({{50.0, 50.0}}, 1e-9, &outside);
  EXPECT_EQ(outside, 1u);
}

TEST(AlphaShape2D, CollinearPointsAreDegenerate) {
  std::vector<Vec2> pts;
  for (int i = 0; i < 10; ++i) pts.emplace_back(i, 2 * i);
  AlphaShape2D s(pts, 5.0);
  EXPECT_TRUE(s.degenerate());
  EXPECT_EQ(s.delaunay_triangle_count(), 0u);
}

namespace {

/// contains() answers points of the inside grid's flagged cells without point location:
/// it must agree with contains_unaccelerated() (point location only, the oracle) on random
/// points (fixed seed) and on the hard cases: points exactly on the grid's cell borders and
/// corners, the triangulation points, and points on the region's boundary.
void expect_inside_grid_agrees(const AlphaShape2D& s, const std::vector<Vec2>& pts, std::uint64_t seed) {
  const auto g = s.inside_grid();
  ASSERT_GT(g.cell, 0.0);
  ASSERT_GT(g.inside_cells, 0u);  // the fast path is exercised
  std::mt19937_64 rng(seed);
  std::vector<Vec2> probes = pts;
  const Vec2 hi = g.origin + Vec2(g.nx, g.ny) * g.cell;
  std::uniform_real_distribution<double> ux(g.origin.x() - g.cell, hi.x() + g.cell),
      uy(g.origin.y() - g.cell, hi.y() + g.cell), unit(0.0, 1.0);
  for (int k = 0; k < 20000; ++k) probes.emplace_back(ux(rng), uy(rng));
  for (int i = 0; i <= g.nx; ++i)
    for (int j = 0; j <= g.ny; ++j) {
      const Vec2 corner = g.origin + Vec2(i, j) * g.cell;
      probes.push_back(corner);
      probes.push_back(corner + Vec2(unit(rng) * g.cell, 0.0));  // on a horizontal border
      probes.push_back(corner + Vec2(0.0, unit(rng) * g.cell));  // on a vertical border
    }
  for (const auto& poly : s.polygons()) {
    auto add_ring = [&](const std::vector<Vec2>& ring) {
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const Vec2 a = ring[i], b = ring[(i + 1) % ring.size()];
        probes.push_back(a);
        probes.push_back(a + 0.5 * (b - a));
        probes.push_back(a + unit(rng) * (b - a));
      }
    };
    add_ring(poly.outer);
    for (const auto& h : poly.holes) add_ring(h);
  }
  std::size_t inside = 0;
  for (const auto& p : probes)
    for (const double tol : {0.0, 1e-9 * g.cell, 0.3 * g.cell}) {
      const bool fast = s.contains(p, tol);
      ASSERT_EQ(fast, s.contains_unaccelerated(p, tol)) << p.transpose() << " tol " << tol;
      inside += fast ? 1 : 0;
    }
  EXPECT_GT(inside, 0u);
}

}  // namespace

TEST(AlphaShape2D, InsideGridAgreesWithPointLocation) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  // Annulus on a grid: the inside grid's cells fall on the sample lattice, so boundary
  // edges and samples lie exactly on cell borders.
  std::vector<Vec2> annulus;
  for (const auto& p : grid_points(0, 0, 20, 20, 0.5))
    if (!(p.x() > 6 && p.x() < 14 && p.y() > 6 && p.y() < 14)) annulus.push_back(p);
  AlphaShape2D grid_shape(annulus, 0.95);
  expect_inside_grid_agrees(grid_shape, annulus, 11);

  // Random cloud with two empty discs: a ragged boundary with holes and islands.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec2> cloud;
  while (cloud.size() < 6000) {
    const Vec2 p(u(rng), u(rng));
    if ((p - Vec2(3, 3)).norm() > 2.5 && (p - Vec2(-4, -2)).norm() > 1.5) cloud.push_back(p);
  }
  AlphaShape2D ragged(cloud, 0.3);
  expect_inside_grid_agrees(ragged, cloud, 12);
  // After refine and cover (the grid is rebuilt with the region), then the convex hull.
  const std::vector<Vec2> extra = {{3.0, 3.0}, {3.5, 2.0}, {-4.0, -2.0}, {9.99, -9.99}};
  ragged.refine(extra, 1e-9);
  ragged.cover(extra, 1e-9);
  for (const auto& p : extra) EXPECT_TRUE(ragged.contains(p, 1e-9));
  expect_inside_grid_agrees(ragged, cloud, 13);
  ragged.keep_all();
  expect_inside_grid_agrees(ragged, cloud, 14);

  // A real projection (motor.stl seen along z), as simplify_part samples it.
  const Mesh motor = read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / "occt/motor.stl");
  const double l_max = 0.015 * motor.bounds().diagonal();
  AlphaSimPrism xy;
  const auto smp = alpha_sim_plane_samples(motor, xy, l_max, std::exp2(-20.0));
  AlphaShape2D proj(smp.points, 1.9 * l_max, l_max);
  expect_inside_grid_agrees(proj, smp.checks, 15);
}

TEST(AlphaShape2D, SegmentGapsOfASquareMatchClosedForm) {
  // The square [0, 10]² (a grid at 0.5): a segment on its edge or inside has no gap, one
  // parallel outside has none within tol and is one gap beyond; one that leaves the square
  // has a gap from 10 + tol on.
  const AlphaShape2D s(grid_points(0, 0, 10, 10, 0.5), 0.95);
  const double tol = 1e-3, spacing = 0.25;
  EXPECT_TRUE(s.segment_gaps({0, 0}, {10, 0}, tol, spacing).empty());
  EXPECT_TRUE(s.segment_gaps({0.3, 0.1}, {9.7, 9.9}, tol, spacing).empty());
  EXPECT_TRUE(s.segment_gaps({-0.5 * tol, 1}, {-0.5 * tol, 9}, tol, spacing).empty());
  EXPECT_TRUE(s.segment_gaps({10, 10}, {10, 10}, tol, spacing).empty());  // a point
  const auto off = s.segment_gaps({-2 * tol, 1}, {-2 * tol, 9}, tol, spacing);
  ASSERT_GE(off.size(), 32u);  // all 8 of it, points ≤ 0.25 apart
  for (std::size_t i = 0; i < off.size(); ++i) {
    EXPECT_FALSE(s.contains(off[i], tol)) << off[i].transpose();
    if (i > 0) {
      EXPECT_LE((off[i] - off[i - 1]).norm(), spacing + 1e-12);
    }
  }
  EXPECT_LE(off.front().y(), 1 + spacing);
  EXPECT_GE(off.back().y(), 9 - spacing);
  const auto out = s.segment_gaps({5, 5}, {11, 5}, tol, spacing);
  ASSERT_FALSE(out.empty());
  for (const auto& q : out) {
    EXPECT_GT(q.x(), 10 + tol);
    EXPECT_DOUBLE_EQ(q.y(), 5.0);
  }
  EXPECT_LE(out.front().x(), 10 + tol + spacing);
  EXPECT_GE(out.back().x(), 11 - spacing);
  EXPECT_THROW(s.segment_gaps({0, 0}, {1, 0}, tol, 0.0), std::invalid_argument);
}

namespace {
/// 3000 random points in [-10, 10]² outside two discs (radius 2 and 1.2, random centres):
/// with α = 0.45 their α-shape has notches, holes and islands.
std::vector<Vec2> ragged_cloud(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec2> cloud;
  const Vec2 c1(u(rng) * 0.5, u(rng) * 0.5), c2(u(rng) * 0.5, u(rng) * 0.5);
  while (cloud.size() < 3000) {
    const Vec2 p(u(rng), u(rng));
    if ((p - c1).norm() > 2.0 && (p - c2).norm() > 1.2) cloud.push_back(p);
  }
  return cloud;
}

/// Calls f(trial, cloud, shape, tol, rng) for six ragged_cloud shapes (α = 0.45) of the
/// seed, with tol 0 and 1e-2 in turn.
template <class F>
void for_ragged_shapes(std::uint64_t seed, F&& f) {
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 6; ++trial) {
    const std::vector<Vec2> cloud = ragged_cloud(rng);
    const AlphaShape2D shape(cloud, 0.45);
    f(trial, cloud, shape, trial % 2 ? 1e-2 : 0.0, rng);
  }
}
}  // namespace

TEST(AlphaShape2D, SegmentGapsAgreeWithDenseSamplingOnRaggedShapes) {
  // Oracle: points every tol/4 along the segment, each tested by point location. A
  // segment found gap-free has every such point within tol (plus the spacing) of the
  // region; a gap point lies farther than tol; a segment with a point farther than
  // tol + spacing has a gap. Random clouds with empty discs give notches, holes and
  // islands; segments at random, and along the region's own boundary edges.
  for_ragged_shapes(24, [](int trial, const std::vector<Vec2>& cloud, const AlphaShape2D& shape, double tol,
                           std::mt19937_64& rng) {
    (void)cloud;
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    std::vector<std::array<Vec2, 2>> segs;
    for (int i = 0; i < 150; ++i) segs.push_back({Vec2(u(rng), u(rng)), Vec2(u(rng), u(rng))});
    for (const auto& poly : shape.polygons())
      for (std::size_t i = 0; i + 1 < poly.outer.size() && i < 60; ++i) segs.push_back({poly.outer[i], poly.outer[i + 1]});
    int with_gaps = 0;
    for (const auto& sg : segs) {
      const auto gaps = shape.segment_gaps(sg[0], sg[1], tol, 0.1);
      for (const auto& q : gaps) {
        ASSERT_FALSE(shape.contains(q, tol * (1 - 1e-9))) << "trial " << trial << " gap point " << q.transpose();
      }
      const double len = (sg[1] - sg[0]).norm();
      const double step = std::max(tol, 1e-3) / 4;
      const int n = static_cast<int>(std::ceil(len / step));
      bool far = false;
      for (int k = 0; k <= n && !far; ++k) {
        const Vec2 q = sg[0] + (sg[1] - sg[0]) * (static_cast<double>(k) / n);
        far = !shape.contains(q, tol + step);
      }
      if (far) {
        ASSERT_FALSE(gaps.empty()) << "trial " << trial << " segment " << sg[0].transpose() << " -> "
                                   << sg[1].transpose();
      }
      with_gaps += gaps.empty() ? 0 : 1;
    }
    EXPECT_GT(with_gaps, 0);
    EXPECT_LT(with_gaps, static_cast<int>(segs.size()));
  });
}

namespace {
/// Points of triangle abc on a barycentric lattice of n steps per side (its corners and
/// edges included).
std::vector<Vec2> triangle_lattice(const Vec2& a, const Vec2& b, const Vec2& c, int n) {
  std::vector<Vec2> pts;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j)
      pts.push_back(a + (b - a) * (static_cast<double>(i) / n) + (c - a) * (static_cast<double>(j) / n));
  return pts;
}
}  // namespace

TEST(AlphaShape2D, TriangleGapsOfAnAnnulusMatchClosedForm) {
  // The annulus of HoleKeptOrFilledByAlpha: the square [0, 20]² less a hole of about
  // [6, 14]². A triangle in the ring has no gap; one across the hole has gaps, all in the
  // hole, farther than tol from the ring; one that enters the hole by less than tol has
  // none, by more it has.
  std::vector<Vec2> pts;
  for (const auto& p : grid_points(0, 0, 20, 20, 0.5))
    if (!(p.x() > 6 && p.x() < 14 && p.y() > 6 && p.y() < 14)) pts.push_back(p);
  const AlphaShape2D s(pts, 0.95);
  const double tol = 1e-3, spacing = 0.25;
  EXPECT_TRUE(s.triangle_gaps({0, 0}, {20, 0}, {0, 6}, tol, spacing).empty());
  EXPECT_TRUE(s.triangle_gaps({0, 0}, {20, 0}, {20, 6}, tol, spacing).empty());
  EXPECT_TRUE(s.triangle_gaps({1, 1}, {1, 19}, {6 + 0.5 * tol, 10}, tol, spacing).empty());
  EXPECT_FALSE(s.triangle_gaps({1, 1}, {1, 19}, {6 + 4 * tol, 10}, tol, spacing).empty());
  const auto across = s.triangle_gaps({0, 0}, {20, 20}, {0, 20}, tol, spacing);
  ASSERT_FALSE(across.empty());
  for (const Vec2& q : across) {
    EXPECT_FALSE(s.contains(q, tol)) << q.transpose();
    EXPECT_GE(q.y(), q.x() - 1e-9) << q.transpose();  // inside the triangle
  }
  // The batch gives the same points, sorted and unique.
  auto sorted = across;
  std::sort(sorted.begin(), sorted.end(), [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  const std::vector<std::array<Vec2, 3>> batch = {{Vec2(0, 0), Vec2(20, 20), Vec2(0, 20)}, {Vec2(0, 0), Vec2(20, 0), Vec2(0, 6)}};
  EXPECT_TRUE(s.triangles_gaps(batch, tol, spacing) == sorted);
  // A triangle without area is its longest edge.
  EXPECT_TRUE(s.triangle_gaps({1, 1}, {19, 1}, {10, 1}, tol, spacing).empty());
  EXPECT_FALSE(s.triangle_gaps({1, 10}, {19, 10}, {10, 10}, tol, spacing).empty());
  EXPECT_THROW(s.triangle_gaps({0, 0}, {1, 0}, {0, 1}, tol, 0.0), std::invalid_argument);
}

TEST(AlphaShape2D, TrianglesAwayFromARepairKeepTheirGapFreedom) {
  // exact_projection tests again, after a repair, only the triangles whose box (widened
  // by tol) meets a Delaunay triangle that the repair added, removed or flipped between
  // two snapshots. That relies on this: a triangle away from every change that had no
  // gaps still has none. Ragged shapes, refined with random points, covered at random
  // points, or both; random triangles of several sizes.
  std::mt19937_64 rng(26);
  std::uniform_real_distribution<double> u(-10.0, 10.0), size(0.05, 2.0);
  int away = 0, near = 0;
  for (int trial = 0; trial < 9; ++trial) {
    AlphaShape2D shape(ragged_cloud(rng), 0.45);
    const double tol = trial % 2 ? 1e-2 : 0.0;
    std::vector<std::array<Vec2, 3>> tris;
    for (int i = 0; i < 400; ++i) {
      const Vec2 c(u(rng), u(rng));
      const double s = size(rng);
      tris.push_back({c, c + s * Vec2(1.0, 0.1), c + s * Vec2(0.3, 0.9)});
    }
    std::vector<char> clear(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i)
      clear[i] = shape.triangle_gaps(tris[i][0], tris[i][1], tris[i][2], tol, 0.1).empty();
    const auto before = shape.snapshot();
    std::vector<Vec2> points;
    for (int i = 0; i < 12; ++i) points.emplace_back(u(rng), u(rng));
    if (trial % 3 != 1) shape.refine(points, tol);
    if (trial % 3 != 0) shape.cover(points, 0.0);
    const auto after = shape.snapshot();
    // The triangles in one snapshot only, by value.
    using Key = std::array<double, 7>;
    auto keys = [](const std::vector<std::pair<std::array<Vec2, 3>, char>>& snap) {
      std::set<Key> out;
      for (const auto& [c, kept] : snap) out.insert({c[0].x(), c[0].y(), c[1].x(), c[1].y(), c[2].x(), c[2].y(), double(kept)});
      return out;
    };
    const std::set<Key> a = keys(before), b = keys(after);
    std::vector<Key> changed;
    std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(changed));
    ASSERT_FALSE(changed.empty()) << "trial " << trial;
    for (std::size_t i = 0; i < tris.size(); ++i) {
      const auto& t = tris[i];
      const Vec2 lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]) - Vec2::Constant(tol), hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]) + Vec2::Constant(tol);
      const bool touched = std::any_of(changed.begin(), changed.end(), [&](const Key& k) {
        const double x0 = std::min({k[0], k[2], k[4]}), x1 = std::max({k[0], k[2], k[4]});
        const double y0 = std::min({k[1], k[3], k[5]}), y1 = std::max({k[1], k[3], k[5]});
        return x0 <= hi.x() && x1 >= lo.x() && y0 <= hi.y() && y1 >= lo.y();
      });
      if (touched || !clear[i]) {
        near += touched;
        continue;
      }
      ++away;
      EXPECT_TRUE(shape.triangle_gaps(t[0], t[1], t[2], tol, 0.1).empty())
          << std::setprecision(17) << "trial " << trial << " triangle " << t[0].transpose() << " / " << t[1].transpose()
          << " / " << t[2].transpose();
    }
  }
  EXPECT_GT(away, 500);  // the property was exercised, and the changes were local
  EXPECT_GT(near, 50);
}

TEST(AlphaShape2D, TriangleGapsAgreeWithDenseSamplingOnRaggedShapes) {
  // Oracle: a barycentric lattice on the triangle, 1/64 of its longest edge apart, each
  // point tested by point location. The claims: a triangle found gap-free has every lattice point within tol of the
  // region (exact: the lattice points lie in the triangle); a triangle with a lattice
  // point farther than tol + its lattice step from the region has gaps; every gap point
  // lies in the triangle and off the region by more than tol·cos(π/8) (the octagons
  // inscribed in the vertices' tol-discs). Random clouds with empty discs give notches,
  // holes and islands; the triangles' corners are cloud points (inside the hull), some
  // large, some small.
  for_ragged_shapes(25, [](int trial, const std::vector<Vec2>& cloud, const AlphaShape2D& shape, double tol,
                           std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    std::uniform_int_distribution<std::size_t> pick(0, cloud.size() - 1);
    std::vector<std::array<Vec2, 3>> tris;
    for (int i = 0; i < 200; ++i) {
      const Vec2 a = cloud[pick(rng)];
      if (i % 2 == 0) {
        tris.push_back({a, cloud[pick(rng)], cloud[pick(rng)]});
        continue;
      }
      // A small triangle: corners are the cloud points nearest to a + random offsets.
      std::array<Vec2, 3> t{a, a, a};
      for (int k = 1; k < 3; ++k) {
        const Vec2 target = a + Vec2(u(rng), u(rng)) * 0.15;
        double best = std::numeric_limits<double>::infinity();
        for (const Vec2& q : cloud)
          if ((q - target).squaredNorm() < best) {
            best = (q - target).squaredNorm();
            t[k] = q;
          }
      }
      tris.push_back(t);
    }
    int with_gaps = 0;
    for (const auto& t : tris) {
      const auto gaps = shape.triangle_gaps(t[0], t[1], t[2], tol, 0.1);
      const double longest = std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
      const double area2 = std::abs((t[1] - t[0]).x() * (t[2] - t[0]).y() - (t[1] - t[0]).y() * (t[2] - t[0]).x());
      for (const auto& q : gaps) {
        ASSERT_FALSE(shape.contains(q, tol * std::cos(M_PI / 8) * (1 - 1e-9)))
            << "trial " << trial << " gap point " << q.transpose();
        if (area2 > 1e-9 * longest * longest) {
          // Inside the triangle (barycentric coordinates ≥ 0 up to rounding).
          for (int e = 0; e < 3; ++e) {
            const Vec2 p = t[e], pq = t[(e + 1) % 3] - p, r = t[(e + 2) % 3] - p, pv = q - p;
            const double side = (pq.x() * pv.y() - pq.y() * pv.x()) * (pq.x() * r.y() - pq.y() * r.x());
            ASSERT_GE(side, -1e-9 * longest * longest * longest * longest) << "trial " << trial;
          }
        }
      }
      const int n = 64;
      const double step = longest / n;
      bool far = false, all_within = true;
      for (const Vec2& q : triangle_lattice(t[0], t[1], t[2], n)) {
        far = far || !shape.contains(q, tol + step);
        all_within = all_within && shape.contains(q, tol * (1 + 1e-9) + 1e-12 * longest);
      }
      if (far) {
        ASSERT_FALSE(gaps.empty()) << "trial " << trial << " triangle " << t[0].transpose() << ", "
                                   << t[1].transpose() << ", " << t[2].transpose();
      }
      if (gaps.empty()) {
        ASSERT_TRUE(all_within) << "trial " << trial << " triangle " << t[0].transpose() << ", "
                                << t[1].transpose() << ", " << t[2].transpose();
      }
      with_gaps += gaps.empty() ? 0 : 1;
    }
    EXPECT_GT(with_gaps, 0);
    EXPECT_LT(with_gaps, static_cast<int>(tris.size()));
  });
}

TEST(AlphaShape2D, FillPinchesJoinsPiecesThatTouchAtAVertex) {
  // Two small triangles meeting at the origin, opposite each other (a bow tie), and α
  // between their circumradius (0.57) and that of every other Delaunay triangle (flat
  // ones across): the α-shape is two pieces touching at a vertex (an extrusion of it
  // touches along an edge). fill_pinches keeps the faces of one side of the origin: one
  // piece, grown only; a region without pinches is left alone.
  const std::vector<Vec2> pts = {{0, 0}, {1, 0}, {0.5, 0.3}, {-1, 0}, {-0.5, -0.3}};
  AlphaShape2D s(pts, 0.6);
  ASSERT_EQ(s.polygons().size(), 2u);
  const double before = s.area();
  EXPECT_NEAR(before, 2 * 0.15, 1e-12);
  const double added = s.fill_pinches();
  EXPECT_GT(added, 0.0);
  EXPECT_NEAR(s.area(), before + added, 1e-12);
  const auto polys = s.polygons();
  ASSERT_EQ(polys.size(), 1u);
  EXPECT_TRUE(polys[0].holes.empty());
  for (const auto& p : pts) EXPECT_TRUE(s.contains(p));
  EXPECT_EQ(s.fill_pinches(), 0.0);
  AlphaShape2D square(grid_points(0, 0, 4, 4, 0.5), 0.4);
  EXPECT_EQ(square.fill_pinches(), 0.0);
  EXPECT_NEAR(square.area(), 16.0, 1e-9);
}

TEST(AlphaShape2D, MergeCollinearKeepsCorners) {
  std::vector<Vec2> ring = {{0, 0}, {1, 0}, {2, 0}, {2, 0}, {2, 1}, {2, 2}, {0, 2}, {0, 1}};
  EXPECT_EQ(merge_collinear(ring, 1e-8), 4u);
  EXPECT_EQ(ring.size(), 4u);
  EXPECT_NEAR(ring_signed_area(ring), 4.0, 1e-12);
  std::vector<Vec2> notch = {{0, 0}, {1, 0}, {1, 0.001}, {1.001, 0}, {2, 0}, {2, 2}, {0, 2}};
  const double a0 = ring_signed_area(notch);
  merge_collinear(notch, 1e-8);
  EXPECT_EQ(notch.size(), 7u);  // a real (tiny) notch is not collinear
  EXPECT_DOUBLE_EQ(ring_signed_area(notch), a0);
}

namespace {

/// merge_collinear's contract checked vertex by vertex (the oracle for its hull shortcut):
/// from the lowest vertex, greedily extend each chord while every skipped vertex lies
/// strictly between its ends and within max(dist_tol, sin(angle)·chord) of it, runs of at
/// most 256 vertices.
std::vector<Vec2> merge_collinear_reference(std::vector<Vec2> ring, double angle_tol_rad, double dist_tol) {
  std::vector<Vec2> r;
  for (const auto& p : ring)
    if (r.empty() || p != r.back()) r.push_back(p);
  while (r.size() > 1 && r.front() == r.back()) r.pop_back();
  if (r.size() < 3) return r;
  std::size_t s0 = 0;
  for (std::size_t i = 1; i < r.size(); ++i)
    if (r[i].x() < r[s0].x() || (r[i].x() == r[s0].x() && r[i].y() < r[s0].y())) s0 = i;
  std::rotate(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(s0), r.end());
  r.push_back(r.front());
  const double sin_tol = std::sin(angle_tol_rad);
  auto fits = [&](std::size_t a, std::size_t j) {
    const Vec2 d = r[j] - r[a];
    const double len = d.norm();
    if (len == 0.0) return false;
    const double lim = std::max(dist_tol, sin_tol * len);
    for (std::size_t k = a + 1; k < j; ++k) {
      const Vec2 w = r[k] - r[a];
      const double along = w.dot(d) / len;
      if (along <= 0.0 || along >= len || std::abs(d.x() * w.y() - d.y() * w.x()) / len > lim) return false;
    }
    return true;
  };
  std::vector<Vec2> out{r[0]};
  for (std::size_t a = 0; a + 1 < r.size();) {
    std::size_t j = a + 1;
    while (j + 1 < r.size() && j + 1 - a <= 256 && fits(a, j + 1)) ++j;
    if (j + 1 < r.size()) out.push_back(r[j]);
    a = j;
  }
  return out;
}

}  // namespace

// Random rings (fixed seeds): squares with sides cut into up to 600 points, jittered by 0
// to 1% of the side (straight runs, hulls of two corners, runs past the 256 cap); circles
// of 8 to 4,000 vertices (gentle arcs, hulls past the corner cap); zigzags; repeated and
// all-equal points. The result must equal the vertex-by-vertex check's exactly.
TEST(AlphaShape2D, MergeCollinearMatchesTheVertexByVertexCheck) {
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto check = [](const std::vector<Vec2>& ring, double angle, double dist, const std::string& what) {
    std::vector<Vec2> got = ring;
    const std::size_t removed = merge_collinear(got, angle, dist);
    const std::vector<Vec2> want = merge_collinear_reference(ring, angle, dist);
    EXPECT_EQ(removed, ring.size() - want.size()) << what;
    ASSERT_EQ(got.size(), want.size()) << what;
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], want[i]) << what << " vertex " << i;
  };
  for (int trial = 0; trial < 40; ++trial) {
    const int per_side = 1 + static_cast<int>(rng() % 600);
    const double jitter = std::array<double, 4>{0.0, 1e-9, 1e-4, 1e-2}[trial % 4];
    std::vector<Vec2> ring;
    const Vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int side = 0; side < 4; ++side)
      for (int k = 0; k < per_side; ++k) {
        const double t = static_cast<double>(k) / per_side;
        ring.push_back(corners[side] + t * (corners[(side + 1) % 4] - corners[side]) + jitter * Vec2(unit(rng), unit(rng)));
      }
    for (double angle : {1e-8, 1e-3, 0.05})
      for (double dist : {0.0, 1e-5, 3e-3}) check(ring, angle, dist, "square " + std::to_string(trial));
  }
  for (int n : {8, 100, 1000, 4000}) {
    std::vector<Vec2> circle;
    for (int k = 0; k < n; ++k) circle.emplace_back(std::cos(2 * M_PI * k / n), std::sin(2 * M_PI * k / n));
    for (double angle : {1e-3, 0.05, 0.3})
      for (double dist : {0.0, 1e-6, 1e-3}) check(circle, angle, dist, "circle " + std::to_string(n));
  }
  std::vector<Vec2> zigzag;
  for (int k = 0; k < 500; ++k) zigzag.emplace_back(k * 0.01, (k % 2) * 1e-4);
  zigzag.emplace_back(5.0, 1.0);
  for (double dist : {0.0, 5e-5, 2e-4}) check(zigzag, 1e-3, dist, "zigzag");
  check(std::vector<Vec2>(7, Vec2(0.5, 0.5)), 1e-3, 0.0, "all equal");
  check({{0, 0}, {0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 0}}, 1e-3, 0.0, "repeats");
}

namespace {

double point_segment_distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

/// Even-odd point-in-region test over all rings, or within eps of a ring (independent
/// of the library's triangle-based region).
bool in_rings(const Vec2& p, const std::vector<std::vector<Vec2>>& rings, double eps) {
  bool in = false;
  for (const auto& r : rings)
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
      if (point_segment_distance(p, r[j], r[i]) <= eps) return true;
      if ((r[i].y() > p.y()) != (r[j].y() > p.y()) &&
          p.x() < (r[j].x() - r[i].x()) * (p.y() - r[i].y()) / (r[j].y() - r[i].y()) + r[i].x())
        in = !in;
    }
  return in;
}

double distance_to_rings(const Vec2& p, const std::vector<std::vector<Vec2>>& rings) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& r : rings)
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) d = std::min(d, point_segment_distance(p, r[j], r[i]));
  return d;
}

/// True if two segments properly cross or touch away from a shared endpoint.
bool segments_touch(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  auto orient = [](const Vec2& p, const Vec2& q, const Vec2& r) {
    const double o = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    return (o > 0) - (o < 0);
  };
  if (a == c || a == d || b == c || b == d) return false;
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  return o1 != o2 && o3 != o4;
}

std::vector<std::vector<Vec2>> rings_of(const std::vector<PolygonWithHoles2>& polys) {
  std::vector<std::vector<Vec2>> rings;
  for (const auto& p : polys) {
    rings.push_back(p.outer);
    for (const auto& h : p.holes) rings.push_back(h);
  }
  return rings;
}

/// Empty if `after` (rings of grow_simplify's output) only grew `before`'s region, by less
/// than max_dev, with each ring's orientation kept and all rings simple and disjoint;
/// otherwise what is wrong. The region test uses `samples` points in the square of
/// half-width `half_width` (seed `seed`).
std::string grown_region_violation(const std::vector<std::vector<Vec2>>& before,
                                   const std::vector<std::vector<Vec2>>& after, double max_dev, double half_width,
                                   std::uint64_t seed, int samples) {
  std::ostringstream os;
  os.precision(17);
  if (after.size() != before.size()) return "ring count changed";
  for (std::size_t r = 0; r < after.size(); ++r) {
    if (after[r].size() < 3) return "ring " + std::to_string(r) + " has fewer than 3 vertices";
    if (!(ring_signed_area(after[r]) * ring_signed_area(before[r]) > 0.0))
      return "ring " + std::to_string(r) + " changed orientation";
    for (const auto& v : after[r])
      if (!(distance_to_rings(v, before) < max_dev)) {
        os << "vertex (" << v.transpose() << ") of ring " << r << " is max_dev or more from the old boundary";
        return os.str();
      }
  }
  // The region only grows (samples of the old region are in the new one), by < max_dev.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-half_width, half_width);
  for (int i = 0; i < samples; ++i) {
    const Vec2 p(u(rng), u(rng));
    const bool was_in = in_rings(p, before, 0.0);
    if (was_in && !in_rings(p, after, 1e-9)) os << "(" << p.transpose() << ") was inside and is not";
    if (!was_in && in_rings(p, after, 0.0) && !(distance_to_rings(p, before) < max_dev))
      os << "(" << p.transpose() << ") was added max_dev or more from the old boundary";
    if (!os.str().empty()) return os.str();
  }
  // Rings stay simple and disjoint.
  for (std::size_t r1 = 0; r1 < after.size(); ++r1)
    for (std::size_t r2 = r1; r2 < after.size(); ++r2)
      for (std::size_t i = 0; i < after[r1].size(); ++i)
        for (std::size_t j = 0; j < after[r2].size(); ++j) {
          const auto& A = after[r1];
          const auto& B = after[r2];
          const std::size_t i1 = (i + 1) % A.size(), j1 = (j + 1) % B.size();
          // Consecutive edges of one ring share a vertex.
          if (r1 == r2 && (i == j || i1 == j || j1 == i)) continue;
          if (segments_touch(A[i], A[i1], B[j], B[j1]))
            return "edges " + std::to_string(r1) + ":" + std::to_string(i) + " and " + std::to_string(r2) + ":" +
                   std::to_string(j) + " meet";
        }
  return "";
}

/// gtest form of grown_region_violation (20,000 samples).
void expect_grown_within(const std::vector<std::vector<Vec2>>& before, const std::vector<std::vector<Vec2>>& after,
                         double max_dev, double half_width, std::uint64_t seed) {
  EXPECT_EQ(grown_region_violation(before, after, max_dev, half_width, seed, 20000), "");
}

/// A gear-like outer ring (notches of random depth, seed 17) around a finely faceted
/// round hole, next to a square piece whose near side is `gap` from the teeth.
std::vector<PolygonWithHoles2> gear_hole_square(double gap) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> depth(0.0, 1.5);
  PolygonWithHoles2 gear;
  const int teeth = 40;
  for (int k = 0; k < 4 * teeth; ++k) {
    const double a = 2 * M_PI * k / (4 * teeth);
    const double r = (k % 4 < 2) ? 20.0 : 20.0 - depth(rng);
    gear.outer.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  std::vector<Vec2> hole;
  for (int k = 0; k < 200; ++k) {
    const double a = -2 * M_PI * k / 200;  // clockwise
    hole.emplace_back(3.0 + 8.0 * std::cos(a), 8.0 * std::sin(a));
  }
  gear.holes.push_back(hole);
  PolygonWithHoles2 square;
  const double x0 = 20.0 + gap;
  square.outer = {{x0, -2}, {x0 + 3.8, -2}, {x0 + 3.8, 2}, {x0, 2}};
  return {gear, square};
}

std::vector<Vec2> disc_ring(double radius, int n) {
  std::vector<Vec2> ring;
  for (int k = 0; k < n; ++k) ring.emplace_back(radius * std::cos(2 * M_PI * k / n), radius * std::sin(2 * M_PI * k / n));
  return ring;
}

}  // namespace

TEST(AlphaShape2D, GrowSimplifyOnlyGrowsTheRegion) {
  // Notch moves only: the notches and the hole's rim may go, convex corners stay.
  std::vector<PolygonWithHoles2> polys = gear_hole_square(1.2);
  const auto before = rings_of(polys);
  const double max_dev = 0.5;
  const std::size_t removed = grow_simplify(polys, max_dev, /*merge_corners=*/false);
  const auto after = rings_of(polys);
  EXPECT_GT(removed, 150u);
  ASSERT_EQ(after.size(), before.size());
  EXPECT_EQ(after[2].size(), 4u);  // the square is convex: unchanged
  EXPECT_LT(after[1].size(), 60u);  // the hole's rim: chords of sagitta < 0.5 on r = 8
  std::size_t total = 0;
  for (std::size_t r = 0; r < after.size(); ++r) {
    total += after[r].size();
    // Every vertex left is an original vertex.
    for (const auto& v : after[r]) EXPECT_NE(std::find(before[r].begin(), before[r].end(), v), before[r].end());
  }
  EXPECT_EQ(total + removed, 4u * 40 + 200u + 4u);
  expect_grown_within(before, after, max_dev, 26.0, 17);
  // Notch moves here also keep every old vertex within max_dev of the new boundary. Not a
  // contract of grow_simplify in general: a notch's deviation is its depth below the
  // chord's line, so an old vertex beyond a chord's end can lie farther from the chord
  // (the random star rings of the property test find such cases); the growth is bounded.
  for (const auto& r : before)
    for (const auto& v : r) EXPECT_LT(distance_to_rings(v, after), max_dev) << v.transpose();
  // A convex ring cannot grow by removing vertices: unchanged.
  std::vector<PolygonWithHoles2> disc(1);
  disc[0].outer = disc_ring(5.0, 48);
  EXPECT_EQ(grow_simplify(disc, 1.0, false), 0u);
}

TEST(AlphaShape2D, GrowSimplifyMergesConvexCornersOutward) {
  // A faceted disc: pairs of convex corners become one vertex on the lines of their
  // neighbouring edges, the circumscribed polygon whose growth stays below max_dev.
  std::vector<PolygonWithHoles2> disc(1);
  disc[0].outer = disc_ring(5.0, 48);
  const auto disc_before = rings_of(disc);
  const std::size_t removed = grow_simplify(disc, 1.0, true);
  EXPECT_GT(removed, 30u);  // a hexagon around r = 5 stands off 0.77; 48 -> < 18 vertices
  expect_grown_within(disc_before, rings_of(disc), 1.0, 7.0, 5);
  // A square's corners cannot merge (their edge lines are parallel).
  std::vector<PolygonWithHoles2> square(1);
  square[0].outer = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  EXPECT_EQ(grow_simplify(square, 1.0, true), 0u);
  // The gear, its hole and the square piece, the square 0.3 from the teeth (less than
  // max_dev): corners grow towards it, but no new edge may meet it.
  for (const double gap : {1.2, 0.3, 0.05}) {
    std::vector<PolygonWithHoles2> polys = gear_hole_square(gap);
    const auto before = rings_of(polys);
    const std::size_t n = grow_simplify(polys, 0.5, true);
    const auto after = rings_of(polys);
    std::size_t total = 0;
    for (const auto& r : after) total += r.size();
    EXPECT_EQ(total + n, 4u * 40 + 200u + 4u) << gap;
    SCOPED_TRACE(gap);
    expect_grown_within(before, after, 0.5, 26.0, 17);
  }
  // A hexagon whose corners (4.8, ±0.5) would merge into (5.067, 0) (growth 0.267; every
  // other merge grows ≥ 0.7), beside a bar whose long side (x = 4.95) crosses both new
  // sides with its vertices outside the added triangle, or a small triangle lying wholly
  // inside it: neither may be reached, so nothing merges.
  for (const bool bar : {true, false}) {
    std::vector<PolygonWithHoles2> polys(2);
    polys[0].outer = {{-3, -2}, {4, -2}, {4.8, -0.5}, {4.8, 0.5}, {4, 2}, {-3, 2}};
    if (bar)
      polys[1].outer = {{4.95, -4}, {5.95, -4}, {5.95, 4}, {4.95, 4}};
    else
      polys[1].outer = {{4.9, 0.0}, {4.95, -0.03}, {4.95, 0.03}};
    const auto before = rings_of(polys);
    SCOPED_TRACE(bar ? "bar" : "small triangle");
    EXPECT_EQ(grow_simplify(polys, 0.5, true), 0u);
    expect_grown_within(before, rings_of(polys), 0.5, 7.0, 3);
    polys.pop_back();  // alone, the hexagon's corners merge
    EXPECT_EQ(grow_simplify(polys, 0.5, true), 1u);
    EXPECT_EQ(polys[0].outer.size(), 5u);
  }
  // Notch-only removes fewer vertices from the gear than both moves.
  std::vector<PolygonWithHoles2> notch = gear_hole_square(1.2), both = gear_hole_square(1.2);
  EXPECT_LT(grow_simplify(notch, 0.5, false), grow_simplify(both, 0.5, true));
}

TEST(AlphaShape2D, RefineClosesANotchThatCoverWouldBridge) {
  // A silhouette x = 0 sampled at y = 0, 4, a sample 0.064 inside it at y = 2 (the
  // midpoint of a facet diagonal), material to the left, free space to the right. The
  // chord through the inner sample cuts a sliver of the projection off the α-shape.
  std::vector<Vec2> pts = grid_points(-16, -8, -4, 12, 4.0);
  for (double y = -8; y <= 12; y += 4) pts.emplace_back(0.0, y);
  pts.emplace_back(-0.064, 2.0);
  pts.emplace_back(-0.064, 6.0);
  for (double y = -8; y <= 12; y += 4) pts.emplace_back(30.0, y);  // far material on the right
  const Vec2 sliver(-0.004, 2.47);  // inside the true projection (x ≤ 0)
  AlphaShape2D plain(pts, 3.8, 3.8);
  ASSERT_FALSE(plain.contains(sliver, 1e-9));
  const double area0 = plain.area();
  AlphaShape2D refined(pts, 3.8, 3.8);
  EXPECT_EQ(refined.refine({{0.0, 2.0}, {0.0, 6.0}, {-2.0, 2.0}}, 1e-9), 2u);  // (-2, 2) is covered already
  EXPECT_TRUE(refined.contains(sliver, 1e-9));
  EXPECT_TRUE(refined.contains({0.0, 2.0}, 1e-9));
  EXPECT_FALSE(refined.contains({1.0, 2.0}, 1e-9));  // no bridge to the far material
  EXPECT_LT(refined.area() - area0, 1.0);
  // cover() alone bridges the gap with a big triangle (what refine avoids).
  AlphaShape2D covered(pts, 3.8, 3.8);
  covered.cover({{0.0, 2.0}}, 1e-9);
  EXPECT_GT(covered.area() - area0, 10.0);
}

// --------------------------------------------------------------- closed-form parts

TEST(AlphaSim, PlateSmallHolesVanishBigHolesStay) {
  // 40 × 40 × 2 plate (cells of 1), two 1 × 1 holes (< dim_pre) and one 8 × 8 hole.
  auto hole = [](int i, int j) {
    if (i == 5 && j == 5) return true;
    if (i == 30 && j == 8) return true;
    return i >= 20 && i < 28 && j >= 20 && j < 28;
  };
  Part plate = make_part("plate", extruded_grid(40, 40, 1.0, 2.0, [&](int i, int j) { return !hole(i, j); }));
  ASSERT_TRUE(plate.closed);
  const auto sp = simplify_part(plate, options(2.0));
  const auto& r = sp.result;
  EXPECT_EQ(r.fallback, AlphaSimFallback::None) << r.reason;
  EXPECT_EQ(r.status, AlphaSimStatus::Ok) << r.reason;
  EXPECT_NEAR(r.volume_before, (1600.0 - 2.0 - 64.0) * 2.0, 1e-9);
  // Small holes filled, big one kept; the α-shape may chamfer each of its four corners
  // by a right triangle of circumradius < α (area < α²).
  const double alpha = 0.95 * 2.0;
  EXPECT_GE(r.volume_after, (1600.0 - 64.0) * 2.0 - 1e-6);
  EXPECT_LE(r.volume_after, (1600.0 - 64.0 + 4 * alpha * alpha) * 2.0);
  EXPECT_DOUBLE_EQ(r.containment, 1.0);
  EXPECT_DOUBLE_EQ(r.containment_implicit, 1.0);
  EXPECT_LT(r.triangles_after, r.triangles_before / 10);
  EXPECT_TRUE(r.closed_after);
  EXPECT_LE(r.hausdorff, alpha);  // filled holes and chamfers stand off by less than α
  EXPECT_GT(r.hausdorff, 0.2);      // the filled 1×1 holes: up to 0.5 from their rim
  ASSERT_TRUE(sp.solid);
  EXPECT_TRUE(sp.solid->contains({5.5, 5.5, 1.0}));     // small hole filled
  EXPECT_FALSE(sp.solid->contains({24.0, 24.0, 1.0}));  // big hole kept
  EXPECT_NEAR(sp.solid->distance_bound({24.0, 24.0, 1.0}), 4.0, 1e-9);
  EXPECT_NEAR(sp.solid->distance_bound({10.0, 10.0, 5.0}), 3.0, 1e-9);
  EXPECT_NEAR(sp.solid->distance_bound({10.0, 10.0, 1.5}), -0.5, 1e-9);
  // Independent oracle on the output mesh.
  const auto samples = dense_surface_samples(plate.mesh, 1.0, 0.5, 20000, 3);
  EXPECT_DOUBLE_EQ(oracle_containment(sp.mesh, samples, r.tolerance), 1.0);
  // XY projection: one polygon with one hole; XZ/YZ rectangles.
  ASSERT_EQ(r.projections.size(), 3u);
  EXPECT_EQ(r.projections[0].holes, 1u);
  // Rectangles: collinear runs are merged in chunks of at most 256 vertices.
  EXPECT_LE(r.projections[1].polygon_vertices, 4u + 2 * (40 * 5 + 2 * 10) / 256 + 4);
  EXPECT_EQ(r.projections[1].holes, 0u);
  EXPECT_EQ(r.projections[2].holes, 0u);
}

TEST(AlphaSim, LBracketIsReproducedExactly) {
  // L-shaped profile (legs 3 wide, 12 long) extruded 2, dim_pre 1.
  Part l = make_part("L", extruded_grid(12, 12, 1.0, 2.0, [](int i, int j) { return i < 3 || j < 3; }));
  const auto sp = simplify_part(l, options(1.0));
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::None) << sp.result.reason;
  // Exact except for the inner corner, which the α-shape may chamfer by a right
  // triangle of circumradius < α = 0.95 (area < α²).
  EXPECT_NEAR(sp.result.volume_before, (36.0 + 36.0 - 9.0) * 2.0, 1e-9);
  EXPECT_GE(sp.result.volume_after, sp.result.volume_before - 1e-6);
  EXPECT_LE(sp.result.volume_after, sp.result.volume_before + 0.95 * 0.95 * 2.0);
  EXPECT_LT(sp.result.hausdorff, 0.95);
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_FALSE(sp.solid->contains({4, 4, 1}));  // the inner corner stays empty
  EXPECT_TRUE(sp.solid->contains({2.9, 11.9, 1.9}));
  EXPECT_EQ(sp.result.projections[0].holes, 0u);
  EXPECT_LE(sp.result.projections[0].polygon_vertices, 8u + 4);
}

TEST(AlphaSim, CylinderVolumeIsKept) {
  // Convex arcs kept as they are: the 48-gon is reproduced exactly.
  Part c = make_part("cyl", cylinder_mesh(5.0, 20.0, 48));
  AlphaSimOptions exact = options(1.0);
  exact.merge_convex_corners = false;
  const auto sp = simplify_part(c, exact);
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::None) << sp.result.reason;
  const double polygon_area = 0.5 * 48 * 25.0 * std::sin(2 * M_PI / 48);
  EXPECT_NEAR(sp.result.volume_before, polygon_area * 20.0, 1e-9);
  EXPECT_NEAR(sp.result.volume_after, sp.result.volume_before, 1e-6 * sp.result.volume_before);
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_LT(sp.result.hausdorff, sp.result.tolerance);
  EXPECT_EQ(sp.result.projections[0].polygon_vertices, 48u);
}

TEST(AlphaSim, CylinderArcIsCoarsenedOutwardWithinTheGrowthBudget) {
  // By default the end view's arc is coarsened outwards: fewer vertices, still contains
  // the original, stands off it by less than polygon_growth_factor·dim_pre (0.25), and
  // the cross-section grows by less than perimeter × 0.25.
  Part c = make_part("cyl", cylinder_mesh(5.0, 20.0, 48));
  const AlphaSimOptions o = options(1.0);
  const auto sp = simplify_part(c, o);
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::None) << sp.result.reason;
  const double budget = o.polygon_growth_factor * o.dim_pre;
  // A circumscribed k-gon stands off r = 5 by 5 (1 / cos(π/k) − 1) < 0.25 from k = 11 on.
  EXPECT_GE(sp.result.projections[0].polygon_vertices, 11u);
  EXPECT_LT(sp.result.projections[0].polygon_vertices, 24u);
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_LT(sp.result.hausdorff, budget);
  EXPECT_GE(sp.result.volume_after, sp.result.volume_before * (1 - 1e-9));
  EXPECT_LT(sp.result.volume_after, sp.result.volume_before + 2 * M_PI * 5.0 * budget * 20.0);
  EXPECT_LT(sp.result.triangles_after, 48u * 4);
}

TEST(AlphaSim, CoarseCylinderIsSmoothedButContained) {
  // dim_pre larger than the radius: the profile keeps its extent, contains the original.
  Part c = make_part("cyl", cylinder_mesh(2.0, 10.0, 64));
  const auto sp = simplify_part(c, options(3.0));
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_GE(sp.result.volume_after, sp.result.volume_before * (1 - 1e-9));
}

// ------------------------------------------------------------------ failure modes

TEST(AlphaSimFailure, AlphaTooSmallForSamplingFallsBackToHull) {
  // 20 × 20 × 2 plate of 5 × 5 cells with a 10 × 10 hole: long edges, few vertices.
  Part plate = make_part("plate", extruded_grid(4, 4, 5.0, 2.0, [](int i, int j) {
                           return !(i >= 1 && i < 3 && j >= 1 && j < 3);
                         }));
  auto o = options(1.0);
  o.sampling_factor = 6.0;  // L_max = 6 ≫ α = 0.95: the paper's empty/ill-conditioned case
  const auto sp = simplify_part(plate, o);
  EXPECT_EQ(sp.result.status, AlphaSimStatus::HullFallback) << sp.result.reason;
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::ConvexHull);
  bool some = false;
  for (const auto& p : sp.result.projections)
    some |= p.status == ProjectionStatus::Empty || p.status == ProjectionStatus::Torn;
  EXPECT_TRUE(some);
  EXPECT_FALSE(sp.result.reason.empty());
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_NEAR(sp.result.volume_after, 800.0, 1e-6);  // XY hull = the full square
}

TEST(AlphaSimFailure, ZeroThicknessSheetKeepsOriginal) {
  Mesh sheet;
  sheet.vertices = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};
  sheet.triangles = {{0, 1, 2}, {0, 2, 3}};
  const auto sp = simplify_part(make_part("sheet", sheet), options(1.0));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::Thin);
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::Original);
  EXPECT_EQ(sp.mesh.triangle_count(), 2u);
  EXPECT_FALSE(sp.solid);
}

TEST(AlphaSimFailure, ProjectionBlockedByAnotherFeatureIsDetected) {
  // Three orthogonal plates at a corner (the paper's worm-gear case in its simplest form):
  // every axis projection is a full square, so the intersection fills the whole cube.
  Mesh m = box_mesh({0, 0, 0}, {10, 10, 2});
  m.append(box_mesh({0, 0, 2.01}, {2, 10, 10}));
  m.append(box_mesh({2.01, 0, 2.01}, {10, 2, 10}));
  const auto sp = simplify_part(make_part("corner", m), options(1.0));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::Blocked) << sp.result.reason;
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::Original);
  EXPECT_GE(sp.result.lost_space_radius, 2.0);
  EXPECT_EQ(sp.mesh.triangle_count(), m.triangle_count());
  // The same part with the check disabled gives the (wrong) full cube.
  auto o = options(1.0);
  o.detect_lost_space = false;
  const auto filled = simplify_part(make_part("corner", m), o);
  EXPECT_NEAR(filled.result.volume_after, 1000.0, 1e-6);
}

TEST(AlphaSimFailure, TooFineSamplingKeepsOriginal) {
  Part b = make_part("big", box_mesh({0, 0, 0}, {1000, 1000, 1000}));
  auto o = options(1.0);  // L_max 0.5 on a 1000-unit box: ~50 M points
  const auto sp = simplify_part(b, o);
  EXPECT_EQ(sp.result.status, AlphaSimStatus::TooFine) << sp.result.reason;
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::Original);
  EXPECT_EQ(sp.mesh.triangle_count(), 12u);
}

TEST(AlphaSimFailure, EmptyAndBadInput) {
  const auto sp = simplify_part(make_part("nothing", Mesh{}), options(1.0));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::EmptyInput);
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::Original);
  Part b = make_part("b", box_mesh({0, 0, 0}, {1, 1, 1}));
  EXPECT_THROW(simplify_part(b, options(0.0)), std::invalid_argument);
  EXPECT_THROW(simplify_part(b, options(std::nan(""))), std::invalid_argument);
  auto o = options(1.0);
  o.extra_planes.push_back(Vec3::Zero());
  EXPECT_THROW(simplify_part(b, o), std::invalid_argument);
  Part bad = b;
  bad.mesh.vertices[0].x() = std::nan("");
  EXPECT_THROW(simplify_part(bad, options(1.0)), std::invalid_argument);
}

TEST(AlphaSim, UserPlaneTightensADiagonalPart) {
  // A box rotated 45° about z: the axis projections give an octagon-ish prism hull; a
  // user plane along the box's own axes is exact.
  Mesh m = box_mesh({-10, -2, 0}, {10, 2, 4});
  m.transform(Eigen::Affine3d(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())));
  Part p = make_part("diag", m);
  auto o = options(1.0);
  const auto plain = simplify_part(p, o);
  o.extra_planes = {Vec3(1, 1, 0), Vec3(-1, 1, 0)};
  const auto tight = simplify_part(p, o);
  EXPECT_DOUBLE_EQ(plain.result.containment, 1.0);
  EXPECT_DOUBLE_EQ(tight.result.containment, 1.0);
  EXPECT_EQ(tight.result.projections.size(), 5u);
  // Exact up to the float32 rounding of the mesh's vertices (AlphaSimOptions::float32_vertices).
  EXPECT_NEAR(tight.result.volume_after, 20.0 * 4.0 * 4.0, 1e-6 + tight.mesh.area() * tight.result.float_rounding);
  EXPECT_LE(tight.result.volume_after, plain.result.volume_after + 1e-9);
}

// --------------------------------------------------------------------- real parts

class AlphaSimReal : public ::testing::TestWithParam<std::pair<const char*, double>> {};

TEST_P(AlphaSimReal, ContainsTheOriginal) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const std::filesystem::path file = std::filesystem::path(LOOM_SHARED_DATA) / GetParam().first;
  Part p = make_part(file.filename().string(), read_mesh_file(file));
  const double dim = GetParam().second * p.mesh.bounds().diagonal();
  auto o = options(dim);
  const auto sp = simplify_part(p, o);
  const auto& r = sp.result;
  EXPECT_DOUBLE_EQ(r.containment, 1.0) << r.reason;
  EXPECT_DOUBLE_EQ(r.containment_implicit, 1.0) << r.reason;
  EXPECT_GT(r.containment_samples, p.mesh.triangle_count());
  if (r.fallback != AlphaSimFallback::Original) {
    EXPECT_TRUE(r.closed_after);
    ASSERT_TRUE(sp.solid);
    // Every original vertex is inside the implicit solid, and (exact containment) every
    // point of every triangle: a barycentric lattice at L_max/4 of each, corners and
    // edges included.
    for (const auto& v : p.mesh.vertices) ASSERT_TRUE(sp.solid->contains(v, r.tolerance));
    std::size_t outside = 0, tested = 0;
    for (const auto& f : p.mesh.triangles) {
      const Vec3 a = p.mesh.vertices[f[0]], b = p.mesh.vertices[f[1]], c = p.mesh.vertices[f[2]];
      const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
      const int n = std::max(1, static_cast<int>(std::ceil(longest / (r.l_max / 4.0))));
      for (int i = 0; i <= n; ++i)
        for (int j = 0; i + j <= n; ++j, ++tested)
          outside += sp.solid->contains(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n), r.tolerance) ? 0 : 1;
    }
    EXPECT_EQ(outside, 0u) << "of " << tested << " lattice points of the triangles";
    if (r.closed_before) {
      EXPECT_GE(r.volume_after, r.volume_before * (1 - 1e-6));
    }
  }
  RecordProperty("alpha_sim_status", alpha_sim_status_name(r.status));
  RecordProperty("triangles_after", std::to_string(r.triangles_after));
  std::printf("%s: %s (%s) tris %zu -> %zu, vol %.4g -> %.4g, hausdorff %.4g, %.1f ms %s\n",
              GetParam().first, alpha_sim_status_name(r.status), alpha_sim_fallback_name(r.fallback),
              r.triangles_before, r.triangles_after, r.volume_before, r.volume_after, r.hausdorff, r.time_ms,
              r.reason.c_str());
}

INSTANTIATE_TEST_SUITE_P(SharedData, AlphaSimReal,
                         ::testing::Values(std::make_pair("occt/motor.stl", 0.03),
                                           std::make_pair("trimesh/featuretype.STL", 0.04),
                                           std::make_pair("fcl/env.obj", 0.02),
                                           std::make_pair("occt/shape.stl", 0.03),
                                           std::make_pair("trimesh/tube.obj", 0.05),
                                           std::make_pair("trimesh/bunny.ply", 0.04)));

TEST(AlphaSim, LatticeBitmapGivesTheSortedSampleSets) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  // The lattice nodes and cell centres are deduplicated on a bitmap; the reference sorts
  // every point (lattice_bitmap = false). Same sets, sorted and unique, on real parts.
  for (const char* name : {"occt/motor.stl", "trimesh/featuretype.STL", "fcl/env.obj"}) {
    const Mesh m = read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / name);
    AlphaSimPrism xy, xz, yz, tilted;
    xz.u = Vec3::UnitX(); xz.v = Vec3::UnitZ(); xz.n = -Vec3::UnitY();
    yz.u = Vec3::UnitY(); yz.v = Vec3::UnitZ(); yz.n = Vec3::UnitX();
    tilted.n = Vec3(1, 2, 3).normalized();
    tilted.u = tilted.n.cross(Vec3::UnitX()).normalized();
    tilted.v = tilted.n.cross(tilted.u);
    const double diag = m.bounds().diagonal();
    const double snap = std::exp2(std::floor(std::log2(1e-6 * diag / 4.0)));
    for (const double l_max : {0.01 * diag, 0.037 * diag})
      for (const auto* pr : {&xy, &xz, &yz, &tilted}) {
        const auto fast = alpha_sim_plane_samples(m, *pr, l_max, snap, true);
        const auto ref = alpha_sim_plane_samples(m, *pr, l_max, snap, false);
        ASSERT_EQ(fast.points.size(), ref.points.size()) << name;
        ASSERT_EQ(fast.checks.size(), ref.checks.size()) << name;
        EXPECT_TRUE(fast.points == ref.points) << name;
        EXPECT_TRUE(fast.checks == ref.checks) << name;
        auto less = [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); };
        EXPECT_TRUE(std::adjacent_find(fast.points.begin(), fast.points.end(),
                                       [&](const Vec2& a, const Vec2& b) { return !less(a, b); }) == fast.points.end());
        EXPECT_GT(fast.points.size(), m.vertices.size() / 8);
      }
  }
}

TEST(AlphaSim, SampleSetsAreSortedOnEverySnapGrid) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  // Points and checks on the snap grid are sorted by packed 64-bit grid keys where the
  // grid indices span less than 2^32, by their coordinates otherwise: both orders must be
  // the lexicographic one, without repeats, and every coordinate a multiple of snap.
  const Mesh m = read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / "occt/motor.stl");
  const double diag = m.bounds().diagonal();
  AlphaSimPrism xy;
  for (const double snap_share : {0.25e-6, 1e-3, std::exp2(-40.0)}) {  // the last spans > 2^32 cells
    const double snap = std::exp2(std::floor(std::log2(snap_share * diag)));
    const auto smp = alpha_sim_plane_samples(m, xy, 0.02 * diag, snap);
    for (const auto* set : {&smp.points, &smp.checks}) {
      std::vector<Vec2> ref = *set;
      std::sort(ref.begin(), ref.end(), [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
      ref.erase(std::unique(ref.begin(), ref.end()), ref.end());
      EXPECT_TRUE(ref == *set) << "snap " << snap;
      for (const Vec2& q : *set) {
        EXPECT_EQ(std::round(q.x() / snap) * snap, q.x());
        EXPECT_EQ(std::round(q.y() / snap) * snap, q.y());
      }
    }
    EXPECT_GT(smp.points.size(), 100u);
  }
}

namespace {
/// A w × h rectangle of two triangles in the XY plane from (0.3, 0.3): its corners lie off
/// the lattices of spacing 1 and 2.
Mesh offset_rectangle(double w, double h) {
  Mesh m;
  m.vertices = {{0.3, 0.3, 0}, {0.3 + w, 0.3, 0}, {0.3 + w, 0.3 + h, 0}, {0.3, 0.3 + h, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}
}  // namespace

TEST(AlphaSim, OnlyOutlineEdgesAreSubdivided) {
  // A 10 × 5 rectangle of two triangles in the XY plane, placed so that no lattice node
  // (spacing 1) lies on its diagonal: the diagonal is interior to the projection (its two
  // triangles lie on either side) and gets no subdivision points — the lattice nodes of
  // the two triangles sample the area around it — while the four sides are subdivided to
  // ≤ L_max. Seen edge-on (XZ) every edge is an outline and is subdivided.
  const Mesh m = offset_rectangle(10.0, 5.0);
  const double l_max = 1.0, snap = std::exp2(-30.0);
  AlphaSimPrism xy;
  const auto smp = alpha_sim_plane_samples(m, xy, l_max, snap);
  auto on_lattice = [](const Vec2& p) {
    return std::abs(p.x() - std::round(p.x())) < 1e-9 && std::abs(p.y() - std::round(p.y())) < 1e-9;
  };
  auto on_outline = [](const Vec2& p) {
    return std::abs(p.x() - 0.3) < 1e-9 || std::abs(p.x() - 10.3) < 1e-9 || std::abs(p.y() - 0.3) < 1e-9 ||
           std::abs(p.y() - 5.3) < 1e-9;
  };
  std::size_t outline = 0, lattice = 0;
  for (const Vec2& p : smp.points) {
    EXPECT_TRUE(on_lattice(p) || on_outline(p)) << "a point off the lattice inside the rectangle: " << p.transpose();
    outline += on_outline(p) ? 1 : 0;
    lattice += on_lattice(p) ? 1 : 0;
  }
  EXPECT_EQ(outline, 4u + 2u * 9u + 2u * 4u);  // corners + 9 and 4 inner points per side pair
  EXPECT_EQ(lattice, 10u * 5u);                // nodes (1..10) × (1..5)
  // The checks still hold the diagonal's sub-edge midpoints.
  std::size_t diagonal_checks = 0;
  for (const Vec2& c : smp.checks)
    if (std::abs((c.y() - 0.3) - 0.5 * (c.x() - 0.3)) < 1e-9 && !on_outline(c)) ++diagonal_checks;
  EXPECT_EQ(diagonal_checks, 12u);  // ⌈√125 / 1⌉ = 12 pieces of the diagonal
  // Edge-on, the outline is the whole projection: every edge is subdivided.
  AlphaSimPrism xz;
  xz.u = Vec3::UnitX(); xz.v = Vec3::UnitZ(); xz.n = -Vec3::UnitY();
  const auto edge_on = alpha_sim_plane_samples(m, xz, l_max, snap);
  std::size_t off_lattice = 0;
  for (const Vec2& p : edge_on.points) off_lattice += on_lattice(p) ? 0 : 1;
  EXPECT_GE(off_lattice, 10u);  // the diagonal's and sides' subdivision points along the line
}

TEST(AlphaSim, PointsInCoveredLatticeCellsAreLeftOutChecksAreKept) {
  // A square plate seen face-on (XY) with a fin standing on it, seen edge-on: the fin
  // projects onto a segment inside the plate, in lattice cells whose four corners are all
  // nodes. Its vertices and subdivision points add nothing there and are left out; its
  // sub-edge midpoints stay among the checks. Seen from the side (XZ) the fin is face-on
  // and its points are taken as usual.
  Mesh plate;
  plate.vertices = {{0.3, 0.3, 0}, {10.3, 0.3, 0}, {10.3, 10.3, 0}, {0.3, 10.3, 0}};
  plate.triangles = {{0, 1, 2}, {0, 2, 3}};
  Mesh with_fin = plate;
  with_fin.vertices.insert(with_fin.vertices.end(), {{3.1, 5.05, 0.5}, {7.7, 5.05, 0.5}, {7.7, 5.05, 3.0}, {3.1, 5.05, 3.0}});
  with_fin.triangles.push_back({4, 5, 6});
  with_fin.triangles.push_back({4, 6, 7});
  const double l_max = 1.0, snap = std::exp2(-30.0);
  AlphaSimPrism xy;
  for (const bool bitmap : {true, false}) {
    const auto alone = alpha_sim_plane_samples(plate, xy, l_max, snap, bitmap);
    const auto both = alpha_sim_plane_samples(with_fin, xy, l_max, snap, bitmap);
    EXPECT_TRUE(both.points == alone.points) << "bitmap " << bitmap;
    std::size_t fin_checks = 0;
    for (const Vec2& c : both.checks)
      if (std::abs(c.y() - 5.05) < 1e-9 && c.x() > 3.1 && c.x() < 7.7) ++fin_checks;
    EXPECT_GE(fin_checks, 5u) << "bitmap " << bitmap;  // ⌈4.6 / 1⌉ = 5 pieces of each long edge
  }
  AlphaSimPrism xz;
  xz.u = Vec3::UnitX(); xz.v = Vec3::UnitZ(); xz.n = -Vec3::UnitY();
  const auto side = alpha_sim_plane_samples(with_fin, xz, l_max, snap);
  std::size_t fin_corners = 0;
  for (const Vec2& p : side.points)
    for (const Vec2& q : {Vec2(3.1, 0.5), Vec2(7.7, 0.5), Vec2(7.7, 3.0), Vec2(3.1, 3.0)})
      if ((p - q).norm() < 1e-9) ++fin_corners;
  EXPECT_EQ(fin_corners, 4u);
}

TEST(AlphaSim, CoarseInteriorKeepsTheCornersOfFullCellsOnly) {
  // A 20 × 10 plate face-on (two triangles, corners off the lattice), L_max = 1: with the
  // coarse interior the nodes of odd index are dropped only where the cells of spacing 2
  // around them have all nine nodes, and so are the cell centres (checks) in such cells;
  // every even node, every point near the outline and every other check stays, and the
  // α-shape (α = 1.9) is the same rectangle and holds every check of the fine lattice. The bitmap and
  // the sorting path agree.
  const Mesh m = offset_rectangle(20.0, 10.0);
  const double l_max = 1.0, snap = std::exp2(-30.0);
  AlphaSimPrism xy;
  const auto fine = alpha_sim_plane_samples(m, xy, l_max, snap, true, false);
  const auto coarse = alpha_sim_plane_samples(m, xy, l_max, snap, true, true);
  const auto coarse_sorted = alpha_sim_plane_samples(m, xy, l_max, snap, false, true);
  EXPECT_TRUE(coarse.points == coarse_sorted.points);
  EXPECT_TRUE(coarse.checks == coarse_sorted.checks);
  auto less = [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); };
  // The cell centres inside complete 2-cells are no checks either: 2 × 2 per such cell.
  EXPECT_TRUE(std::includes(fine.checks.begin(), fine.checks.end(), coarse.checks.begin(), coarse.checks.end(), less));
  EXPECT_EQ(fine.checks.size() - coarse.checks.size(), 9u * 4u * 4u);
  EXPECT_TRUE(std::includes(fine.points.begin(), fine.points.end(), coarse.points.begin(), coarse.points.end(), less));
  std::size_t dropped = 0;
  for (const Vec2& p : fine.points) {
    if (std::binary_search(coarse.points.begin(), coarse.points.end(), p, less)) continue;
    ++dropped;
    const long i = std::lround(p.x()), j = std::lround(p.y());
    EXPECT_TRUE((i & 1) || (j & 1)) << p.transpose();  // an odd node
    // The nodes 1..20 × 1..10 are met: a dropped node has its 2-cells inside them.
    EXPECT_TRUE(i >= 2 && i <= 19 && j >= 2 && j <= 9) << p.transpose();
  }
  // Nodes 1..20 × 1..10: the complete 2-cells have even lower corners in 2..18 × 2..8.
  // Dropped: odd/odd 3..19 × 3..9 (9 × 4), odd/even 3..19 × 4..8 (9 × 3), even/odd
  // 4..18 × 3..9 (8 × 4).
  EXPECT_EQ(dropped, 36u + 27u + 32u);
  const AlphaShape2D a(fine.points, 1.9), b(coarse.points, 1.9);
  EXPECT_NEAR(a.area(), 200.0, 1e-6);
  EXPECT_NEAR(b.area(), a.area(), 1e-6);
  for (const Vec2& c : fine.checks) EXPECT_TRUE(b.contains(c, 1e-9)) << c.transpose();
}

// ---------------------------------------------------------- determinism, indices

TEST(AlphaSim, DeterministicAcrossRuns) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  Part p = make_part("motor", read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / "occt/motor.stl"));
  auto o = options(0.06 * p.mesh.bounds().diagonal());
  const auto a = simplify_part(p, o);
  const auto b = simplify_part(p, o);
  // The motor keeps three general outlines: this covers CGAL's corefinement, whose raw
  // output order follows heap addresses (mesh_intersection sorts it).
  EXPECT_EQ(a.result.booleans_by, "cgal");
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  ASSERT_EQ(a.mesh.triangles, b.mesh.triangles);
  for (std::size_t i = 0; i < a.mesh.vertices.size(); ++i) ASSERT_EQ(a.mesh.vertices[i], b.mesh.vertices[i]);
  EXPECT_EQ(a.result.hausdorff, b.result.hausdorff);
  EXPECT_EQ(a.result.containment_samples, b.result.containment_samples);
}

TEST(AlphaSim, SimplifiedPartsPlugIntoAnObstacleIndex) {
  std::vector<Part> parts;
  parts.push_back(make_part("plate", extruded_grid(20, 20, 1.0, 1.0, [](int i, int j) { return !(i == 4 && j == 4); })));
  parts.push_back(make_part("box", box_mesh({30, 0, 0}, {35, 5, 5})));
  parts[1].clearance = 2.5;
  std::vector<AlphaSimResult> res;
  const auto simple = simplify_parts(parts, options(2.0), &res);
  ASSERT_EQ(simple.size(), 2u);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_EQ(simple[0].name, "plate");
  EXPECT_EQ(res[1].name, "box");
  EXPECT_DOUBLE_EQ(simple[1].clearance, 2.5);
  EXPECT_TRUE(simple[0].closed);
  BruteForceIndex original(parts), simplified(simple);
  const Vec3 in_small_hole(4.5, 4.5, 0.5);
  EXPECT_FALSE(original.inside(in_small_hole));
  EXPECT_TRUE(simplified.inside(in_small_hole));
  EXPECT_EQ(simple[1].mesh.triangle_count(), 12u);
}

TEST(AlphaSim, LongBoxIsTwelveTriangles) {
  // A spar-web-like plate 1500 × 6 × 200 at dim_pre 8: each projection is a rectangle with
  // thousands of boundary samples along its long sides; merged, the result is the box.
  Part web = make_part("web", box_mesh({0, 0, 0}, {1500, 6, 200}));
  const auto sp = simplify_part(web, options(8.0));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::Ok) << sp.result.reason;
  EXPECT_EQ(sp.mesh.triangle_count(), 12u);
  for (const auto& p : sp.result.projections) EXPECT_EQ(p.polygon_vertices, 4u) << p.plane;
  EXPECT_NEAR(sp.result.volume_after, 1500.0 * 6.0 * 200.0, 1e-6 * 1500.0 * 6.0 * 200.0);
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
}

TEST(AlphaSim, FacesSeenEdgeOnAreCheckedAsTheirEdges) {
  // The long plate: in each plane the four faces along the normal (eight triangles) are
  // seen edge-on and project onto the rectangle's four sides, one merged segment each.
  Part web = make_part("web", box_mesh({0, 0, 0}, {1500, 6, 200}));
  const auto sp = simplify_part(web, options(8.0));
  ASSERT_EQ(sp.result.status, AlphaSimStatus::Ok) << sp.result.reason;
  for (const auto& p : sp.result.projections) {
    EXPECT_EQ(p.edge_on_triangles, 8u) << p.plane;
    EXPECT_EQ(p.edge_on_segments, 4u) << p.plane;
  }
  // A faceted cylinder along x: its 48 side facets (96 triangles) are edge-on in the end
  // view, each its own chord; the caps' 96 fan triangles in the two side views, one merged
  // segment per cap. The result contains the original (oracle); the other triangles are
  // tested whole.
  Mesh cyl = cylinder_mesh(5.0, 20.0, 48);
  for (auto& v : cyl.vertices) v = Vec3(v.z(), v.x(), v.y());  // along x
  const Part c = make_part("cyl-x", cyl);
  {
    const auto r = simplify_part(c, options(1.0));
    ASSERT_EQ(r.result.status, AlphaSimStatus::Ok) << r.result.reason;
    for (const auto& p : r.result.projections) {
      const bool end_view = std::abs(p.normal.x()) == 1.0;
      EXPECT_EQ(p.edge_on_triangles, 96u) << p.plane;
      EXPECT_EQ(p.edge_on_segments, end_view ? 48u : 2u) << p.plane;
      EXPECT_EQ(p.exact_triangles, c.mesh.triangle_count() - 96u) << p.plane;
    }
    const auto samples = dense_surface_samples(c.mesh, 0.25, 4.0, 100000, 31);
    EXPECT_DOUBLE_EQ(oracle_containment(r.mesh, samples, r.result.tolerance), 1.0);
  }
}

TEST(AlphaSim, AbsorbedBoxPrismsGiveTheSolidOfEveryBoolean) {
  // A U-channel (rectangles from the side and the end: one prism left), the L-bracket
  // (a rectangle from two sides), a box (one box) and a cylinder across the axes (one
  // rectangle absorbed, two prisms left: sliced): the same solid as intersecting all three
  // prisms — the implicit solid, which absorbs none — with no Boolean run.
  struct Case {
    Part part;
    double dim_pre;
    int kept;  // prisms left after absorbing
  };
  std::vector<Case> cases;
  cases.push_back({make_part("U", extruded_grid(20, 6, 1.0, 30.0,
                                                [](int i, int j) { return j == 0 || i < 2 || i > 17; })),
                   1.0, 1});
  cases.push_back({make_part("L", extruded_grid(12, 12, 1.0, 2.0, [](int i, int j) { return i < 3 || j < 3; })),
                   1.0, 1});
  cases.push_back({make_part("box", box_mesh({0, 0, 0}, {40, 6, 20})), 2.0, 1});
  Mesh cyl = cylinder_mesh(5.0, 20.0, 48);
  for (auto& v : cyl.vertices) v = Vec3(v.z(), v.x(), v.y());  // along x
  cases.push_back({make_part("cyl-x", cyl), 1.0, 2});
  for (const Case& c : cases) {
    const AlphaSimOptions o = options(c.dim_pre);
    const auto a = simplify_part(c.part, o);
    ASSERT_EQ(a.result.status, AlphaSimStatus::Ok) << c.part.name << ": " << a.result.reason;
    EXPECT_EQ(a.result.booleans, 0) << c.part.name;
    EXPECT_EQ(a.result.prisms_absorbed, 3 - c.kept) << c.part.name;
    EXPECT_TRUE(a.result.closed_after) << c.part.name;
    EXPECT_DOUBLE_EQ(a.result.containment, 1.0) << c.part.name;
    ASSERT_TRUE(a.solid);
    // Oracle: the implicit solid, the intersection of all three prisms. The mesh may grow
    // it by the outlines' growth and stand off by the tolerance; farther than that from its
    // boundary (distance_bound: exact sign, a lower bound outside) the two agree.
    const double band = o.polygon_growth_factor * c.dim_pre + a.result.tolerance;
    Part mesh_part = make_part("a", a.mesh);
    mesh_part.closed = true;
    const EmbreeIndex on_a({mesh_part});
    const AABB box = a.mesh.bounds().inflated(2.0 * band);
    constexpr int kGrid = 24;
    std::size_t in_checked = 0, out_checked = 0;
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; j <= kGrid; ++j)
        for (int k = 0; k <= kGrid; ++k) {
          const Vec3 p = box.min + (box.max - box.min).cwiseProduct(Vec3(i, j, k) / kGrid);
          const double d = a.solid->distance_bound(p);
          if (d < -band) {
            ++in_checked;
            EXPECT_TRUE(on_a.inside(p)) << c.part.name << " " << p.transpose();
          } else if (d > band) {
            ++out_checked;
            EXPECT_FALSE(on_a.inside(p)) << c.part.name << " " << p.transpose();
          }
        }
    EXPECT_GT(in_checked, 0u) << c.part.name;
    EXPECT_GT(out_checked, 0u) << c.part.name;
  }
}

TEST(AlphaSim, CgalBooleansGiveTheSolidOfOpenCascade) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  // Parts left with three general outlines (a sphere; the motor, featuretype and bunny at
  // the bench's 2% of the diagonal): CGAL's exact corefinement of the prism meshes against
  // OpenCASCADE's Booleans of the same prisms (the oracle, an independent implementation).
  // The same solid: equal volumes, every vertex of each on the other's surface.
  std::vector<Part> parts;
  const Mesh sphere = testmesh::uv_sphere(Vec3::Zero(), 10.0, 32, 16);
  parts.push_back(make_part("sphere", sphere));
  for (const char* rel : {"occt/motor.stl", "trimesh/featuretype.STL", "trimesh/bunny.ply"})
    parts.push_back(make_part(rel, read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / rel)));
  for (const Part& p : parts) {
    const double dim = p.name == "sphere" ? 2.0 : 0.02 * p.mesh.bounds().diagonal();
    AlphaSimOptions occt = options(dim);
    // STEP output needs OpenCASCADE's B-rep: it runs the Booleans.
    occt.step_dir = std::filesystem::temp_directory_path() / "loom-test-alpha-sim-step";
    std::filesystem::create_directories(occt.step_dir);
    const auto a = simplify_part(p, options(dim)), b = simplify_part(p, occt);
    ASSERT_NE(a.result.fallback, AlphaSimFallback::Original) << p.name << ": " << a.result.reason;
    ASSERT_NE(b.result.fallback, AlphaSimFallback::Original) << p.name << ": " << b.result.reason;
    EXPECT_EQ(a.result.booleans_by, "cgal") << p.name;
    EXPECT_EQ(b.result.booleans_by, "opencascade") << p.name;
    EXPECT_EQ(a.result.booleans_note, "") << p.name;
    EXPECT_EQ(b.result.booleans_note, "--step") << p.name;
    // Two of the three prisms are sliced by loom, the third is one corefinement.
    EXPECT_EQ(a.result.booleans, 1) << p.name;
    EXPECT_EQ(b.result.booleans, 2) << p.name;
    EXPECT_TRUE(a.result.closed_after) << p.name;
    EXPECT_DOUBLE_EQ(a.result.containment, 1.0) << p.name;
    // OpenCASCADE's result is exact up to its own tolerance (≤ the containment tolerance).
    EXPECT_NEAR(a.result.volume_after, b.result.volume_after, 1e-6 * b.result.volume_after) << p.name;
    // Faces: OpenCASCADE keeps two coplanar faces apart where they come from different
    // prisms (it does not unify same-domain faces); loom's slicer gives a slice plane one
    // label, so its count is the same or lower.
    EXPECT_LE(a.result.faces_after, b.result.faces_after) << p.name;
    EXPECT_GE(a.result.faces_after, b.result.faces_after * 9 / 10) << p.name;
    // The points corefinement adds are merged away: about OpenCASCADE's triangle count.
    EXPECT_LE(a.result.triangles_after, b.result.triangles_after * 11 / 10) << p.name;
    const EmbreeIndex on_a({make_part("a", a.mesh)}), on_b({make_part("b", b.mesh)});
    for (const Vec3& v : a.mesh.vertices)
      ASSERT_LT(on_b.closest(v, 1.0).distance, a.result.tolerance) << p.name << " " << v.transpose();
    for (const Vec3& v : b.mesh.vertices)
      ASSERT_LT(on_a.closest(v, 1.0).distance, a.result.tolerance) << p.name << " " << v.transpose();
  }
}

TEST(AlphaSim, FacetedCylinderAcrossTheAxesIsNotEroded) {
  // The actuator case: a cylinder along x whose side facets are split by diagonals; seen
  // along z its silhouette has samples just inside it (diagonal midpoints) that notch the
  // α-shape. Refinement closes the notches: no convex-hull fallback, containment 1.
  Mesh m = cylinder_mesh(35.0, 170.0, 96);
  m.transform(Eigen::Affine3d(Eigen::Translation3d(480, 600, 100) * Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY())));
  Part c = make_part("body", m);
  const auto sp = simplify_part(c, options(8.0));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::Ok) << sp.result.reason;
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::None);
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_DOUBLE_EQ(sp.result.containment_implicit, 1.0);
  // Merging nearly collinear boundary points may shave up to the tolerance off the circle.
  EXPECT_GE(sp.result.volume_after, sp.result.volume_before * (1 - 1e-6));
  const auto samples = dense_surface_samples(c.mesh, 4.0, 1.0, 20000, 9);
  EXPECT_DOUBLE_EQ(oracle_containment(sp.mesh, samples, sp.result.tolerance), 1.0);
}

TEST(AlphaSim, DenseSamplesTakeEachFixedPointOnce) {
  // A closed box: 8 vertices, 18 edges (12 + 6 diagonals), 12 triangles. Without random
  // points (fixed_points only, the cap leaves one per triangle) the fixed points are every
  // vertex, every edge midpoint and every centroid, each exactly once: a shared edge's
  // midpoint is not taken once per triangle.
  const Mesh m = box_mesh({0, 0, 0}, {2, 4, 8});
  const auto with = dense_surface_samples(m, 1.0, 0.0, 0, 11, true);
  const auto without = dense_surface_samples(m, 1.0, 0.0, 0, 11, false);
  ASSERT_EQ(without.size(), m.triangles.size());  // one random point per triangle
  ASSERT_EQ(with.size(), 8 + 18 + 12 + without.size());
  auto key = [](const Vec3& v) { return std::make_tuple(v.x(), v.y(), v.z()); };
  std::map<std::tuple<double, double, double>, int> taken;  // how often each point was taken
  for (const Vec3& v : with) ++taken[key(v)];
  std::set<std::tuple<double, double, double>> expected;  // vertices, edge midpoints, centroids
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    for (int k = 0; k < 3; ++k) {
      expected.insert(key(c[k]));
      expected.insert(key((c[k] + c[(k + 1) % 3]) / 2.0));
    }
    expected.insert(key((c[0] + c[1] + c[2]) / 3.0));
  }
  ASSERT_EQ(expected.size(), 8u + 18u + 12u);
  for (const auto& e : expected)
    EXPECT_EQ(taken[e], 1) << "point (" << std::get<0>(e) << ", " << std::get<1>(e) << ", " << std::get<2>(e) << ")";
}

TEST(AlphaSim, TranslatedAndAxisTurnedCopiesAreSimplifiedOnce) {
  auto plate = [](const Vec3& at) {
    Mesh m = extruded_grid(12, 12, 1.0, 2.0, [](int i, int j) { return !(i == 3 && j == 3) && !(i >= 6 && i < 10 && j >= 6 && j < 10); });
    for (auto& v : m.vertices) v += at;
    return m;
  };
  std::vector<Part> parts = {make_part("a", plate({0, 0, 0})), make_part("b", plate({100.3, 7.1, -2.0})),
                             make_part("c", plate({0, 0, 0})), make_part("d", plate({0, 0, 0}))};
  parts[2].mesh.transform(Eigen::Affine3d(Eigen::AngleAxisd(M_PI / 6, Vec3::UnitZ())));  // not a copy: 30°
  // Turned end for end (180° about z) and moved, like the wing's rear spar: a copy.
  const Eigen::Affine3d turn = Eigen::Translation3d(50.0, 80.0, 3.0) * Eigen::AngleAxisd(M_PI, Vec3::UnitZ());
  parts[3].mesh.transform(turn);
  std::vector<AlphaSimResult> res;
  const auto simple = simplify_parts(parts, options(1.5), &res);
  ASSERT_EQ(res.size(), 4u);
  EXPECT_TRUE(res[0].copy_of.empty());
  EXPECT_EQ(res[1].copy_of, "a");
  EXPECT_EQ(res[1].name, "b");
  EXPECT_TRUE(res[2].copy_of.empty());
  EXPECT_EQ(res[3].copy_of, "a");
  ASSERT_EQ(simple[1].mesh.vertices.size(), simple[0].mesh.vertices.size());
  EXPECT_EQ(simple[1].mesh.triangles, simple[0].mesh.triangles);
  // The same vertices moved, up to the float32 rounding of the copy (AlphaSimOptions::float32_vertices).
  for (std::size_t i = 0; i < simple[0].mesh.vertices.size(); ++i)
    ASSERT_LT((simple[1].mesh.vertices[i] - simple[0].mesh.vertices[i] - Vec3(100.3, 7.1, -2.0)).norm(),
              1e-9 + res[1].float_rounding);
  // The copy contains its own original (independent oracle), like a direct simplification.
  const auto samples = dense_surface_samples(parts[1].mesh, 0.75, 1.0, 20000, 5);
  EXPECT_DOUBLE_EQ(oracle_containment(simple[1].mesh, samples, res[1].tolerance), 1.0);
  EXPECT_EQ(res[1].triangles_after, res[0].triangles_after);
  // The turned copy: the result turned the same way, and it contains its own original.
  for (std::size_t i = 0; i < simple[0].mesh.vertices.size(); ++i)
    ASSERT_LT((simple[3].mesh.vertices[i] - turn * simple[0].mesh.vertices[i]).norm(), 1e-9 + res[3].float_rounding);
  EXPECT_GT(simple[3].mesh.signed_volume(), 0.0);  // still outward
  EXPECT_NEAR(simple[3].mesh.signed_volume(), simple[0].mesh.signed_volume(),
              1e-9 * simple[0].mesh.signed_volume() + simple[0].mesh.area() * res[3].float_rounding);
  const auto samples_d = dense_surface_samples(parts[3].mesh, 0.75, 1.0, 20000, 6);
  EXPECT_DOUBLE_EQ(oracle_containment(simple[3].mesh, samples_d, res[3].tolerance), 1.0);
  // A copy turned a quarter about x: its XY projection is the source's XZ one (no hole)
  // and its XZ projection the source's XY one (the big hole); reported as a direct
  // simplification of the turned part reports them.
  Part e = parts[0];
  e.name = "e";
  e.mesh.transform(Eigen::Affine3d(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX())));
  std::vector<AlphaSimResult> res_e;
  simplify_parts({parts[0], e}, options(1.5), &res_e);
  ASSERT_EQ(res_e[1].copy_of, "a");
  const auto direct = simplify_part(e, options(1.5)).result;
  ASSERT_EQ(res_e[1].projections.size(), direct.projections.size());
  for (std::size_t k = 0; k < direct.projections.size(); ++k) {
    const auto& got = res_e[1].projections[k];
    const auto& want = direct.projections[k];
    EXPECT_EQ(got.plane, want.plane);
    EXPECT_EQ(got.holes, want.holes) << want.plane;
    EXPECT_NEAR(got.area, want.area, 1e-6 * want.area) << want.plane;
  }
  EXPECT_EQ(res_e[1].projections[1].holes, 1u);  // XZ: the big hole
  // With a user plane a rotation would turn it: only translations are reused then.
  auto with_plane = options(1.5);
  with_plane.extra_planes = {Vec3(1, 1, 0)};
  std::vector<AlphaSimResult> res_plane;
  simplify_parts({parts[0], parts[3]}, with_plane, &res_plane);
  EXPECT_TRUE(res_plane[1].copy_of.empty());
  EXPECT_EQ(simplify_part(parts[1], options(1.5)).result.status, AlphaSimStatus::Ok);
}

// ----------------------------------------------------------------------- property

/// Inside a property: one to three boxes, each turned about (1, 2, 3) (so that all three
/// projections are general outlines), their shells overlapping or apart.
Part random_turned_boxes() {
  const int n = *rc::gen::inRange(1, 4);
  Mesh m;
  for (int k = 0; k < n; ++k) {
    const double x = *rc::gen::inRange(0, 20), y = *rc::gen::inRange(0, 20), z = *rc::gen::inRange(0, 20);
    const double w = *rc::gen::inRange(1, 15), d = *rc::gen::inRange(1, 15), h = *rc::gen::inRange(1, 15);
    Mesh b = box_mesh({x, y, z}, {x + w, y + d, z + h});
    const double angle = *rc::gen::inRange(0, 90) * M_PI / 180.0;
    b.transform(Eigen::Affine3d(Eigen::AngleAxisd(angle, Vec3(1, 2, 3).normalized())));
    m.append(b);
  }
  return make_part("boxes", m);
}

/// Inside a property: options at a random dim_pre for random_turned_boxes.
AlphaSimOptions random_box_options() {
  auto o = options(*rc::gen::inRange(5, 40) / 10.0);
  o.detect_lost_space = false;  // overlapping shells have no consistent inside
  o.containment_max_samples = 20000;
  return o;
}

RC_GTEST_PROP(AlphaSimProperty, RandomBoxUnionsAreContained, ()) {
  const Part p = random_turned_boxes();
  const auto sp = simplify_part(p, random_box_options());
  // The output contains the original: verified, or the original itself is kept.
  RC_ASSERT(sp.result.fallback == AlphaSimFallback::Original || sp.result.containment == 1.0);
  RC_ASSERT(sp.result.containment_implicit == 1.0);
  if (sp.solid)
    for (const auto& v : p.mesh.vertices) RC_ASSERT(sp.solid->contains(v, sp.result.tolerance));
}

/// Random points (fixed seed) in the implicit solid of sp that the mesh neither holds nor
/// comes within tol of. The extruded outlines only grow the α-shapes (and merging collinear
/// points shrinks them by less than tol), so the mesh must hold the implicit solid.
std::size_t implicit_points_outside_the_mesh(const AlphaSimPart& sp, double tol, int samples) {
  // Closed as simplify_part verified it (closed_after): pieces may touch along an edge,
  // which analyse_topology does not call closed.
  Part part = make_part("mesh", sp.mesh);
  part.closed = true;
  const EmbreeIndex mesh({part});
  const AABB box = sp.mesh.bounds();
  std::mt19937_64 rng(23);
  std::size_t outside = 0;
  for (int k = 0; k < samples; ++k) {
    Vec3 q;
    for (int c = 0; c < 3; ++c) q[c] = std::uniform_real_distribution<double>(box.min[c], box.max[c])(rng);
    if (sp.solid->contains(q) && !mesh.inside(q) && !(mesh.closest(q, tol).found())) ++outside;
  }
  return outside;
}

RC_GTEST_PROP(AlphaSimProperty, TheMeshHoldsTheImplicitSolid, ()) {
  // The mesh (two prisms sliced, the third by exact corefinement, corefinement points
  // merged) against the implicit solid, the independent definition of the same prisms,
  // whose outlines the mesh's only grow.
  const Part p = random_turned_boxes();
  AlphaSimOptions o = random_box_options();
  o.measure = false;
  const auto sp = simplify_part(p, o);
  RC_PRE(sp.result.fallback != AlphaSimFallback::Original);
  RC_ASSERT(sp.result.closed_after);
  // Where pieces touch (a 2-manifold cannot hold them), OpenCASCADE runs the Booleans, and
  // its result has lost pieces of the intersection that hold no surface of the part (known
  // limit, docs/simplify.md): only CGAL's result is held to this.
  RC_TAG(sp.result.booleans_by);
  RC_ASSERT((sp.result.booleans_by == "opencascade") == !sp.result.booleans_note.empty());  // the fallback says why
  if (sp.result.booleans_by == "cgal") RC_ASSERT(implicit_points_outside_the_mesh(sp, sp.result.tolerance, 20000) == 0u);
}

RC_GTEST_PROP(AlphaSimProperty, GrowSimplifyOnlyGrowsRandomStarRings, ()) {
  // A star-shaped outer ring (random radii at increasing angles) around a star-shaped hole
  // (radii below the outer ring's distance from the centre), both moves, a random budget:
  // the region only grows, by less than the budget, and the rings stay simple, disjoint
  // and oriented.
  auto star = [](double r_lo, double r_hi, bool clockwise) {
    const int n = *rc::gen::inRange(4, 60);
    std::vector<Vec2> ring;
    for (int k = 0; k < n; ++k) {
      const double a = 2 * M_PI * (k + 0.01 * *rc::gen::inRange(0, 90)) / n;
      const double r = r_lo + (r_hi - r_lo) * 0.001 * *rc::gen::inRange(0, 1001);
      ring.emplace_back(r * std::cos(clockwise ? -a : a), r * std::sin(clockwise ? -a : a));
    }
    return ring;
  };
  std::vector<PolygonWithHoles2> polys(1);
  polys[0].outer = star(6.0, 10.0, false);
  double inner = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < polys[0].outer.size(); ++i)
    inner = std::min(inner, point_segment_distance(Vec2::Zero(), polys[0].outer[i],
                                                   polys[0].outer[(i + 1) % polys[0].outer.size()]));
  if (*rc::gen::arbitrary<bool>()) polys[0].holes.push_back(star(0.15 * inner, 0.9 * inner, true));
  const double max_dev = 0.01 * *rc::gen::inRange(1, 300);
  const auto before = rings_of(polys);
  grow_simplify(polys, max_dev, true);
  RC_ASSERT(grown_region_violation(before, rings_of(polys), max_dev, 10.5, *rc::gen::inRange(0, 1000), 2000) == "");
}
