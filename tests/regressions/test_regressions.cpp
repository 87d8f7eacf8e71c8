// One test per bug found, with the inputs that exposed it written out in full so that the
// case replays without the generator or seed that found it. Name: area, what broke.
// Bugs of the command line are replayed where the command runs: tests/app/test_cli.cpp,
// CliRegression.* (e.g. given option values taken for "use the default").
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/centerline.hpp"
#include "index/box_pairs.hpp"
#include "routing/sweep.hpp"

namespace {

using loom::Centerline;
using loom::Vec3;

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// 2026-11-21, CI run after session 1: SweepProperty (RapidCheck, random seed) found a step
// where the double-reflection normal turned 1e-7 rad more than the tangent (0.0217073 vs
// 0.0217072). Not a sweep bug: double reflection approximates the rotation-minimising
// frame with an O(turn³) local error; the property's bound was too tight. The frame must
// stay within that order, and the tube must stay closed.
TEST(Regression, SweepDoubleReflectionTurnsWithinThirdOrderOfTheTangent) {
  // The original falsifying input (-64,-42,21, -77,1,-79, -23,39,-79, -23,-43,-84,
  // 29,-100,-67, 28,-12,-83; r = 0.15) stopped reaching its case when ring placement began
  // to predict steps from the curvature change (smaller first step); this input reaches it
  // with the current placement (excess 3.6e-8 at a turn of 0.077).
  const std::vector<int> c = {26, -11, -20, 5, -55, 78, 9, 100, 52, -51, -45, 11, 48, 14, -56, 11, -8, -47, -89, 54, 73, 18, -22, 10};
  std::vector<Vec3> p;
  for (std::size_t i = 0; i + 2 < c.size(); i += 3) p.emplace_back(c[i] * 0.1, c[i + 1] * 0.1, c[i + 2] * 0.1);
  const Centerline line = Centerline::interpolate(p);
  const double r = 0.05 + 0.01 * 6;
  const auto sec = loom::tube_sections(line, r, {0.02, true});
  ASSERT_GT(sec.size(), 2u);
  double worst_excess = 0.0;
  for (std::size_t i = 1; i < sec.size(); ++i) {
    const double turn = angle(sec[i - 1].tangent, sec[i].tangent);
    const double excess = angle(sec[i - 1].normal, sec[i].normal) - turn;
    EXPECT_LE(excess, turn * turn * turn + 1e-9) << "section " << i << " turn " << turn;
    worst_excess = std::max(worst_excess, excess);
  }
  // The case is only a regression test if it still exercises the excess it was found for.
  EXPECT_GT(worst_excess, 1e-9);
}

// 2026-11-21, session 9: BoxPairs.EqualsBruteForce (RapidCheck) aborted the process in
// Embree's BVH builder (assertion `diag[dim] > 0.0f`, heuristic_openmerge_array.h) on two
// equal point boxes: re-centred on their own centre, they rounded to float boxes of zero
// size (denormals flushed). The broad phase now pads every float box outwards by a normal
// float length, so no set of boxes has zero extent.
TEST(Regression, BoxPairsTwoEqualPointBoxesDoNotAbortTheBuilder) {
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0.1, -2.5, 7.0)}) {
    loom::AABB b;
    b.min = b.max = p;
    const auto pairs = loom::overlapping_box_pairs({b, b}, 2);
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0], loom::BoxPair(0, 1));
  }
}

}  // namespace
