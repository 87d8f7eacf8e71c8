// Extrusions (α-SIM's prisms): the direct mesh against closed-form volumes and
// topology, and the absorption of axis boxes against a point-membership oracle (a point is
// in an intersection of extrusions iff it is in each: depth range and even-odd rings).
#include "index/simplify/extrusion.hpp"

#include "core/part.hpp"
#include "index/embree_index.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

using namespace loom;

namespace {

Extrusion frame_xy() { return Extrusion{}; }
Extrusion frame_xz() {
  Extrusion e;
  e.u = Vec3::UnitX();
  e.v = Vec3::UnitZ();
  e.n = -Vec3::UnitY();
  return e;
}
Extrusion frame_yz() {
  Extrusion e;
  e.u = Vec3::UnitY();
  e.v = Vec3::UnitZ();
  e.n = Vec3::UnitX();
  return e;
}

std::vector<Vec2> rect(double x0, double x1, double y0, double y1) {
  return {Vec2(x0, y0), Vec2(x1, y0), Vec2(x1, y1), Vec2(x0, y1)};
}

/// Even-odd membership of q in a polygon with holes (the test's own oracle).
bool in_rings(const PolygonWithHoles2& p, const Vec2& q) {
  bool in = false;
  auto ring = [&](const std::vector<Vec2>& r) {
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++)
      if ((r[i].y() > q.y()) != (r[j].y() > q.y()) &&
          q.x() < (r[j].x() - r[i].x()) * (q.y() - r[i].y()) / (r[j].y() - r[i].y()) + r[i].x())
        in = !in;
  };
  ring(p.outer);
  for (const auto& h : p.holes) ring(h);
  return in;
}

bool inside(const Extrusion& e, const Vec3& p) {
  const double d = p.dot(e.n);
  if (d < e.depth_min || d > e.depth_max) return false;
  const Vec2 q(p.dot(e.u), p.dot(e.v));
  for (const auto& poly : e.polygons)
    if (in_rings(poly, q)) return true;
  return false;
}

bool inside_all(const std::vector<Extrusion>& es, const Vec3& p) {
  for (const auto& e : es)
    if (!inside(e, p)) return false;
  return true;
}

/// Shortest distance from p to any face plane of the extrusions' rings and depth ranges
/// (points nearer than this to a boundary are left out of membership comparisons).
double boundary_distance(const std::vector<Extrusion>& es, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& e : es) {
    best = std::min({best, std::abs(p.dot(e.n) - e.depth_min), std::abs(p.dot(e.n) - e.depth_max)});
    const Vec2 q(p.dot(e.u), p.dot(e.v));
    auto ring = [&](const std::vector<Vec2>& r) {
      for (std::size_t i = 0; i < r.size(); ++i) {
        const Vec2 a = r[i], b = r[(i + 1) % r.size()];
        const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        best = std::min(best, (a + t * (b - a) - q).norm());
      }
    };
    for (const auto& poly : e.polygons) {
      ring(poly.outer);
      for (const auto& h : poly.holes) ring(h);
    }
  }
  return best;
}

/// A C-channel profile in (y, z): 40 wide, 20 high, walls 3 thick (CCW).
std::vector<Vec2> channel() {
  return {Vec2(0, 0), Vec2(40, 0), Vec2(40, 20), Vec2(37, 20), Vec2(37, 3), Vec2(3, 3), Vec2(3, 20), Vec2(0, 20)};
}

}  // namespace

