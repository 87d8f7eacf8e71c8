// Router-placed branch points keep apart (place_branch_points): a 16-leg hub H and a node G
// whose medians coincide, next to a branch point F the file fixes there. Each pair ends at
// least the gap it needs (neighbours: both breakouts; others: the larger bundle diameter),
// F and every port stay where the file puts them.
#include "routing/route/branch_layout.hpp"

#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace loom {
namespace {

Harness separation_harness() {
  Harness h;
  h.name = "separation";
  h.branches.push_back({"H", std::nullopt, 0});
  h.branches.push_back({"G", std::nullopt, 0});
  h.branches.push_back({"F", Vec3(10, 0, 0), 0});
  auto port = [&](const std::string& id, const Vec3& at) { h.ports.push_back({id, at, -at.normalized(), 0, true}); };
  auto segment = [&](const std::string& a, const std::string& b) {
    Segment s;
    s.from = a;
    s.to = b;
    h.segments.push_back(s);
  };
  auto cable = [&](const std::string& a, const std::string& b) {
    Cable c;
    c.id = "C" + std::to_string(h.cables.size());
    c.ports[0] = a;
    c.ports[1] = b;
    c.physical.diameter = 3.0;
    c.physical.min_bend_radius = 12.0;
    h.cables.push_back(c);
  };
  // H: 15 ports spread over a sphere, plus G: 16 legs, its median at the origin.
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < 15; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 15;
    const Vec3 d(std::sqrt(1 - z * z) * std::cos(golden * i), std::sqrt(1 - z * z) * std::sin(golden * i), z);
    port("P" + std::to_string(i), 300.0 * d);
    segment("H", "P" + std::to_string(i));
  }
  // G: between two opposite ports, H and F: its median is on the line through the origin.
  port("PA", Vec3(0, -300, 0));
  port("PB", Vec3(0, 300, 0));
  segment("PA", "G");
  segment("G", "PB");
  segment("G", "H");
  segment("F", "G");
  port("PF1", Vec3(300, 0, 100));
  port("PF2", Vec3(300, 0, -100));
  segment("F", "PF1");
  segment("PF2", "F");
  for (int i = 1; i < 15; ++i) cable("P0", "P" + std::to_string(i));
  cable("PA", "PB");
  cable("PA", "P3");
  cable("PB", "P7");
  cable("PF1", "PF2");
  cable("PF1", "PA");
  cable("PF2", "P9");
  return h;
}

TEST(BranchSeparation, RouterPlacedNodesKeepTheirGaps) {
  Harness h = separation_harness();
  const Harness before = h;
  const HarnessTopology topo(h);
  ASSERT_EQ(topo.incident_segments("H").size(), 16u);
  const auto ends = segment_ends(topo, derived_stub_length);
  const EmbreeIndex index({testmesh::box_part("far", Vec3(1000, 1000, 1000), Vec3(1001, 1001, 1001))});
  BranchPlacementOptions opt;
  opt.clearance_of = [](int) { return 5.0; };
  const auto placed = place_branch_points(h, topo, index, ends, opt);
  ASSERT_EQ(placed.size(), 2u);

  // Fixed nodes and ports stay.
  ASSERT_TRUE(h.branches[2].position);
  EXPECT_EQ(*h.branches[2].position, Vec3(10, 0, 0));
  for (std::size_t p = 0; p < h.ports.size(); ++p) EXPECT_EQ(h.ports[p].position, before.ports[p].position);

  auto diameter_at = [&](const std::string& id) {
    double d = 0.0;
    for (int s : topo.incident_segments(id)) d = std::max(d, topo.segment_diameter(s));
    return d;
  };
  auto at = [&](int b) { return *h.branches[b].position; };
  const double bo_h = breakout_length(topo, "H"), bo_g = breakout_length(topo, "G"), bo_f = breakout_length(topo, "F");
  EXPECT_GE((at(0) - at(1)).norm(), bo_h + bo_g - 1e-9);  // neighbours H–G
  EXPECT_GE((at(1) - at(2)).norm(), bo_g + bo_f - 1e-9);  // neighbours G–F
  EXPECT_GE((at(0) - at(2)).norm(), std::max(diameter_at("H"), diameter_at("F")) - 1e-9);
  // Still near the middle of their legs: placement did not throw them out of the harness.
  EXPECT_LE(at(0).norm(), 100.0);
  EXPECT_LE(at(1).norm(), 100.0);
}

}  // namespace
}  // namespace loom
