// Branch-point placement and exit directions (routing/branch_layout): placed points are
// clear, can turn into their connectors within the bend radius, and are no longer than a
// brute-force grid search over the same constraints finds; cables never fold back at a node.
#include "routing/route/branch_layout.hpp"

#include "core/error.hpp"
#include "index/brute_force_index.hpp"
#include "index/embree_index.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "routing/route/path_planner.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>

namespace {

using namespace loom;

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

Cable cable(const std::string& id, const std::string& a, const std::string& b, double d, double bend) {
  Cable c;
  c.id = id;
  c.ports[0] = a;
  c.ports[1] = b;
  c.physical.diameter = d;
  c.physical.min_bend_radius = bend;
  return c;
}

/// The wing section's K3 in miniature: a trunk from a fixed T-junction at the origin up to
/// an unplaced branch K, which splits to two connectors 60 mm apart facing down (−y) at
/// y = 133. The geometric median sits too close to the connectors for a 30 mm bend radius.
Harness fork(bool place_k) {
  Harness h;
  h.name = "fork";
  h.ports = {{"ROOT", Vec3(-200, 0, 0), Vec3::UnitX(), 0},
             {"TIP", Vec3(200, 0, 0), -Vec3::UnitX(), 0},
             {"A", Vec3(-30, 133, 0), -Vec3::UnitY(), 0},
             {"B", Vec3(30, 133, 0), -Vec3::UnitY(), 0}};
  h.branches = {{"T", Vec3(0, 0, 0), 0}, {"K", std::nullopt, 0}};
  if (place_k) h.branches[1].position = Vec3(0, 60, 0);
  for (const auto& [from, to] : {std::pair{"T", "ROOT"}, {"T", "TIP"}, {"T", "K"}, {"K", "A"}, {"K", "B"}}) {
    Segment s;
    s.from = from;
    s.to = to;
    h.segments.push_back(s);
  }
  h.cables = {cable("W1", "ROOT", "A", 3, 30), cable("W2", "ROOT", "B", 3, 30), cable("W3", "A", "TIP", 3, 20),
              cable("W4", "B", "TIP", 3, 20), cable("W5", "ROOT", "TIP", 3, 20), cable("W6", "ROOT", "TIP", 3, 20)};
  return h;
}

std::vector<SegmentEnds> ends_of(const HarnessTopology& topo) { return segment_ends(topo, derived_stub_length); }

/// Independent restatement of the bend rule the placement must meet: a leg from branch point
/// q to a port turns at the port's stub end S by θ into the connector axis and needs
/// R·tan(θ/2) of straight run on both sides (the stub; the leg after the breakout run).
double bend_deficit(const Harness& h, const HarnessTopology& topo, const std::vector<SegmentEnds>& ends,
                    const std::string& branch, const Vec3& q) {
  double deficit = 0.0;
  for (int s : topo.incident_segments(branch)) {
    const Segment& sg = h.segments[s];
    const int p = h.find_port(sg.from == branch ? sg.to : sg.from);
    if (p < 0) continue;
    const Vec3 stub_end = h.ports[p].position + ends[s].port_stub * h.ports[p].direction;
    const double need = ends[s].min_bend_radius * std::tan(0.5 * angle(stub_end - q, -h.ports[p].direction));
    deficit += std::max(0.0, need - ends[s].port_stub) +
               std::max(0.0, need + breakout_length(topo, branch) - (stub_end - q).norm());
  }
  return deficit;
}

double leg_sum(const Harness& h, const HarnessTopology& topo, const std::vector<SegmentEnds>& ends,
               const std::string& branch, const Vec3& q) {
  double sum = 0.0;
  for (int s : topo.incident_segments(branch)) {
    const Segment& sg = h.segments[s];
    const std::string& other = sg.from == branch ? sg.to : sg.from;
    Vec3 target = *h.node_position(other);
    if (int p = h.find_port(other); p >= 0) target += ends[s].port_stub * h.ports[p].direction;
    sum += (target - q).norm();
  }
  return sum;
}

BranchPlacementOptions options_with_clearance(double c) {
  BranchPlacementOptions o;
  o.clearance_of = [c](int) { return c; };
  return o;
}

TEST(BranchLayout, PlacedForkTurnsIntoItsConnectorsAndIsAsShortAsABruteForceGrid) {
  Harness h = fork(false);
  const HarnessTopology topo(h);
  const auto ends = ends_of(topo);
  const BruteForceIndex empty({});
  const auto placed = place_branch_points(h, topo, empty, ends, options_with_clearance(5.0));
  ASSERT_EQ(placed, std::vector<std::string>{"K"});
  const Vec3 k = *h.branches[1].position;
  EXPECT_NEAR(bend_deficit(h, topo, ends, "K", k), 0.0, 1e-6) << "K at " << k.transpose();
  // Brute force: the shortest bend-feasible point on a 1 mm grid of the plane z = 0 (the
  // problem is planar and symmetric, so the optimum lies in it).
  double best = std::numeric_limits<double>::infinity();
  Vec3 best_q = Vec3::Zero();
  for (double x = -60; x <= 60; x += 1.0)
    for (double y = -20; y <= 140; y += 1.0) {
      const Vec3 q(x, y, 0);
      if (bend_deficit(h, topo, ends, "K", q) > 0.0) continue;
      const double len = leg_sum(h, topo, ends, "K", q);
      if (len < best) best = len, best_q = q;
    }
  ASSERT_TRUE(std::isfinite(best));
  EXPECT_LE(leg_sum(h, topo, ends, "K", k), best + 2.0) << "grid optimum at " << best_q.transpose();
  // The plain geometric median is not feasible here: the bend rule is what moved K.
  Harness median = fork(false);
  BranchPlacementOptions no_bend = options_with_clearance(5.0);
  no_bend.bend_deficit_weight = 0.0;
  place_branch_points(median, topo, empty, ends, no_bend);
  EXPECT_GT(bend_deficit(h, topo, ends, "K", *median.branches[1].position), 1.0);
}

TEST(BranchLayout, PlacedPointKeepsItsClearanceFromABlockAtTheMedian) {
  Harness h = fork(false);
  const HarnessTopology topo(h);
  const auto ends = ends_of(topo);
  // A block where the unconstrained optimum would be.
  const std::vector<Part> parts = {loom::testmesh::make_part("block", loom::testmesh::box(Vec3(-30, 40, -30), Vec3(30, 90, 30)), true)};
  const EmbreeIndex index(parts);
  const double need = 6.0;
  place_branch_points(h, topo, index, ends, options_with_clearance(need));
  const Vec3 k = *h.branches[1].position;
  EXPECT_FALSE(index.inside(k));
  EXPECT_FALSE(index.any_within(k, need)) << "K at " << k.transpose();
}

TEST(BranchLayout, NoClearPlaceIsAnInputErrorNamingTheBranch) {
  Harness h = fork(false);
  h.source_file = "fork.xml";
  const HarnessTopology topo(h);
  const auto ends = ends_of(topo);
  // Everything around the neighbours is solid.
  const std::vector<Part> parts = {loom::testmesh::make_part("slab", loom::testmesh::box(Vec3(-5000, -5000, -5000), Vec3(5000, 5000, 5000)), true)};
  const EmbreeIndex index(parts);
  try {
    place_branch_points(h, topo, index, ends, options_with_clearance(5.0));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("branch 'K'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fork.xml"), std::string::npos) << e.what();
  }
}