TEST(Extrusion, MeshOfAnLWithAHoleIsClosedWithItsVolume) {
  for (Extrusion e : {frame_xy(), frame_xz(), frame_yz()}) {
    PolygonWithHoles2 l;
    l.outer = {Vec2(0, 0), Vec2(10, 0), Vec2(10, 4), Vec2(4, 4), Vec2(4, 10), Vec2(0, 10)};  // area 64
    l.holes.push_back({Vec2(1, 1), Vec2(1, 3), Vec2(3, 3), Vec2(3, 1)});                      // CW, area 4
    e.polygons = {l, PolygonWithHoles2{rect(20, 25, 0, 2), {}}};                                // + 10
    e.depth_min = 1.0;
    e.depth_max = 3.5;
    Mesh m = extrusion_mesh(e);
    weld_identical_vertices(m);
    const MeshTopology t = analyse_topology(m);
    EXPECT_TRUE(t.closed);
    EXPECT_EQ(t.boundary_edges, 0u);
    EXPECT_EQ(t.misoriented_edges, 0u);
    // Outward: positive signed volume, the region's area times the depth.
    EXPECT_NEAR(m.signed_volume(), (64.0 - 4.0 + 10.0) * 2.5, 1e-9);
    for (const Vec3& v : m.vertices) {
      const double d = v.dot(e.n);
      EXPECT_TRUE(std::abs(d - 1.0) < 1e-12 || std::abs(d - 3.5) < 1e-12) << d;
    }
    // Walls 6 + 4 + 4, caps 2 per polygon.
    EXPECT_EQ(extrusion_faces(e), 6 + 4 + 4 + 2 * 2);
  }
}

TEST(Extrusion, CrossingRingsOrAnEmptyDepthAreRefused) {
  Extrusion e = frame_xy();
  e.depth_max = 1.0;
  e.polygons = {PolygonWithHoles2{{Vec2(0, 0), Vec2(2, 2), Vec2(2, 0), Vec2(0, 2)}, {}}};  // a bow tie
  EXPECT_THROW(extrusion_mesh(e), std::runtime_error);
  e.polygons = {PolygonWithHoles2{rect(0, 1, 0, 1), {}}};
  EXPECT_NO_THROW(extrusion_mesh(e));
  e.depth_max = e.depth_min;
  EXPECT_THROW(extrusion_mesh(e), std::runtime_error);
  e.depth_max = 1.0;
  e.polygons.clear();
  EXPECT_THROW(extrusion_mesh(e), std::runtime_error);
}

TEST(Extrusion, AxisBoxIsOnlyAnAxisRectangleInAnAxisFrame) {
  Extrusion e = frame_xz();
  e.polygons = {PolygonWithHoles2{rect(0, 2, 0, 1), {}}};
  EXPECT_TRUE(is_axis_box(e));
  e.polygons[0].outer = {Vec2(0, 0), Vec2(0, -1), Vec2(2, -1), Vec2(2, 0)};  // starts along v (CW here)
  EXPECT_TRUE(is_axis_box(e));
  e.polygons[0].outer = {Vec2(0, 0), Vec2(1, 1), Vec2(0, 2), Vec2(-1, 1)};  // a turned square
  EXPECT_FALSE(is_axis_box(e));
  e.polygons[0] = {rect(0, 4, 0, 4), {{Vec2(1, 1), Vec2(1, 2), Vec2(2, 2), Vec2(2, 1)}}};
  EXPECT_FALSE(is_axis_box(e));  // a hole
  e.polygons = {PolygonWithHoles2{rect(0, 2, 0, 1), {}}, PolygonWithHoles2{rect(5, 6, 0, 1), {}}};
  EXPECT_FALSE(is_axis_box(e));  // two pieces
  e.polygons.resize(1);
  e.u = Vec3(1, 1, 0).normalized();
  e.n = e.u.cross(e.v);
  EXPECT_FALSE(axis_aligned(e));
  EXPECT_FALSE(is_axis_box(e));
}

