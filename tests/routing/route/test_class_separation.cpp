// Cable classes in planning: the classes each segment carries, the gap between two sets of
// classes, and the places where the topology itself breaks a separation (named before
// planning), on a hand-made harness: a power trunk and a signal branch meeting at a node,
// and a segment carrying both.
#include "routing/route/class_separation.hpp"

#include <gtest/gtest.h>

#include <string>

namespace loom {
namespace {

/// P1 -> N carries two power cables; N -> S1 a signal cable alone; N -> M a power cable and
/// a data cable (a mixed segment); M -> S2 the data cable.
Harness mixed_harness() {
  Harness h;
  h.name = "mixed";
  h.source_file = "mixed.xml";
  for (const char* p : {"P1", "S1", "M1", "S2"}) h.ports.push_back({p, {0, 0, 0}, {1, 0, 0}, 1});
  h.branches.push_back({"N", Vec3(1, 0, 0), 2});
  h.branches.push_back({"M", Vec3(2, 0, 0), 3});
  auto seg = [&](const char* a, const char* b) {
    Segment s;
    s.from = a;
    s.to = b;
    h.segments.push_back(s);
  };
  seg("P1", "N");
  seg("N", "S1");
  seg("N", "M");
  seg("M", "M1");
  seg("M", "S2");
  auto cable = [&](const char* id, const char* a, const char* b, const char* cls) {
    Cable c;
    c.id = id;
    c.ports[0] = a;
    c.ports[1] = b;
    c.physical.diameter = 2.0;
    c.physical.cable_class = cls;
    h.cables.push_back(c);
  };
  cable("W1", "P1", "S1", "power");
  cable("W2", "P1", "M1", "power");
  cable("W3", "S1", "S2", "data");
  return h;
}

TEST(ClassSeparation, SegmentClassesAndGaps) {
  const Harness h = mixed_harness();
  const HarnessTopology topo(h);
  const auto cls = segment_classes(topo);
  ASSERT_EQ(cls.size(), 5u);
  EXPECT_EQ(cls[0], (std::set<std::string>{"power"}));          // P1 - N
  EXPECT_EQ(cls[1], (std::set<std::string>{"data", "power"}));  // N - S1: W1 and W3
  EXPECT_EQ(cls[2], (std::set<std::string>{"data", "power"}));  // N - M: W2 and W3
  EXPECT_EQ(cls[4], (std::set<std::string>{"data"}));           // M - S2
  RoutingSettings r;
  EXPECT_EQ(class_gap(r, cls[0], cls[4]), 0.0);  // no separation given
  r.separation[{"data", "power"}] = 40.0;
  r.separation[{"data", "signal"}] = 10.0;
  EXPECT_EQ(class_gap(r, cls[0], cls[4]), 40.0);
  EXPECT_EQ(class_gap(r, cls[0], cls[0]), 0.0);  // one class: never kept from itself
  EXPECT_EQ(class_gap(r, {"signal"}, cls[1]), 10.0);
  EXPECT_EQ(class_gap(r, {}, cls[1]), 0.0);
}

TEST(ClassSeparation, ConflictsOfTheTopologyAreNamed) {
  const Harness h = mixed_harness();
  const HarnessTopology topo(h);
  RoutingSettings r;
  EXPECT_TRUE(separation_conflicts(topo, r, segment_classes(topo)).empty());
  r.separation[{"data", "power"}] = 40.0;
  const auto lines = separation_conflicts(topo, r, segment_classes(topo));
  // Two mixed segments, and the nodes where a power-only and a data-only segment meet (M:
  // N - M is mixed, M - M1 power, M - S2 data; N: P1 - N power, N - S1 mixed); S1 joins one
  // segment and is not named.
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "segment N -> S1 carries classes data and power, which [routing.separation] keeps 40 apart: "
                      "the audit reports segregation along it (give each class its own segments)");
  EXPECT_NE(lines[1].find("segment N -> M carries classes data and power"), std::string::npos);
  EXPECT_NE(lines[2].find("node N joins segments of classes data and power"), std::string::npos);
  EXPECT_NE(lines[3].find("node M joins segments of classes data and power"), std::string::npos);
}

}  // namespace
}  // namespace loom
