// Exit directions at nodes of 4, 8 and 16 segments (branch_exit_directions): the main line
// leaves in exactly opposite directions, every leg that shares cables with it leaves at least
// 90° from both of its directions (no cable folds back at the node), all are unit vectors.
#include "routing/route/branch_layout.hpp"

#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace loom {
namespace {

/// Hub H at the origin, N ports 300 mm out along well-spread directions with leg 1 opposite
/// leg 0 (the main line); cables 0–1 (three of them) and 0–i for every other leg.
Harness hub(int n) {
  Harness h;
  h.name = "hub";
  h.branches.push_back({"H", Vec3::Zero(), 0});
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    Vec3 d;
    if (i == 0) d = Vec3(1, 0.1, 0).normalized();
    else if (i == 1) d = Vec3(-1, 0.05, 0.02).normalized();
    else {
      const double z = 1.0 - 2.0 * (i + 0.5) / n;
      d = Vec3(std::sqrt(1 - z * z) * std::cos(golden * i), std::sqrt(1 - z * z) * std::sin(golden * i), z);
    }
    h.ports.push_back({"P" + std::to_string(i), 300.0 * d, -d, 0});
    Segment s;
    s.from = i % 2 ? "P" + std::to_string(i) : "H";  // both orientations of segments
    s.to = i % 2 ? "H" : "P" + std::to_string(i);
    h.segments.push_back(s);
  }
  auto add = [&](int a, int b, int k) {
    Cable c;
    c.id = "C" + std::to_string(a) + "_" + std::to_string(b) + "_" + std::to_string(k);
    c.ports[0] = "P" + std::to_string(a);
    c.ports[1] = "P" + std::to_string(b);
    c.physical.diameter = 2.0;
    c.physical.min_bend_radius = 12.0;
    h.cables.push_back(c);
  };
  for (int k = 0; k < 3; ++k) add(0, 1, k);
  for (int i = 2; i < n; ++i) add(0, i, 0);
  return h;
}

/// The hub of GetParam() legs, its topology, segment ends and exit directions.
class ExitDirections : public ::testing::TestWithParam<int> {
 protected:
  const int n = GetParam();
  const Harness h = hub(n);
  const HarnessTopology topo{h};
  const std::vector<SegmentEnds> ends = segment_ends(topo, derived_stub_length);
  const std::map<std::pair<int, bool>, Vec3> before = branch_exit_directions(h, topo, ends);
};

TEST_P(ExitDirections, MainLineStraightAndNoFoldBack) {
  const auto& dirs = before;
  ASSERT_EQ(static_cast<int>(dirs.size()), n);
  auto exit_of = [&](int s) { return dirs.at({s, h.segments[s].from == "H"}); };
  for (int s = 0; s < n; ++s) EXPECT_NEAR(exit_of(s).norm(), 1.0, 1e-12);
  EXPECT_NEAR(exit_of(0).dot(exit_of(1)), -1.0, 1e-12) << "the main line runs straight through the node";
  // Legs sharing cables with leg 0 leave at least 90° from it (the turn of each cable ≤ 90°).
  for (int s = 2; s < n; ++s) EXPECT_LE(exit_of(s).dot(exit_of(0)), 1e-12) << "leg " << s;
}

// A wall 8 mm beside the hub (x ∈ [8, 40]) blocks the run of legs heading into it. Every exit
// that turns turns to a free direction (the run — breakout plus bend radius — clear by radius
// + clearance, checked exactly) away from the wall, ≥ 90° from the exits sharing cables with
// it and ≥ 30° from the rest; at the 4-way node every blocked exit finds one (at 8 and 16
// legs the main line, sharing cables with every leg, finds none and is kept); exits that were
// free stay as they were.
TEST_P(ExitDirections, BlockedExitsTurnToTheNearestFreeDirection) {
  auto dirs = before;
  const EmbreeIndex index({testmesh::box_part("wall", Vec3(8, -200, -200), Vec3(40, 200, 200))});
  const std::map<std::string, double> breakout{{"H", breakout_length(topo, "H")}};
  const double clearance = 1.0;
  const int turned = free_blocked_exits(index, h, topo, ends, breakout, clearance, dirs);
  auto key = [&](int s) { return std::make_pair(s, h.segments[s].from == "H"); };
  auto blocked = [&](int s, const Vec3& e) {
    return index.segment_within(Vec3::Zero(), (breakout.at("H") + ends[s].min_bend_radius) * e, ends[s].radius + clearance);
  };
  // Cables pass between leg 0 and every other leg, and between legs 0 and 1 (the main line).
  auto shares = [](int a, int b) { return a == 0 || b == 0; };
  int was_blocked = 0, moved = 0;
  for (int s = 0; s < n; ++s) {
    const Vec3 e0 = before.at(key(s)), e = dirs.at(key(s));
    EXPECT_NEAR(e.norm(), 1.0, 1e-12);
    was_blocked += blocked(s, e0);
    if (e == e0) {
      EXPECT_TRUE(n > 4 || !blocked(s, e0)) << "leg " << s << " stayed blocked";
      continue;
    }
    ++moved;
    EXPECT_TRUE(blocked(s, e0)) << "leg " << s << " was free";
    EXPECT_FALSE(blocked(s, e)) << "leg " << s;
    EXPECT_LT(e.x(), 0.3) << "leg " << s << " turns away from the wall, not through it";
    for (int t = 0; t < n; ++t) {
      if (t == s) continue;
      EXPECT_LE(e.dot(dirs.at(key(t))), shares(s, t) ? 1e-12 : std::cos(M_PI / 6) + 1e-12) << s << ", " << t;
    }
  }
  EXPECT_GT(was_blocked, 0);
  if (n == 4) {
    EXPECT_GT(moved, 0);
  }
  EXPECT_EQ(turned, moved);
}

INSTANTIATE_TEST_SUITE_P(Ways, ExitDirections, ::testing::Values(4, 8, 16));

}  // namespace
}  // namespace loom
