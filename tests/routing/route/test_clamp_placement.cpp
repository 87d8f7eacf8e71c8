// Clamp placement: a straight cable 20 mm above two plates with a 600 mm gap. Oracle: the
// closed-form stretches within reach (27 mm from the axis: x ≤ 800 + √(27² − 20²) over the
// first plate, x ≥ 1400 − √(27² − 20²) over the second), brute-force box distances for each
// clamp, and the supports audit of the placed clamps.
#include "routing/route/clamp_placement.hpp"

#include "common/support_fixtures.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/supports.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace loom {
namespace {

constexpr double kLength = 2000.0, kHeight = 20.0, kDiameter = 4.0;
constexpr double kSpacing = 450.0, kReach = 25.0;
const double kOverhang = std::sqrt(std::pow(kReach + 0.5 * kDiameter, 2) - kHeight * kHeight);
constexpr double kStep = kSpacing / 20.0;  ///< place_clamps' sample step here (< reach)

/// Euclidean distance from p to the box [lo, hi] (0 inside).
double box_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  return (p - p.cwiseMax(lo).cwiseMin(hi)).norm();
}

const Vec3 kLo1{-50, -100, -10}, kHi1{800, 100, 0}, kLo2{1400, -100, -10}, kHi2{2050, 100, 0};

TEST(ClampPlacement, GreedyClampsWithinReachAndAtMostTheSpacingApart) {
  const std::vector<Part> parts = {test::box_part("plate-1", kLo1, kHi1), test::box_part("plate-2", kLo2, kHi2)};
  Harness h = test::straight_cable(kLength, kHeight, kDiameter, {});
  const EmbreeIndex index(parts);
  const ClampPlacement placed = place_clamps(h, parts, index, kSpacing, kReach);
  ASSERT_FALSE(placed.clamps.empty());
  std::vector<double> xs{0.0};
  for (const Clamp& c : placed.clamps) {
    EXPECT_TRUE(c.placed);
    EXPECT_EQ(c.segment, 0);
    EXPECT_DOUBLE_EQ(c.bundle_diameter, kDiameter);
    const double d = std::min(box_distance(c.position, kLo1, kHi1), box_distance(c.position, kLo2, kHi2));
    EXPECT_LE(d, kReach + 0.5 * kDiameter + 1e-6) << c.id;
    EXPECT_EQ(c.part, c.position.x() < 1100 ? "plate-1" : "plate-2");
    xs.push_back(c.position.x());
  }
  xs.push_back(kLength);
  ASSERT_TRUE(std::is_sorted(xs.begin(), xs.end()));
  int long_gaps = 0;
  for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
    if (xs[i + 1] - xs[i] <= kSpacing + 1e-9) continue;
    ++long_gaps;  // only across the gap, from as far as reach allows to as near as it allows
    EXPECT_GE(xs[i], 800 + kOverhang - kStep);
    EXPECT_LE(xs[i + 1], 1400 - kOverhang + kStep);
  }
  EXPECT_EQ(long_gaps, 1);
  const double within = (800 + kOverhang) + (kLength - (1400 - kOverhang));
  EXPECT_NEAR(placed.share_within_reach(), within / kLength, kStep / kLength);

  // The audit of the placed clamps reports exactly that one stretch.
  h.clamps = placed.clamps;
  const SupportAudit audit = audit_supports(h, parts, index, kSpacing, kReach, true);
  ASSERT_EQ(audit.spans.size(), 1u);
  EXPECT_GE(audit.spans[0].from_s, 800 + kOverhang - kStep);
  EXPECT_LE(audit.spans[0].to_s, 1400 - kOverhang + kStep);
}

TEST(ClampPlacement, NothingWithinReachPlacesNothing) {
  const std::vector<Part> parts = {test::box_part("far", {0, 500, 0}, {10, 510, 10})};
  const Harness h = test::straight_cable(kLength, kHeight, kDiameter, {});
  const EmbreeIndex index(parts);
  const ClampPlacement placed = place_clamps(h, parts, index, kSpacing, kReach);
  EXPECT_TRUE(placed.clamps.empty());
  EXPECT_DOUBLE_EQ(placed.share_within_reach(), 0.0);
  EXPECT_DOUBLE_EQ(placed.cable_length, kLength);
}

TEST(ClampPlacement, KeepOutZonesHoldNothing) {
  const std::vector<Part> parts = {test::box_part("zone", kLo1, kHi1, PartRole::KeepOut)};
  const Harness h = test::straight_cable(kLength, kHeight, kDiameter, {});
  const EmbreeIndex index(parts);
  EXPECT_TRUE(place_clamps(h, parts, index, kSpacing, kReach).clamps.empty());
}

}  // namespace
}  // namespace loom
