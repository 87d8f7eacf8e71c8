// Arc–line routes against closed forms (tangent lengths, the rounded length of a right-angle
// corner, arc points on their circle), the cubic through the rounded points against the
// margin the router gives it, and the arc clearance check against brute-force exact distances.
#include "core/centerline.hpp"
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/route/arc_line.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <random>

namespace loom {
namespace {

TEST(ArcLine, CornerTangentIsRTimesTanOfHalfTheTurn) {
  EXPECT_NEAR(corner_tangent(Vec3::UnitX(), Vec3::UnitY(), 10.0), 10.0, 1e-12);
  const Vec3 out(std::cos(M_PI / 3), std::sin(M_PI / 3), 0.0);
  EXPECT_NEAR(corner_tangent(Vec3::UnitX(), out, 10.0), 10.0 * std::tan(M_PI / 6), 1e-12);
  EXPECT_EQ(corner_tangent(Vec3::UnitX(), Vec3::UnitX(), 10.0), 0.0);
  EXPECT_TRUE(std::isinf(corner_tangent(Vec3::UnitX(), -Vec3::UnitX(), 10.0)));
}

/// A right-angle corner: (0,0,0) → (100,0,0) → (100,100,0), arriving along +x, leaving along +y.
struct RightAngle {
  std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(100, 0, 0), Vec3(100, 100, 0)};
  ArcLineEnds ends{Vec3::UnitX(), 30.0, Vec3::UnitY(), 30.0};
};

TEST(ArcLine, RightAngleLengthAndShortLeg) {
  const RightAngle c;
  const double r = 40.0;
  EXPECT_NEAR(arc_line_length(c.v, c.ends, r), 200.0 - 2.0 * r + 0.5 * M_PI * r, 1e-9);
  EXPECT_EQ(arc_line_short_leg(c.v, c.ends, r).leg, -1);
  // A radius of 120 needs 120 of each 100-long leg: the first leg (ending at vertex 1) is short.
  const ShortLeg s = arc_line_short_leg(c.v, c.ends, 120.0);
  EXPECT_EQ(s.leg, 1);
  EXPECT_NEAR(s.needed, 120.0, 1e-9);
  EXPECT_NEAR(s.length, 100.0, 1e-12);
  EXPECT_TRUE(s.at.isApprox(c.v[1]));
}

TEST(ArcLine, SlackOnlyBetweenArcsOfOppositeSense) {
  const double r = 10.0;
  const Vec3 up = corner_normal(Vec3::UnitX(), Vec3::UnitY()), down = corner_normal(Vec3::UnitY(), Vec3::UnitX());
  EXPECT_TRUE(up.isApprox(Vec3::UnitZ()));
  EXPECT_EQ(leg_slack(up, up, r), 0.0);
  EXPECT_NEAR(leg_slack(up, down, r), kInnerLegSlack * r, 1e-12);
  EXPECT_EQ(leg_slack(up, Vec3::Zero(), r), 0.0);
  EXPECT_NEAR(leg_slack(Vec3::UnitZ(), Vec3(0, std::sin(0.5), std::cos(0.5)), r),
              kInnerLegSlack * r * 2.0 * std::sin(0.25), 1e-12);
  EXPECT_NEAR(leg_slack(Vec3::UnitZ(), Vec3::UnitY(), r), kInnerLegSlack * r, 1e-12);
  // An S: two right angles of opposite sense joined by a leg of exactly 2R; a U: of one sense.
  const ArcLineEnds ends{Vec3::UnitX(), r, Vec3::UnitX(), r};
  const std::vector<Vec3> s{Vec3(0, 0, 0), Vec3(0, 2 * r, 0)};
  EXPECT_EQ(arc_line_short_leg(s, ends, r).leg, 1);
  EXPECT_NEAR(arc_line_short_leg(s, ends, r).needed, (2.0 + kInnerLegSlack) * r, 1e-9);
  const ArcLineEnds u_ends{Vec3::UnitX(), r, -Vec3::UnitX(), r};
  EXPECT_EQ(arc_line_short_leg(s, u_ends, r).leg, -1);
}

TEST(ArcLine, EndVerticesTurnOnTheirStubs) {
  // The start vertex turns 90° from its heading: its tangent uses the stub's run.
  const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(0, 100, 0)};
  const ArcLineEnds ends{Vec3::UnitX(), 30.0, Vec3::UnitY(), 0.0};
  EXPECT_EQ(arc_line_short_leg(v, ends, 25.0).leg, -1);
  const ShortLeg s = arc_line_short_leg(v, ends, 35.0);
  EXPECT_EQ(s.leg, 0);
  EXPECT_NEAR(s.needed, 35.0, 1e-9);
  EXPECT_NEAR(s.length, 30.0, 1e-12);
  const std::vector<Vec3> pts = arc_line_points(v, ends, 25.0, 0.0);
  EXPECT_TRUE(pts.front().isApprox(Vec3(-25, 0, 0)));  // on the stub, before the stub end
}

