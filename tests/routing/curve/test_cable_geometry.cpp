// Cable centerlines assembled from segment curves along the harness tree.
#include "core/io/harness_xml.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <gtest/gtest.h>

namespace loom {
namespace {

const char* kHarness = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="10"/></cable>
    <cable id="C2"><electrical><port id="B"/><port id="D"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="A" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="200" y="0" z="0" dx="-1" dy="0" dz="0"/>
    <port id="D" x="100" y="-100" z="0" dx="0" dy="1" dz="0"/>
    <branch id="J" x="100" y="10" z="0">
      <segment to="A"><path><pt x="50" y="8" z="0"/></path></segment>
      <segment to="B"><path interp="polyline"><pt x="150" y="10" z="0"/></path></segment>
      <segment to="D"/>
    </branch>
  </structure>
</harness>
)";

/// Distance from p to the curve: coarse samples, then a ternary search on the arc length
/// around the best one (the distance is unimodal that close to the curve).
double closest_distance(const Centerline& c, const Vec3& p) {
  const double h = 0.5;
  double best = 1e300, best_s = 0;
  for (const auto& [s, q] : c.sample_by_arc_length(h)) {
    if ((q - p).norm() < best) best = (q - p).norm(), best_s = s;
  }
  double lo = std::max(0.0, best_s - h), hi = std::min(c.length(), best_s + h);
  auto dist = [&](double s) { return (c.position(c.parameter_at_length(s)) - p).norm(); };
  for (int i = 0; i < 200; ++i) {
    const double a = lo + (hi - lo) / 3, b = hi - (hi - lo) / 3;
    (dist(a) < dist(b) ? hi : lo) = (dist(a) < dist(b) ? b : a);
  }
  return std::min(best, dist(0.5 * (lo + hi)));
}

TEST(CableGeometry, SegmentCurveHonoursPortTangentAndPoints) {
  Harness h = parse_harness_xml(kHarness, "h.xml");
  // Segment 0 runs J -> A: it arrives at A against A's exit direction (+x), i.e. along -x.
  auto c = segment_centerline(h, 0);
  ASSERT_TRUE(c.has_value());
  EXPECT_LT((c->position(c->u_min()) - Vec3(100, 10, 0)).norm(), 1e-9);
  EXPECT_LT((c->position(c->u_max()) - Vec3(0, 0, 0)).norm(), 1e-9);
  const Vec3 t_end = c->derivative(c->u_max(), 1).normalized();
  EXPECT_LT((t_end - Vec3(-1, 0, 0)).norm(), 1e-9);
  EXPECT_LT(closest_distance(*c, Vec3(50, 8, 0)), 1e-6);
}

TEST(CableGeometry, PolylineSegmentIsExact) {
  Harness h = parse_harness_xml(kHarness, "h.xml");
  auto c = segment_centerline(h, 1);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->degree(), 1);
  EXPECT_NEAR(c->length(), 50.0 + std::hypot(50.0, 10.0), 1e-9);
}

TEST(CableGeometry, CableChainJoinsSegmentsInTravelOrder) {
  Harness h = parse_harness_xml(kHarness, "h.xml");
  HarnessTopology topo(h);
  auto c1 = cable_centerline(topo, 0);  // A -> J (segment 0 reversed) -> B (segment 1)
  ASSERT_TRUE(c1.has_value());
  EXPECT_EQ(c1->degree(), 3);
  EXPECT_LT((c1->position(c1->u_min()) - Vec3(0, 0, 0)).norm(), 1e-9);
  EXPECT_LT((c1->position(c1->u_max()) - Vec3(200, 0, 0)).norm(), 1e-9);
  EXPECT_LT(closest_distance(*c1, Vec3(100, 10, 0)), 1e-6);  // through the branch point
  EXPECT_LT(closest_distance(*c1, Vec3(150, 10, 0)), 1e-6);  // and the polyline corner
  const double expected = segment_centerline(h, 0)->length() + segment_centerline(h, 1)->length();
  EXPECT_NEAR(c1->length(), expected, 1e-6 * expected);
  // Leaves A along A's exit direction.
  EXPECT_LT((c1->derivative(c1->u_min(), 1).normalized() - Vec3(1, 0, 0)).norm(), 1e-9);
}

TEST(CableGeometry, ExactSplineIsUsedAsGiven) {
  Harness h = parse_harness_xml(kHarness, "h.xml");
  h.segments[2].bspline = BSplineData{3, {0, 0, 0, 0, 1, 1, 1, 1}, {{100, 10, 0}, {100, -20, 0}, {100, -60, 0}, {100, -100, 0}}};
  auto c = segment_centerline(h, 2);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->length(), 110.0, 1e-9);
}

TEST(CableGeometry, UnplacedBranchMeansNotRouted) {
  Harness h = parse_harness_xml(kHarness, "h.xml");
  h.branches[0].position.reset();
  HarnessTopology topo(h);
  EXPECT_FALSE(segment_centerline(h, 0).has_value());
  EXPECT_FALSE(cable_centerline(topo, 1).has_value());
}

TEST(CableGeometry, SegmentCurvesBuildEachDirectionOnceAndMatchTheSegmentCurve) {
  Harness h = parse_harness_xml(kHarness, "h.xml");
  HarnessTopology topo(h);
  SegmentCurves curves(topo);
  for (int s = 0; s < static_cast<int>(h.segments.size()); ++s) {
    const auto want = segment_centerline(h, s);
    const std::optional<Centerline>& fwd = curves.segment(s, false);
    const std::optional<Centerline>& back = curves.segment(s, true);
    ASSERT_TRUE(want && fwd && back);
    EXPECT_EQ(&fwd, &curves.segment(s, false));  // cached, not rebuilt
    EXPECT_EQ(&back, &curves.segment(s, true));
    EXPECT_EQ(fwd->control_points(), want->control_points());
    EXPECT_EQ(fwd->knots(), want->knots());
    EXPECT_NEAR(back->length(), want->length(), 1e-9 * want->length());
    for (double t : {0.0, 0.3, 1.0}) {
      const double u = want->u_min() + t * (want->u_max() - want->u_min());
      const double v = back->u_max() - (u - want->u_min());
      EXPECT_LT((back->position(v) - want->position(u)).norm(), 1e-9);
    }
  }
  // Cable curves through the cache are those of the free functions (C1 runs segment 0
  // backwards, C2 segment 2), piece by piece.
  for (int c = 0; c < 2; ++c) {
    const auto a = curves.cable(c), b = cable_centerline(topo, c);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->control_points(), b->control_points());
    EXPECT_EQ(a->knots(), b->knots());
    const auto pa = curves.pieces(c), pb = cable_pieces(topo, c);
    ASSERT_EQ(pa.size(), pb.size());
    for (std::size_t k = 0; k < pa.size(); ++k) {
      EXPECT_EQ(pa[k].segment, pb[k].segment);
      EXPECT_EQ(pa[k].s0, pb[k].s0);
    }
  }
  h.branches[0].position.reset();  // unplaced: not routed, through the cache too
  HarnessTopology unplaced(h);
  SegmentCurves none(unplaced);
  EXPECT_FALSE(none.segment(0, true).has_value());
  EXPECT_FALSE(none.cable(1).has_value());
  EXPECT_TRUE(none.pieces(1).empty());
}

}  // namespace
}  // namespace loom