TEST(Extrusion, SparSeenFromAboveAndTheSideIsItsProfileBetweenItsEnds) {
  // A C-channel spar along x ∈ [0, 1500]: XY and XZ are rectangles, YZ the profile. The
  // prisms run 1 past the part (the margin).
  Extrusion xy = frame_xy(), xz = frame_xz(), yz = frame_yz();
  xy.polygons = {PolygonWithHoles2{rect(0, 1500, 0, 40), {}}};
  xy.depth_min = -1;
  xy.depth_max = 21;
  xz.polygons = {PolygonWithHoles2{rect(0, 1500, 0, 20), {}}};
  xz.depth_min = -41;  // p·n = -y
  xz.depth_max = 1;
  yz.polygons = {PolygonWithHoles2{channel(), {}}};
  yz.depth_min = -1;
  yz.depth_max = 1501;
  const ExtrusionReduction red = reduce_extrusions({xy, xz, yz}, 0.0);
  ASSERT_EQ(red.kept.size(), 1u);
  EXPECT_EQ(red.absorbed, 2u);
  EXPECT_EQ(red.kept[0].polygons[0].outer, channel());
  EXPECT_EQ(red.kept[0].depth_min, 0.0);  // the rectangles' x range, not the margin
  EXPECT_EQ(red.kept[0].depth_max, 1500.0);
  Mesh m = extrusion_mesh(red.kept[0]);
  EXPECT_NEAR(m.signed_volume(), (40.0 * 20.0 - 34.0 * 17.0) * 1500.0, 1e-6);

  // Three boxes: one box, the intersection of the three.
  yz.polygons = {PolygonWithHoles2{rect(5, 30, 2, 15), {}}};
  const ExtrusionReduction boxes = reduce_extrusions({xy, xz, yz}, 0.0);
  ASSERT_EQ(boxes.kept.size(), 1u);
  EXPECT_NEAR(extrusion_mesh(boxes.kept[0]).signed_volume(), 1500.0 * 25.0 * 13.0, 1e-6);

  // A profile wider than the rectangle along y is not implied by it, and y is the normal
  // of no general prism: the rectangle stays (its Boolean is still needed).
  yz.polygons = {PolygonWithHoles2{channel(), {}}};
  xy.polygons = {PolygonWithHoles2{rect(0, 1500, 0, 39), {}}};
  const ExtrusionReduction wide = reduce_extrusions({xy, xz, yz}, 0.0);
  EXPECT_EQ(wide.kept.size(), 2u);
  EXPECT_EQ(wide.absorbed, 1u);
  // ... unless the excess is within the slack asked for.
  EXPECT_EQ(reduce_extrusions({xy, xz, yz}, 1.0).kept.size(), 1u);
}

namespace {

/// A random simple polygon: star-shaped around (cx, cy), sorted angles, CCW.
std::vector<Vec2> random_star(double cx, double cy, double r, int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.3, 1.0);
  std::vector<Vec2> ring;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * (k + 0.8 * u(rng)) / n;
    const double radius = r * u(rng);
    ring.emplace_back(cx + radius * std::cos(a), cy + radius * std::sin(a));
  }
  return ring;
}

}  // namespace

RC_GTEST_PROP(ExtrusionProperty, AbsorbingBoxesKeepsTheIntersection, ()) {
  std::mt19937_64 rng(*rc::gen::arbitrary<std::uint32_t>());
  std::uniform_real_distribution<double> coord(0.0, 10.0);
  std::vector<Extrusion> es = {frame_xy(), frame_xz(), frame_yz()};
  int boxes = 0;
  for (Extrusion& e : es) {
    const double lo = coord(rng), hi = lo + 1.0 + coord(rng);
    // XZ's normal is -y: its depth range is -y's.
    e.depth_min = e.n.sum() < 0 ? -hi : lo;
    e.depth_max = e.n.sum() < 0 ? -lo : hi;
    if (*rc::gen::inRange(0, 3) < 2) {
      const double x0 = coord(rng), y0 = coord(rng);
      e.polygons = {PolygonWithHoles2{rect(x0, x0 + 1.0 + coord(rng), y0, y0 + 1.0 + coord(rng)), {}}};
      ++boxes;
    } else {
      e.polygons = {PolygonWithHoles2{random_star(5.0 + coord(rng) / 2, 5.0 + coord(rng) / 2, 6.0, 12, rng), {}}};
    }
  }
  const ExtrusionReduction red = reduce_extrusions(es, 0.0);
  if (red.absorbed > 0) {
    RC_ASSERT(red.kept.size() + red.absorbed == es.size());
    if (boxes == 3) RC_ASSERT(red.kept.size() == 1u);
  } else {
    RC_ASSERT(red.kept.size() == es.size());
  }
  // Same solid: every point away from the boundaries is in both or in neither.
  std::uniform_real_distribution<double> any(-12.0, 22.0);
  int compared = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3 p(any(rng), any(rng), any(rng));
    if (boundary_distance(es, p) < 1e-9 || boundary_distance(red.kept, p) < 1e-9) continue;
    ++compared;
    RC_ASSERT(inside_all(es, p) == inside_all(red.kept, p));
  }
  RC_ASSERT(compared > 3900);
  // A single kept prism meshes into a closed solid of the same volume as the membership
  // count estimates (the mesh is the solid the indices will query).
  if (red.kept.size() == 1u) {
    Mesh m = extrusion_mesh(red.kept[0]);
    weld_identical_vertices(m);
    RC_ASSERT(analyse_topology(m).closed);
    RC_ASSERT(m.signed_volume() > 0.0);
  }
}