TEST(ArcLine, RoundedPointsLieOnTheArc) {
  const RightAngle c;
  const double r = 40.0;
  const std::vector<Vec3> pts = arc_line_points(c.v, c.ends, r, M_PI / 16);
  const Vec3 centre(100.0 - r, r, 0.0);
  int on_arc = 0;
  for (const Vec3& p : pts) {
    if (p.x() >= 100.0 - r - 1e-9 && p.y() <= r + 1e-9) {
      EXPECT_NEAR((p - centre).norm(), r, 1e-9) << p.transpose();
      ++on_arc;
    }
  }
  EXPECT_GE(on_arc, 9);  // both tangent points and the 7 between them (8 pieces of 11.25°)
  EXPECT_TRUE(pts.front().isApprox(c.v.front()));
  EXPECT_TRUE(pts.back().isApprox(c.v.back()));
}

// The router rounds at 1.3 × the bend radius so that the cubic through the rounded points
// (end tangents along the stubs) keeps the radius: it bends up to ~22% tighter than the arcs
// where the curvature jumps from a leg's 0 to an arc's 1/R (most at short arcs between long
// ones; 13% at a lone corner). Random 3-D routes, turns up to 150°,
// each leg as short as its two tangents and the slack between the arcs allow (none between
// arcs of one sense and plane), or longer.
RC_GTEST_PROP(ArcLine, CubicThroughRoundedPointsKeepsTheRadiusWithinTheMargin, ()) {
  constexpr double kMargin = 1.3;
  const double radius = 10.0, arc = kMargin * radius;
  const int n = *rc::gen::inRange(2, 7);
  std::mt19937_64 rng(*rc::gen::inRange(0, 1 << 30));
  std::uniform_real_distribution<double> u(-1.0, 1.0), extra(0.0, 1.0);
  std::vector<Vec3> dirs{Vec3::UnitX()};  // heading into vertex k, then the end heading
  for (int i = 0; i < n; ++i) {
    Vec3 d;
    do d = dirs.back() + 1.6 * Vec3(u(rng), u(rng), u(rng));
    while (d.norm() < 1e-3 || std::acos(std::clamp(d.normalized().dot(dirs.back()), -1.0, 1.0)) > 150.0 * M_PI / 180.0);
    dirs.push_back(d.normalized());
  }
  std::vector<double> t;
  for (int k = 0; k < n; ++k) t.push_back(corner_tangent(dirs[k], dirs[k + 1], arc));
  const bool tight = *rc::gen::arbitrary<bool>();
  std::vector<Vec3> v{Vec3::Zero()};
  for (int k = 1; k < n; ++k)
    v.push_back(v.back() + (t[k - 1] + t[k] + 1e-9 +
                            leg_slack(corner_normal(dirs[k - 1], dirs[k]), corner_normal(dirs[k], dirs[k + 1]), arc) +
                            (tight ? 0.0 : 3.0 * arc * extra(rng))) *
                               dirs[k]);
  // Stubs as long as their arcs' tangents, or a little or much longer.
  const double stub_extra = *rc::gen::element(1e-9, 0.01, 0.05, 0.2, 1.0) * arc;
  const ArcLineEnds ends{dirs.front(), t.front() + stub_extra, dirs.back(), t.back() + stub_extra};
  RC_PRE(arc_line_short_leg(v, ends, arc).leg < 0);
  std::vector<Vec3> pts{v.front() - ends.start_run * ends.start_heading};
  for (const Vec3& p : arc_line_points(v, ends, arc, 0.0)) pts.push_back(p);
  pts.push_back(v.back() + ends.end_run * ends.end_heading);
  InterpolationOptions opt;
  opt.start_tangent = ends.start_heading;
  opt.end_tangent = ends.end_heading;
  const BendExtremum w = Centerline::interpolate(pts, opt).min_bend_radius();
  RC_ASSERT(w.radius >= radius);
}

// corner_arc_clear against exact distances from dense arc samples, near random boxes.
TEST(ArcLine, ArcClearanceAgreesWithBruteForce) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int clear = 0, blocked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 lo(60 + 50 * u(rng), 5 + 50 * u(rng), -20 + 20 * u(rng));
    const EmbreeIndex index({testmesh::box_part("b", lo, lo + Vec3(4 + 10 * u(rng), 4 + 10 * u(rng), 10))});
    const double r = 20.0 + 30.0 * u(rng), required = 3.0;
    const bool ok = corner_arc_clear(index, Vec3(100, 0, 0), Vec3::UnitX(), Vec3::UnitY(), r, required);
    double nearest = 1e300;
    const std::vector<Vec3> pts = arc_line_points({Vec3(100, 0, 0)}, {Vec3::UnitX(), r, Vec3::UnitY(), r}, r, 1e-3);
    for (const Vec3& p : pts) nearest = std::min(nearest, index.closest(p, 1e3).distance);
    if (ok) {
      EXPECT_GE(nearest, required - 1e-9) << "trial " << trial << " r " << r;
      ++clear;
    } else {
      // Refused: some arc point is within required plus the chords' sagitta.
      EXPECT_LT(nearest, required + r * (1.0 - std::cos(M_PI / 24)) + 1e-9) << "trial " << trial << " r " << r;
      ++blocked;
    }
  }
  EXPECT_GT(clear, 20);
  EXPECT_GT(blocked, 20);
}

}  // namespace
}  // namespace loom
