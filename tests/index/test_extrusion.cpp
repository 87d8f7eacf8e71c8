// Extrusions (α-SIM's prisms, issue 4): the direct mesh against closed-form volumes and
// topology, and the absorption of axis boxes against a point-membership oracle (a point is
// in an intersection of extrusions iff it is in each: depth range and even-odd rings).
#include "index/extrusion.hpp"

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
