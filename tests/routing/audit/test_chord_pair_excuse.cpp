// The pair rules' excuses on one chord pair (routing/chord_pair_excuse.hpp) against closed
// forms: the deepest self contact beside a fold lies on the |s − t| = π r edge, the excused
// boxes of a shared segment and a junction, and the closest points outside them.
#include "routing/audit/chord_pair_excuse.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace loom;
using namespace loom::audit;

namespace {

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

// A V of angle θ folded at the origin: arm A runs in to the corner (s = 0 … L), arm B out of
// it (t = L … 2L). Points a and b from the corner are a + b apart along the cable; with
// a + b ≥ g the closest are a = b = g/2, g·sin(θ/2) apart, on the band's edge t − s = g.
TEST(ChordPairExcuse, VeeIsClosestOnTheBandEdge) {
  const double L = 10.0, g = 3.0;
  for (const double deg : {20.0, 60.0, 90.0, 150.0}) {
    const double th = deg * M_PI / 180.0;
    const Vec3 pa(L, 0, 0), pb(0, 0, 0), qa(0, 0, 0), qb(L * std::cos(th), L * std::sin(th), 0);
    const auto r = closest_apart(pa, pb, 0.0, L, qa, qb, L, 2 * L, g);
    ASSERT_TRUE(r.has_value()) << "theta " << g17(deg);
    EXPECT_NEAR(std::sqrt(r->dist2), g * std::sin(th / 2), 1e-12) << "theta " << g17(deg);
    // On the edge, halfway: s = L − g/2, t = L + g/2.
    EXPECT_NEAR(r->s, (L - g / 2) / L, 1e-12);
    EXPECT_NEAR(r->t, (g / 2) / L, 1e-12);
    EXPECT_NEAR((r->p - (pa + r->s * (pb - pa))).norm(), 0.0, 1e-12);
  }
}

// Chords shorter than the gap and next to each other along the cable: no points are π r
// apart, the pair is wholly excused. Two points (zero-length chords) are too.
TEST(ChordPairExcuse, ChordsWithinTheBandHaveNoPointsApart) {
  EXPECT_FALSE(closest_apart(Vec3(0, 0, 0), Vec3(1, 0, 0), 0.0, 1.0, Vec3(1, 0, 0), Vec3(2, 0, 0), 1.0, 2.0, 5.0));
  EXPECT_FALSE(closest_apart(Vec3(0, 0, 0), Vec3(0, 0, 0), 3.0, 3.0, Vec3(1, 0, 0), Vec3(1, 0, 0), 4.0, 4.0, 5.0));
}

// Two cables crossing in an X one unit apart (closest at the middle of both chords).
TEST(ChordPairExcuse, ClosestOutsideTheExcusedBoxesLiesOnAnUncoveredEdge) {
  const Vec3 pa(-5, 0, 0), pb(5, 0, 0), qa(0, -5, 1), qb(0, 5, 1);
  // Everything excused.
  EXPECT_FALSE(closest_unexcused({{0, 1, 0, 1}}, pa, pb, qa, qb));
  // The middle excused: the closest points left are 1 from the middle along one chord.
  const auto r = closest_unexcused({{0.4, 0.6, 0.4, 0.6}}, pa, pb, qa, qb);
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(std::sqrt(r->dist2), std::sqrt(2.0), 1e-12);
  // Two boxes sharing the edge λ = 0.6: that edge is inside the excused region, the others
  // are not; the answer is still √2, never a point of the shared edge's interior.
  const auto r2 = closest_unexcused({{0.4, 0.6, 0.4, 0.6}, {0.6, 0.8, 0.3, 0.7}}, pa, pb, qa, qb);
  ASSERT_TRUE(r2.has_value());
  EXPECT_NEAR(std::sqrt(r2->dist2), std::sqrt(2.0), 1e-12);
  EXPECT_FALSE(std::abs(r2->s - 0.6) < 1e-12 && r2->t > 0.4 && r2->t < 0.6) << g17(r2->s) << " " << g17(r2->t);
  // A box that covers a whole band of λ leaves only the sides: λ ≤ 0.3 or λ ≥ 0.7.
  const auto r3 = closest_unexcused({{0.3, 0.7, 0.0, 1.0}}, pa, pb, qa, qb);
  ASSERT_TRUE(r3.has_value());
  EXPECT_NEAR(std::sqrt(r3->dist2), std::sqrt(4.0 + 1.0), 1e-12);
}

// The excused boxes of one chord pair: a shared harness segment gives the product of the
// chords' parameter ranges within it; a shared junction the ranges within its radius.
TEST(ChordPairExcuse, BoxesOfASharedSegmentAndJunction) {
  CableInput a, b;
  a.segments = {{3, 10.0, 20.0}};
  b.segments = {{3, 0.0, 10.0}, {4, 10.0, 30.0}};
  // Chord A covers s 15 … 25 (half in segment 3), chord B t 5 … 15 (half in segment 3).
  auto boxes = excused_boxes(a, Vec3(0, 0, 0), Vec3(10, 0, 0), 15.0, 25.0, b, Vec3(0, 1, 0), Vec3(10, 1, 0), 5.0, 15.0);
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_NEAR(boxes[0].l0, 0.0, 1e-6);
  EXPECT_NEAR(boxes[0].l1, 0.5, 1e-6);
  EXPECT_NEAR(boxes[0].m0, 0.0, 1e-6);
  EXPECT_NEAR(boxes[0].m1, 0.5, 1e-6);
  // Different segments: nothing excused.
  CableInput c;
  c.segments = {{5, 0.0, 100.0}};
  EXPECT_TRUE(excused_boxes(a, Vec3(0, 0, 0), Vec3(10, 0, 0), 15.0, 25.0, c, Vec3(0, 1, 0), Vec3(10, 1, 0), 5.0, 15.0)
                  .empty());
  // A junction of radius 2 at (5, 0.5, 0) shared by both: each chord within 2 of it.
  CableInput ja, jb;
  ja.junctions = {{"B1", Vec3(5, 0.5, 0), 2.0}};
  jb.junctions = {{"B1", Vec3(5, 0.5, 0), 1.0}};
  boxes = excused_boxes(ja, Vec3(0, 0, 0), Vec3(10, 0, 0), 0.0, 10.0, jb, Vec3(0, 1, 0), Vec3(10, 1, 0), 0.0, 10.0);
  ASSERT_EQ(boxes.size(), 1u);
  const double half = std::sqrt(4.0 - 0.25) / 10.0;  // the larger radius applies
  EXPECT_NEAR(boxes[0].l0, 0.5 - half, 1e-12);
  EXPECT_NEAR(boxes[0].l1, 0.5 + half, 1e-12);
  EXPECT_NEAR(boxes[0].m0, 0.5 - half, 1e-12);
  EXPECT_NEAR(boxes[0].m1, 0.5 + half, 1e-12);
}
