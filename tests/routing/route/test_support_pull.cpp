// pull_to_structure: a route floating 120 mm over a plate is pulled down to it where it runs
// longer than the spacing out of reach. Oracle: closed-form box distances along the output
// sampled every 0.5 mm (the stretches within reach, and the clearance of every segment).
#include "routing/route/support_pull.hpp"

#include "common/support_fixtures.hpp"
#include "index/embree_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

namespace loom {
namespace {

constexpr double kSpacing = 450.0, kReach = 30.0, kRequired = 10.0, kFloat = 120.0;
const Vec3 kPlateLo{-50, -100, -10}, kPlateHi{2050, 100, 0};

double box_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) { return (p - p.cwiseMax(lo).cwiseMin(hi)).norm(); }

SupportPullSettings settings() {
  SupportPullSettings s;
  s.spacing = kSpacing;
  s.reach = kReach;
  s.required = kRequired;
  return s;
}

/// Longest stretch of `pts` (sampled every 0.5) between points within `reach` of the boxes
/// (`dist`), the ends counting as supports when `ports`; and the least distance seen.
template <class Dist>
std::pair<double, double> longest_span_and_min_distance(const std::vector<Vec3>& pts, Dist dist, double reach) {
  double s = 0.0, last = 0.0, longest = 0.0, min_d = 1e300;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double len = (pts[i + 1] - pts[i]).norm();
    const int n = std::max(1, static_cast<int>(len / 0.5));
    for (int k = 0; k <= n; ++k) {
      const double d = dist(pts[i] + (pts[i + 1] - pts[i]) * (static_cast<double>(k) / n));
      min_d = std::min(min_d, d);
      if (d <= reach) {
        longest = std::max(longest, s + len * k / n - last);
        last = s + len * k / n;
      }
    }
    s += len;
  }
  return {std::max(longest, s - last), min_d};
}

TEST(SupportPull, FloatingRouteIsPulledToThePlateAtMostTheSpacingApart) {
  const std::vector<Part> parts = {test::box_part("plate", kPlateLo, kPlateHi)};
  const EmbreeIndex index(parts);
  const std::vector<Vec3> route = {{0, 0, kFloat}, {2000, 0, kFloat}};
  const SupportPullResult r = pull_to_structure(index, route, settings());
  EXPECT_GT(r.inserted, 0);
  EXPECT_EQ(r.unfixed_spans, 0);
  EXPECT_NEAR(r.longest_span_before, 2000.0, 1e-9);
  EXPECT_LE(r.longest_span_after, kSpacing);
  ASSERT_EQ(r.points.size(), route.size() + static_cast<std::size_t>(r.inserted));
  EXPECT_EQ(r.points.front(), route.front());
  EXPECT_EQ(r.points.back(), route.back());
  const auto [longest, min_d] = longest_span_and_min_distance(
      r.points, [](const Vec3& p) { return box_distance(p, kPlateLo, kPlateHi); }, kReach);
  EXPECT_LE(longest, kSpacing) << "pulled route of " << r.points.size() << " points";
  EXPECT_GE(min_d, kRequired - 1e-9);
  // Inserted points sit at the target, midway between required and reach.
  for (std::size_t i = 1; i + 1 < r.points.size(); ++i)
    EXPECT_NEAR(box_distance(r.points[i], kPlateLo, kPlateHi), 0.5 * (kRequired + kReach), 1e-6) << i;
}

// A keep-out slab between the route and the plate: no move reaches the plate clear of it.
// With the slab as a non-supporting part nothing is inserted and the span is reported; with
// it marked as able to carry clamps, the route is pulled to the slab instead.
TEST(SupportPull, MovesThatBreakClearanceAreDroppedAndOnlySupportingPartsAttract) {
  const Vec3 slab_lo{-100, -150, 40}, slab_hi{2100, 150, 60};
  const std::vector<Part> parts = {test::box_part("plate", kPlateLo, kPlateHi),
                                   test::box_part("slab", slab_lo, slab_hi, PartRole::KeepOut)};
  const EmbreeIndex index(parts);
  const std::vector<Vec3> route = {{0, 0, kFloat}, {2000, 0, kFloat}};
  SupportPullSettings s = settings();
  s.part_supports = {true, false};
  SupportPullResult r = pull_to_structure(index, route, s);
  EXPECT_EQ(r.inserted, 0);
  EXPECT_EQ(r.unfixed_spans, 1);
  EXPECT_EQ(r.points, route);
  EXPECT_NEAR(r.longest_span_after, 2000.0, 1e-9);

  s.part_supports = {true, true};
  r = pull_to_structure(index, route, s);
  EXPECT_GT(r.inserted, 0);
  EXPECT_EQ(r.unfixed_spans, 0);
  const auto [longest, min_d] = longest_span_and_min_distance(
      r.points, [&](const Vec3& p) { return std::min(box_distance(p, kPlateLo, kPlateHi), box_distance(p, slab_lo, slab_hi)); },
      kReach);
  EXPECT_LE(longest, kSpacing);
  EXPECT_GE(min_d, kRequired - 1e-9);
}

// A branch-point end holds nothing: the first support must come within spacing / 2 of it
// (so that two segments meeting there leave at most the spacing across it); a port end holds.
TEST(SupportPull, BranchPointEndsNeedASupportWithinHalfTheSpacing) {
  const std::vector<Part> parts = {test::box_part("plate", kPlateLo, kPlateHi)};
  const EmbreeIndex index(parts);
  const std::vector<Vec3> route = {{0, 0, kFloat}, {400, 0, kFloat}};
  SupportPullSettings s = settings();
  EXPECT_EQ(pull_to_structure(index, route, s).inserted, 0);  // 400 between two ports
  s.start_is_port = false;
  const SupportPullResult r = pull_to_structure(index, route, s);
  ASSERT_GT(r.inserted, 0);
  // The first support (an inserted point) lies within spacing / 2 of the branch point.
  double s_first = 0.0;
  for (std::size_t i = 1; i < r.points.size(); ++i) {
    s_first += (r.points[i] - r.points[i - 1]).norm();
    if (box_distance(r.points[i], kPlateLo, kPlateHi) <= kReach) break;
  }
  EXPECT_LE(s_first, 0.5 * kSpacing);
}

TEST(SupportPull, RefusesSettingsWithoutRoom) {
  const std::vector<Part> parts = {test::box_part("plate", kPlateLo, kPlateHi)};
  const EmbreeIndex index(parts);
  SupportPullSettings s = settings();
  s.spacing = 0.0;
  EXPECT_THROW(pull_to_structure(index, {{0, 0, 50}, {100, 0, 50}}, s), std::invalid_argument);
  s = settings();
  s.reach = s.required;
  EXPECT_THROW(pull_to_structure(index, {{0, 0, 50}, {100, 0, 50}}, s), std::invalid_argument);
}

}  // namespace
}  // namespace loom
