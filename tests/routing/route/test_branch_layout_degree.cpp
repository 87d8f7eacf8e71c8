// Exit directions at nodes of 4, 8 and 16 segments (branch_exit_directions): the main line
// leaves in exactly opposite directions, every leg that shares cables with it leaves at least
// 90° from both of its directions (no cable folds back at the node), all are unit vectors.
#include "routing/route/branch_layout.hpp"

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

class ExitDirections : public ::testing::TestWithParam<int> {};

TEST_P(ExitDirections, MainLineStraightAndNoFoldBack) {
  const int n = GetParam();
  const Harness h = hub(n);
  const HarnessTopology topo(h);
  const auto ends = segment_ends(topo, derived_stub_length);
  const auto dirs = branch_exit_directions(h, topo, ends);
  ASSERT_EQ(static_cast<int>(dirs.size()), n);
  auto exit_of = [&](int s) { return dirs.at({s, h.segments[s].from == "H"}); };
  for (int s = 0; s < n; ++s) EXPECT_NEAR(exit_of(s).norm(), 1.0, 1e-12);
  EXPECT_NEAR(exit_of(0).dot(exit_of(1)), -1.0, 1e-12) << "the main line runs straight through the node";
  // Legs sharing cables with leg 0 leave at least 90° from it (the turn of each cable ≤ 90°).
  for (int s = 2; s < n; ++s) EXPECT_LE(exit_of(s).dot(exit_of(0)), 1e-12) << "leg " << s;
}

INSTANTIATE_TEST_SUITE_P(Ways, ExitDirections, ::testing::Values(4, 8, 16));

}  // namespace
}  // namespace loom
