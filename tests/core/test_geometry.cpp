// AABB: the box operations the indices and the audit build their query boxes with.
#include "core/geometry.hpp"

#include <gtest/gtest.h>

using loom::AABB;
using loom::Vec3;

TEST(AABB, InflatedGrowsEverySideAndKeepsTheBox) {
  AABB b;
  b.extend(Vec3(1, 2, 3));
  b.extend(Vec3(4, 2, 5));  // flat in y
  const AABB g = b.inflated(0.5);
  EXPECT_EQ(g.min, Vec3(0.5, 1.5, 2.5));
  EXPECT_EQ(g.max, Vec3(4.5, 2.5, 5.5));
  EXPECT_EQ(b.min, Vec3(1, 2, 3));  // the original is unchanged
  EXPECT_EQ(b.inflated(0.0).min, b.min);
  EXPECT_EQ(b.inflated(0.0).max, b.max);
  // A point box grown by r holds exactly the points within r in every coordinate.
  AABB p;
  p.extend(Vec3::Zero());
  EXPECT_TRUE(p.inflated(1.0).contains(Vec3(1, -1, 1)));
  EXPECT_FALSE(p.inflated(1.0).contains(Vec3(1.0000001, 0, 0)));
}

TEST(AABB, InflatedEmptyBoxStaysEmpty) {
  const AABB e;
  EXPECT_TRUE(e.inflated(10.0).empty());
  EXPECT_FALSE(e.inflated(10.0).contains(Vec3::Zero()));
}