TEST(BranchLayout, MainLineIsSmoothAndTheSideLegLeavesAsATee) {
  const Harness h = fork(true);
  const HarnessTopology topo(h);
  const auto dirs = branch_exit_directions(h, topo, ends_of(topo));
  // At T: ROOT and TIP are a straight line (most cables pass between them), K is the side leg.
  const Vec3 root = dirs.at({0, true}), tip = dirs.at({1, true}), side = dirs.at({2, true});
  EXPECT_NEAR((root + tip).norm(), 0.0, 1e-12);
  EXPECT_NEAR(angle(root, -Vec3::UnitX()), 0.0, 1e-12);
  // Cables pass from K to both ROOT and TIP: the side leg is normal to the main line.
  EXPECT_NEAR(side.dot(root), 0.0, 1e-12);
  EXPECT_GT(side.dot(Vec3::UnitY()), 0.99);
}

/// Every pair of segments that shares a cable at a node leaves it at least 90° apart, for
/// random node layouts: no cable folds back on itself at a branch point.
RC_GTEST_PROP(BranchLayoutProperty, CablesNeverFoldBackAtANode, ()) {
  const auto coord = [] { return *rc::gen::inRange(-100, 101) * 1.0; };
  Harness h = fork(true);
  for (auto& p : h.ports) {
    p.position = Vec3(coord(), coord(), coord());
    Vec3 d(coord(), coord(), coord());
    RC_PRE(d.norm() > 1.0);
    p.direction = d.normalized();
  }
  h.branches[1].position = Vec3(coord(), coord(), coord());
  const HarnessTopology topo(h);
  const auto dirs = branch_exit_directions(h, topo, ends_of(topo));
  for (std::size_t c = 0; c < h.cables.size(); ++c) {
    const auto& chain = topo.cable_chain(static_cast<int>(c));
    for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
      const Segment& a = h.segments[chain[k].segment];
      const Segment& b = h.segments[chain[k + 1].segment];
      const std::string& node = chain[k].reversed ? a.from : a.to;
      const Vec3 ea = dirs.at({chain[k].segment, a.from == node});
      const Vec3 eb = dirs.at({chain[k + 1].segment, b.from == node});
      RC_ASSERT(std::abs(ea.norm() - 1.0) < 1e-9);
      RC_ASSERT(ea.dot(eb) <= 1e-9);
    }
  }
}

}  // namespace
