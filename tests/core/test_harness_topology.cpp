// Derived harness quantities on a hand-checked harness: chains, bundles, diameters, order.
#include "core/error.hpp"
#include "core/harness_topology.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace loom {
namespace {

Port port(const std::string& id, double x) { return Port{id, Vec3(x, 0, 0), Vec3::UnitZ(), 0}; }

Cable cable(const std::string& id, const std::string& a, const std::string& b, double d) {
  Cable c;
  c.id = id;
  c.ports[0] = a;
  c.ports[1] = b;
  c.physical.diameter = d;
  return c;
}

Segment seg(const std::string& a, const std::string& b) {
  Segment s;
  s.from = a;
  s.to = b;
  return s;
}

/// Hand-checked tree:      P1          P3
///                          \          / (tree)
///                           B1 ---- B2
///                          /          \ (tree)
///                        P2            P4
/// Cables: C1 P1–P3 (d 2), C2 P2–P3 (d 1), C3 P1–P4 (d 3), C4 P1–P2 (d 1).
Harness sample() {
  Harness h;
  h.name = "T";
  h.ports = {port("P1", 0), port("P2", 1), port("P3", 2), port("P4", 3)};
  h.branches = {{"B1", Vec3(0, 1, 0), 0}, {"B2", Vec3(2, 1, 0), 0}};
  h.segments = {seg("B1", "P1"), seg("P2", "B1"), seg("B1", "B2"), seg("B2", "P3"), seg("P4", "B2")};
  h.cables = {cable("C1", "P1", "P3", 2), cable("C2", "P2", "P3", 1), cable("C3", "P1", "P4", 3),
              cable("C4", "P1", "P2", 1)};
  return h;
}

TEST(HarnessTopology, ChainsFollowTheTreeWithDirections) {
  Harness h = sample();
  HarnessTopology t(h);
  // C1: P1 -> B1 (segment 0 is B1->P1: reversed), B1 -> B2 (fwd), B2 -> P3 (fwd).
  const auto& c1 = t.cable_chain(0);
  ASSERT_EQ(c1.size(), 3u);
  EXPECT_EQ(c1[0].segment, 0);
  EXPECT_TRUE(c1[0].reversed);
  EXPECT_EQ(c1[1].segment, 2);
  EXPECT_FALSE(c1[1].reversed);
  EXPECT_EQ(c1[2].segment, 3);
  EXPECT_FALSE(c1[2].reversed);
  // C3: P1 -> B1 -> B2 -> P4 (segment 4 is P4->B2: reversed).
  const auto& c3 = t.cable_chain(2);
  ASSERT_EQ(c3.size(), 3u);
  EXPECT_EQ(c3[2].segment, 4);
  EXPECT_TRUE(c3[2].reversed);
  // C4: P1 -> B1 -> P2: segment 1 is P2->B1, travelled B1->P2: reversed.
  const auto& c4 = t.cable_chain(3);
  ASSERT_EQ(c4.size(), 2u);
  EXPECT_EQ(c4[1].segment, 1);
  EXPECT_TRUE(c4[1].reversed);
}

TEST(HarnessTopology, BundlesAndDiameters) {
  Harness h = sample();
  HarnessTopology t(h);
  // Segment 0 (B1-P1) carries C1, C3, C4; segment 2 (B1-B2) carries C1, C2, C3;
  // segment 1 (P2-B1) carries C2, C4; segment 3 (B2-P3) carries C1, C2; segment 4 carries C3.
  EXPECT_EQ(t.segment_cables(0), (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(t.segment_cables(2), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(t.segment_cables(1), (std::vector<int>{1, 3}));
  EXPECT_EQ(t.segment_cables(4), (std::vector<int>{2}));
  EXPECT_NEAR(t.segment_diameter(0), 1.2 * std::sqrt(4 + 9 + 1), 1e-12);
  EXPECT_NEAR(t.segment_diameter(2), 1.2 * std::sqrt(4 + 1 + 9), 1e-12);
  EXPECT_NEAR(t.segment_diameter(1), 1.2 * std::sqrt(1 + 1), 1e-12);
  EXPECT_DOUBLE_EQ(t.segment_diameter(4), 3.0);
  EXPECT_EQ(t.bundles(), (std::vector<int>{0, 1, 2, 3}));
  // Patent order: 3-cable bundles (file order: 0 then 2), 2-cable (1 then 3), singles (4).
  EXPECT_EQ(t.routing_order(), (std::vector<int>{0, 2, 1, 3, 4}));
}

TEST(HarnessTopology, FileDiameterOverridesRule) {
  Harness h = sample();
  h.segments[2].diameter = 9.5;
  HarnessTopology t(h);
  EXPECT_DOUBLE_EQ(t.segment_diameter(2), 9.5);
}

void expect_error(const Harness& h, const std::string& needle) {
  try {
    HarnessTopology t(h);
    FAIL() << "expected InputError containing '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(HarnessTopology, BranchWithTwoConnectionsIsAPassThroughPoint) {
  Harness h = sample();
  h.segments.pop_back();  // B2 now joins only B1 and P3
  h.cables.pop_back();
  h.cables.erase(h.cables.begin() + 2);  // drop C3, which used P4
  HarnessTopology t(h);
  // C1 P1 -> B1 -> B2 -> P3 runs through the pass-through point B2.
  ASSERT_EQ(t.cable_chain(0).size(), 3u);
  EXPECT_EQ(t.incident_segments("B2"), (std::vector<int>{2, 3}));
  const auto notes = t.notes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("branch 'B2' joins 2 nodes: a pass-through point"), std::string::npos) << notes[0];
}

/// Tree path between two nodes by brute force: depth-first search over the segments.
bool dfs_path(const Harness& h, const std::string& at, const std::string& goal, std::vector<int>& used,
              std::vector<int>& path) {
  if (at == goal) return true;
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    if (used[s]) continue;
    const Segment& sg = h.segments[s];
    if (sg.from != at && sg.to != at) continue;
    used[s] = 1;
    path.push_back(static_cast<int>(s));
    if (dfs_path(h, sg.from == at ? sg.to : sg.from, goal, used, path)) return true;
    path.pop_back();
  }
  return false;
}

// Nodes of 4, 8 and 16 segments: two hubs joined by a trunk, N − 1 ports on each; every
// cable's chain is the tree path found by brute force, in order and direction.
TEST(HarnessTopology, NodesOfAnyDegree) {
  for (int n : {4, 8, 16}) {
    Harness h;
    h.source_file = "hubs.xml";
    h.branches = {{"A", Vec3::Zero(), 3}, {"B", Vec3(100, 0, 0), 4}};
    h.segments.push_back(seg("A", "B"));
    for (int i = 0; i < n - 1; ++i) {
      for (const char* hubid : {"A", "B"}) {
        const std::string id = std::string("P") + hubid + std::to_string(i);
        h.ports.push_back(port(id, i));
        h.segments.push_back(i % 2 ? seg(id, hubid) : seg(hubid, id));
      }
    }
    for (int i = 0; i < n - 1; ++i)
      for (int j = 0; j < n - 1; j += 3) {
        h.cables.push_back(cable("CA" + std::to_string(i) + "_" + std::to_string(j), "PA" + std::to_string(i),
                                 "PB" + std::to_string(j), 1));
        if (i != j)
          h.cables.push_back(cable("CS" + std::to_string(i) + "_" + std::to_string(j), "PA" + std::to_string(i),
                                   "PA" + std::to_string(j), 1));
      }
    HarnessTopology t(h);
    EXPECT_EQ(static_cast<int>(t.incident_segments("A").size()), n);
    EXPECT_EQ(t.nodes_by_degree(), (std::map<int, int>{{1, 2 * (n - 1)}, {n, 2}}));
    const auto notes = t.notes();
    ASSERT_EQ(notes.size(), n == 3 ? 0u : 2u);
    EXPECT_NE(notes[0].find("hubs.xml:3 branch 'A' joins " + std::to_string(n) + " nodes"), std::string::npos);
    for (std::size_t c = 0; c < h.cables.size(); ++c) {
      std::vector<int> used(h.segments.size(), 0), path;
      ASSERT_TRUE(dfs_path(h, h.cables[c].ports[0], h.cables[c].ports[1], used, path));
      const auto& chain = t.cable_chain(static_cast<int>(c));
      ASSERT_EQ(chain.size(), path.size()) << h.cables[c].id;
      std::string at = h.cables[c].ports[0];
      for (std::size_t k = 0; k < path.size(); ++k) {
        EXPECT_EQ(chain[k].segment, path[k]);
        const Segment& sg = h.segments[path[k]];
        EXPECT_EQ(chain[k].reversed, sg.to == at) << h.cables[c].id << " step " << k;
        at = sg.from == at ? sg.to : sg.from;
      }
    }
  }
}

TEST(HarnessTopology, Cycle) {
  Harness h = sample();
  h.segments.push_back(seg("P3", "P4"));
  expect_error(h, "cycle");
}

TEST(HarnessTopology, DisconnectedCable) {
  Harness h = sample();
  h.ports.push_back(port("P5", 9));
  h.cables.push_back(cable("C9", "P1", "P5", 1));
  expect_error(h, "not connected");
}

TEST(HarnessTopology, UnknownPortAndNode) {
  Harness h = sample();
  h.cables[0].ports[1] = "NOPE";
  expect_error(h, "unknown port id 'NOPE'");
  Harness h2 = sample();
  h2.segments[0].to = "X";
  expect_error(h2, "unknown node id 'X'");
}

TEST(HarnessTopology, DuplicateIds) {
  Harness h = sample();
  h.ports.push_back(port("P1", 5));
  expect_error(h, "duplicate node id");
  Harness h2 = sample();
  h2.cables.push_back(h2.cables[0]);
  expect_error(h2, "duplicate cable id");
}

TEST(HarnessTopology, EmptyHarness) {
  Harness h;
  HarnessTopology t(h);
  EXPECT_TRUE(t.routing_order().empty());
  EXPECT_TRUE(t.bundles().empty());
}

}  // namespace
}  // namespace loom