namespace {

/// Length of the slice of a region at height g along its other in-plane axis, clipped to
/// [lo, hi] (even-odd crossings; the test's own oracle). `region` maps each ring point to
/// (p, g) world coordinates.
double slice_length(const std::vector<std::vector<Vec2>>& rings, double g, double lo, double hi) {
  std::vector<double> xs;
  for (const auto& r : rings)
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Vec2 a = r[i], b = r[(i + 1) % r.size()];
      if ((a.y() > g) != (b.y() > g)) xs.push_back(a.x() + (g - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
    }
  std::sort(xs.begin(), xs.end());
  double len = 0.0;
  for (std::size_t i = 0; i + 1 < xs.size(); i += 2)
    len += std::max(0.0, std::min(xs[i + 1], hi) - std::max(xs[i], lo));
  return len;
}

/// Volume of the intersection of an XZ extrusion (region in (x, z), y in [ylo, yhi]) and a
/// YZ one (region in (y, z), x in [xlo, xhi]): the integral over z of the product of their
/// slice lengths, by the midpoint rule on a fine grid.
double pair_volume(const Extrusion& xz, const Extrusion& yz, int steps) {
  auto rings = [](const Extrusion& e) {
    std::vector<std::vector<Vec2>> out;
    for (const auto& p : e.polygons) {
      out.push_back(p.outer);
      for (const auto& h : p.holes) out.push_back(h);
    }
    return out;
  };
  const auto rx = rings(xz), ry = rings(yz);
  double z0 = std::numeric_limits<double>::infinity(), z1 = -z0;
  for (const auto& r : rx)
    for (const Vec2& q : r) {
      z0 = std::min(z0, q.y());
      z1 = std::max(z1, q.y());
    }
  const double h = (z1 - z0) / steps;
  double v = 0.0;
  for (int i = 0; i < steps; ++i) {
    const double z = z0 + (i + 0.5) * h;
    v += slice_length(rx, z, yz.depth_min, yz.depth_max) * slice_length(ry, z, -xz.depth_max, -xz.depth_min) * h;
  }
  return v;
}

void expect_closed(Mesh m, const std::string& what) {
  weld_identical_vertices(m);
  const MeshTopology t = analyse_topology(m);
  EXPECT_EQ(t.boundary_edges, 0u) << what;
  EXPECT_EQ(t.misoriented_edges, 0u) << what;
}

}  // namespace

TEST(ExtrusionPair, CrossedSquareFramesHaveTheirClosedFormVolume) {
  // A square frame seen from the front (XZ: 10 × 10 with a 6 × 6 hole) and a triangle from
  // the side (YZ: base 8 at z = 0, apex at z = 10), each deep enough to cover the other.
  Extrusion xz = frame_xz(), yz = frame_yz();
  xz.polygons = {PolygonWithHoles2{rect(0, 10, 0, 10), {{Vec2(2, 2), Vec2(2, 8), Vec2(8, 8), Vec2(8, 2)}}}};
  xz.depth_min = -9;  // y ∈ [-1, 9]
  xz.depth_max = 1;
  yz.polygons = {PolygonWithHoles2{{Vec2(0, 0), Vec2(8, 0), Vec2(4, 10)}, {}}};
  yz.depth_min = -1;
  yz.depth_max = 11;
  const ExtrusionsMesh pm = extrusion_pair_mesh(xz, yz);
  expect_closed(pm.mesh, "frames");
  // ∫ w_x(z) w_y(z) dz, w_y = 8 (1 - z/10); w_x = 10 outside z ∈ (2, 8), 4 inside.
  auto w_y_integral = [](double a, double b) { return 8.0 * ((b - a) - (b * b - a * a) / 20.0); };
  const double exact = 10.0 * w_y_integral(0, 2) + 4.0 * w_y_integral(2, 8) + 10.0 * w_y_integral(8, 10);
  EXPECT_NEAR(pm.mesh.signed_volume(), exact, 1e-9 * exact);
  // Nine planes: the frame's four walls across z (x = 0, 2, 8, 10), the triangle's two
  // slanted walls, and the slice planes z = 0 (facing down), 2 (up, under the hole) and 8
  // (down, over it); the apex at z = 10 is an edge.
  EXPECT_EQ(pm.faces, 9);

  // Depth ranges that cut the other region: y ∈ [1, 5] clips the triangle's slices, and
  // x ∈ [3, 20] the frame's.
  xz.depth_min = -5;
  xz.depth_max = -1;
  yz.depth_min = 3;
  yz.depth_max = 20;
  const ExtrusionsMesh cut = extrusion_pair_mesh(xz, yz);
  expect_closed(cut.mesh, "cut");
  const double v = pair_volume(xz, yz, 200000);
  EXPECT_NEAR(cut.mesh.signed_volume(), v, 1e-6 * v);
}

TEST(ExtrusionPair, RefusesParallelFramesAndEmptyIntersections) {
  Extrusion a = frame_xz(), b = frame_xz();
  a.polygons = b.polygons = {PolygonWithHoles2{rect(0, 1, 0, 1), {}}};
  a.depth_min = b.depth_min = -1;
  a.depth_max = b.depth_max = 0;
  EXPECT_THROW(extrusion_pair_mesh(a, b), std::runtime_error);
  Extrusion c = frame_yz();
  c.polygons = {PolygonWithHoles2{rect(0, 1, 5, 6), {}}};  // z ∈ [5, 6]: above a
  c.depth_min = -1;
  c.depth_max = 2;
  EXPECT_THROW(extrusion_pair_mesh(a, c), std::runtime_error);
  // Three whose first two do not meet: empty; one is meshed as it is.
  EXPECT_THROW(mesh_extrusions({a, c, c}, 1e-9), std::runtime_error);
  EXPECT_EQ(mesh_extrusions({a}, 1e-9).faces, extrusion_faces(a));
}

namespace {

/// Inside a property: one or two random star regions (side by side along the in-plane axis
/// other than z, some with a square hole) and a random depth range for e.
void random_region(Extrusion& e, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> coord(0.0, 10.0);
  const int pieces = *rc::gen::inRange(1, 3);
  for (int i = 0; i < pieces; ++i) {
    // A star around c: every vertex at least 1.8 from it, consecutive ones less than
    // 2π·1.56/n apart in angle, so from 6 vertices on every edge is more than
    // 1.8·cos(0.26π) ≈ 1.22 from c and a square hole of half-side 0.5 around c lies
    // inside (CW).
    const Vec2 c(7.0 + 14.0 * i, 5.0 + coord(rng) / 5);
    const int n = *rc::gen::inRange(3, 14);
    PolygonWithHoles2 p{random_star(c.x(), c.y(), 6.0, n, rng), {}};
    if (n >= 6 && *rc::gen::inRange(0, 2) == 1)
      p.holes.push_back({c + Vec2(-0.5, -0.5), c + Vec2(-0.5, 0.5), c + Vec2(0.5, 0.5), c + Vec2(0.5, -0.5)});
    e.polygons.push_back(p);
  }
  const double lo = coord(rng) * 2.0 - 2.0, hi = lo + 2.0 + coord(rng) * 2.0;
  e.depth_min = e.n.sum() < 0 ? -hi : lo;
  e.depth_max = e.n.sum() < 0 ? -lo : hi;
}

}  // namespace

RC_GTEST_PROP(ExtrusionPairProperty, RandomRegionsGiveAClosedSolidOfTheSlicedVolume, ()) {
  std::mt19937_64 rng(*rc::gen::arbitrary<std::uint32_t>());
  Extrusion xz = frame_xz(), yz = frame_yz();
  random_region(xz, rng);
  random_region(yz, rng);
  const double v = pair_volume(xz, yz, 100000);
  ExtrusionsMesh pm;
  try {
    pm = extrusion_pair_mesh(xz, yz);
  } catch (const std::runtime_error&) {
    RC_ASSERT(v < 1e-9);  // refused only when nothing is left
    return;
  }
  Mesh m = pm.mesh;
  weld_identical_vertices(m);
  const MeshTopology t = analyse_topology(m);
  RC_ASSERT(t.boundary_edges == 0u);
  RC_ASSERT(t.misoriented_edges == 0u);
  RC_ASSERT(std::abs(m.signed_volume() - v) <= 1e-4 * std::max(v, 1.0));
}

namespace {

/// Inside a property: the three axis frames, each with random regions and a depth over most
/// of the others' outlines (random ends), so that all three meet; with `user_plane`, a
/// fourth frame of random normal (a user projection plane) whose region covers their middle.
std::vector<Extrusion> random_meeting_extrusions(std::mt19937_64& rng, bool user_plane) {
  std::vector<Extrusion> es = {frame_xy(), frame_xz(), frame_yz()};
  std::uniform_real_distribution<double> end(0.0, 4.0);
  for (auto& e : es) {
    random_region(e, rng);
    const double lo = -3.0 + end(rng), hi = 27.0 + end(rng);
    e.depth_min = e.n.sum() < 0 ? -hi : lo;
    e.depth_max = e.n.sum() < 0 ? -lo : hi;
  }
  if (user_plane) {
    std::normal_distribution<double> g(0.0, 1.0);
    Extrusion e;
    e.n = Vec3(g(rng), g(rng), g(rng)).normalized();
    e.u = e.n.unitOrthogonal();
    e.v = e.n.cross(e.u);
    const Vec3 middle(10.0, 10.0, 6.0);
    const double cu = middle.dot(e.u), cv = middle.dot(e.v), cn = middle.dot(e.n);
    e.polygons = {PolygonWithHoles2{random_star(cu, cv, 14.0, *rc::gen::inRange(3, 14), rng), {}}};
    e.depth_min = cn - 12.0 - end(rng);
    e.depth_max = cn + 12.0 + end(rng);
    es.push_back(e);
  }
  return es;
}

}  // namespace

RC_GTEST_PROP(ExtrusionsProperty, ThreeRandomRegionsGiveTheirIntersection, ()) {
  // Three general outlines: two sliced, the third by exact corefinement, the points it
  // leaves merged within tol; with a fourth, user-plane outline half of the time (one more
  // corefinement, faces at any angle). Against point membership in every extrusion
  // (even-odd rings, depth range) at random points more than 10·tol from any face plane.
  std::mt19937_64 rng(*rc::gen::arbitrary<std::uint32_t>());
  const bool user_plane = *rc::gen::arbitrary<bool>();
  const std::vector<Extrusion> es = random_meeting_extrusions(rng, user_plane);
  const double tol = 1e-7;
  ExtrusionsMesh r;
  try {
    r = mesh_extrusions(es, tol);
  } catch (const std::runtime_error&) {
    // Refused only when nothing is left: no sample point lies in all of them.
    std::uniform_real_distribution<double> x(-2.0, 30.0), z(-4.0, 24.0);
    for (int k = 0; k < 20000; ++k) RC_ASSERT(!inside_all(es, Vec3(x(rng), x(rng), z(rng))));
    return;
  }
  RC_ASSERT(r.booleans == (user_plane ? 2 : 1));
  Mesh m = r.mesh;
  weld_identical_vertices(m);
  const MeshTopology t = analyse_topology(m);
  RC_ASSERT(t.boundary_edges == 0u);
  RC_ASSERT(t.misoriented_edges == 0u);
  RC_ASSERT(m.signed_volume() > 0.0);
  Part part;
  part.name = "r";
  part.mesh = r.mesh;
  part.closed = true;
  const EmbreeIndex index({part});
  std::uniform_real_distribution<double> x(-2.0, 30.0), z(-4.0, 24.0);
  for (int k = 0; k < 5000; ++k) {
    const Vec3 p(x(rng), x(rng), z(rng));
    if (boundary_distance(es, p) < 10.0 * tol) continue;
    RC_ASSERT(index.inside(p) == inside_all(es, p));
  }
}
