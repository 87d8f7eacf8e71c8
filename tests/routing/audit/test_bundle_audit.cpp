// The bundle-level certified audit against the per-cable one (ClashRequest::per_cable, the
// reference): the same findings to the tolerance on random generated harnesses with and
// without structure (rapidcheck, fixed seed), and on hand-made cases — a trunk touching a
// plate, two trunks crossing, a cable leaving its bundle into another, a trunk folding on
// itself, parts attached to ports.
#include "bench/audit_compare.hpp"
#include "bench/harness_gen.hpp"
#include "common/run_loom.hpp"
#include "core/io/harness_xml.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/audit/audit.hpp"
#include "routing/audit/clash_check.hpp"

#include "core/harness_topology.hpp"
#include "index/embree_index.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>

namespace loom {

/// Both audits of the harness among `parts` (2 threads), and what they were given.
struct Both {
  std::vector<CableInput> cables;
  std::vector<Part> parts;
  std::unique_ptr<EmbreeIndex> index;
  ClashResult ref, bundle;
};

Both audit_both(const Harness& h, const std::vector<Part>& parts, double clearance = 3.0) {
  Both b;
  std::vector<AuditCable> ac;
  b.cables = audit_cable_inputs(h, ac);
  b.parts = parts;
  b.index = std::make_unique<EmbreeIndex>(b.parts);
  attach_ports(h, b.parts, clearance, b.cables, b.index.get());
  ClashRequest req;
  req.routing_clearance = clearance;
  req.threads = 2;
  req.per_cable = true;
  b.ref = check_clashes(b.cables, b.parts, b.index.get(), req);
  req.per_cable = false;
  b.bundle = check_clashes(b.cables, b.parts, b.index.get(), req);
  return b;
}

/// The exact clearance of a cable to a part at arc length s: the index's closest point on
/// that part, −r with the centerline inside it.
bench::ClearanceOracle oracle_of(const Both& b) {
  return [&b](int cable, int part, double s) {
    const CableInput& c = b.cables[static_cast<std::size_t>(cable)];
    const Vec3 p = c.curve.position(c.curve.parameter_at_length(s));
    std::vector<int> inside;
    b.index->inside_parts(p, inside);
    if (std::find(inside.begin(), inside.end(), part) != inside.end()) return -c.radius;
    return b.index->closest_on_part(p, part).distance - c.radius;
  };
}

/// The differences between the two audits, one per line (empty: the same findings).
std::string differences(const Both& b) {
  std::string out;
  for (const auto& p : bench::compare_findings(b.ref, b.bundle, b.cables, oracle_of(b)).problems) out += p + "\n";
  return out;
}

/// A random small harness (seeded): 2–7 trunk branch points, 0–7 in side trees, 4–40 wires,
/// with 0–30 parts placed `standoff` from the routes (negative: through them).
struct RandomCase {
  Harness harness;
  std::vector<Part> parts;
};

RandomCase random_case(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  bench::HarnessShape shape;
  shape.spine_branches = 2 + static_cast<int>(U(rng) * 6);
  shape.side_branches = static_cast<int>(U(rng) * 8);
  shape.wires = 4 + static_cast<int>(U(rng) * 37);
  shape.spacing = 30.0 + 60.0 * U(rng);
  shape.min_wire = 100.0;
  shape.max_wire = 3000.0;
  shape.seed = seed;
  shape.max_degree = 3 + static_cast<int>(U(rng) * 14);  // dense nodes of 3 to 16 segments
  shape.dense_every = 1 + static_cast<int>(U(rng) * 4);
  RandomCase rc;
  rc.harness = bench::generate_harness(shape).harness;
  const int n_parts = static_cast<int>(U(rng) * 31);
  const double standoff = -30.0 + 50.0 * U(rng);
  if (n_parts > 0) rc.parts = bench::harness_structure(rc.harness, n_parts, 300, seed + 1, standoff);
  return rc;
}

RC_GTEST_PROP(BundleAudit, RandomHarnessesGiveThePerCableFindings, ()) {
  const auto seed = *rc::gen::inRange<std::uint32_t>(0, 1u << 30);
  const RandomCase rc = random_case(seed);
  const Both b = audit_both(rc.harness, rc.parts);
  RC_ASSERT(b.bundle.bundle_level);
  RC_TAG(b.ref.clashes.empty() ? "no clash" : "clashes", b.ref.violations.empty() ? "no violation" : "violations");
  const std::string diff = differences(b);
  if (!diff.empty()) RC_LOG() << "seed " << seed << ":\n" << diff;
  RC_ASSERT(diff.empty());
}

// ---------------------------------------------------------------------------------------
// Hand-made harnesses: straight segments between nodes (polylines through no key point),
// so that distances have closed forms.

/// A harness built node by node.
struct HandHarness {
  Harness h;
  void port(const std::string& id, const Vec3& at, const Vec3& exit) {
    Port p;
    p.id = id;
    p.position = at;
    p.direction = exit.normalized();
    h.ports.push_back(p);
  }
  void branch(const std::string& id, const Vec3& at) {
    BranchPoint b;
    b.id = id;
    b.position = at;
    h.branches.push_back(b);
  }
  void segment(const std::string& from, const std::string& to, std::vector<Vec3> path = {},
               Interp interp = Interp::Polyline) {
    Segment s;
    s.from = from;
    s.to = to;
    s.path = std::move(path);
    s.interp = interp;
    h.segments.push_back(s);
  }
  void cable(const std::string& id, const std::string& a, const std::string& b, double diameter) {
    Cable c;
    c.id = id;
    c.ports[0] = a;
    c.ports[1] = b;
    c.physical.diameter = diameter;
    c.physical.min_bend_radius = 3.0 * diameter;
    h.cables.push_back(c);
  }
  /// A trunk from branch `p`A at `a` to `p`B at `b`, fanned out at each end to three ports
  /// (`p`L0..2 and `p`R0..2) 40–80 along and 40 across `side` (a unit vector ⊥ the trunk).
  void trunk(const std::string& p, const Vec3& a, const Vec3& b, const Vec3& side) {
    const Vec3 t = (b - a).normalized();
    branch(p + "A", a);
    branch(p + "A2", a - 40.0 * t + 40.0 * side);
    port(p + "L0", a - 40.0 * t - 40.0 * side, t + side);
    port(p + "L1", a - 80.0 * t + 60.0 * side, 2.0 * t - side);
    port(p + "L2", a - 80.0 * t + 20.0 * side, 2.0 * t + side);
    segment(p + "L0", p + "A");
    segment(p + "A2", p + "A");
    segment(p + "L1", p + "A2");
    segment(p + "L2", p + "A2");
    branch(p + "B", b);
    branch(p + "B2", b + 40.0 * t + 40.0 * side);
    port(p + "R0", b + 40.0 * t - 40.0 * side, -t + side);
    port(p + "R1", b + 80.0 * t + 60.0 * side, -2.0 * t - side);
    port(p + "R2", b + 80.0 * t + 20.0 * side, -2.0 * t + side);
    segment(p + "B", p + "R0");
    segment(p + "B", p + "B2");
    segment(p + "B2", p + "R1");
    segment(p + "B2", p + "R2");
    segment(p + "A", p + "B");
  }
  /// `n` cables along trunk `p`, between its left and right ports in turn, diameters from
  /// `d` in turn; ids `p`0, `p`1, ...
  void trunk_cables(const std::string& p, int n, const std::vector<double>& d) {
    for (int i = 0; i < n; ++i)
      cable(p + std::to_string(i), p + "L" + std::to_string(i % 3), p + "R" + std::to_string((i / 3) % 3),
            d[static_cast<std::size_t>(i) % d.size()]);
  }
};

/// Three ports L0, L1, L2 left of the origin gathered into node A at the origin (through
/// branch point A2): the start of a trunk that leaves A.
void add_left_fan(HandHarness& hh) {
  hh.branch("A", {0, 0, 0});
  hh.branch("A2", {-40, 40, 0});
  hh.port("L0", {-40, -40, 0}, {1, 1, 0});
  hh.port("L1", {-80, 60, 0}, {2, -1, 0});
  hh.port("L2", {-80, 20, 0}, {2, 1, 0});
  hh.segment("L0", "A");
  hh.segment("A2", "A");
  hh.segment("L1", "A2");
  hh.segment("L2", "A2");
}

const std::vector<double> kDiameters{1.2, 2.0, 3.0, 1.6, 2.6};

/// The per-cable and bundle audits agree (compare_findings, with the oracle).
void expect_same(const Both& b) {
  EXPECT_TRUE(b.bundle.bundle_level);
  EXPECT_FALSE(b.ref.bundle_level);
  EXPECT_EQ(differences(b), "");
}

/// Findings of one cable with one part (clashes and clearance violations), in s order.
std::vector<double> structure_values(const ClashResult& r, int cable, int part) {
  std::vector<double> out;
  for (const auto& e : r.clashes)
    if (e.kind == ClashKind::CableStructure && e.cable == cable && e.part == part) out.push_back(e.clearance);
  for (const auto& v : r.violations)
    if (v.kind == ViolationKind::Clearance && v.cable == cable && v.part == part) out.push_back(v.value);
  return out;
}

TEST(BundleAudit, ATrunkTouchingAPlate) {
  // A trunk along x at z = 0 over a plate whose top is 0.9 below its axis: each cable's
  // clearance there is 0.9 − r (a clash for r > 0.9, a violation of the 3.0 required below).
  HandHarness hh;
  hh.trunk("T", {-100, 0, 0}, {100, 0, 0}, Vec3::UnitY());
  hh.trunk_cables("T", 10, kDiameters);
  const std::vector<Part> parts{testmesh::box_part("plate", {-40, -30, -20}, {40, 30, -0.9})};
  const Both b = audit_both(hh.h, parts);
  expect_same(b);
  for (const ClashResult* r : {&b.ref, &b.bundle})
    for (std::size_t c = 0; c < b.cables.size(); ++c) {
      const std::vector<double> v = structure_values(*r, static_cast<int>(c), 0);
      ASSERT_EQ(v.size(), 1u) << b.cables[c].id;
      EXPECT_NEAR(v[0], std::max(0.0, 0.9 - b.cables[c].radius) + std::min(0.0, 0.9 - b.cables[c].radius), r->tolerance)
          << b.cables[c].id;
    }
}

TEST(BundleAudit, ATrunkThroughAWall) {
  // The plate stands across the trunk: every cable runs through it (inside: clearance −r).
  HandHarness hh;
  hh.trunk("T", {-100, 0, 0}, {100, 0, 0}, Vec3::UnitY());
  hh.trunk_cables("T", 10, kDiameters);
  const std::vector<Part> parts{testmesh::box_part("wall", {-2, -30, -30}, {2, 30, 30})};
  const Both b = audit_both(hh.h, parts);
  expect_same(b);
  for (std::size_t c = 0; c < b.cables.size(); ++c) {
    const std::vector<double> v = structure_values(b.bundle, static_cast<int>(c), 0);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_NEAR(v[0], -b.cables[c].radius, b.bundle.tolerance);
  }
}

TEST(BundleAudit, TwoTrunksCrossing) {
  // Trunks along x (z = 0) and along y (z = 2.5) cross at the origin: cables a, b of
  // different trunks clash there, at 2.5 − r_a − r_b, exactly when r_a + r_b > 2.5.
  HandHarness hh;
  hh.trunk("X", {-100, 0, 0}, {100, 0, 0}, Vec3::UnitY());
  hh.trunk("Y", {0, -100, 2.5}, {0, 100, 2.5}, Vec3::UnitX());
  hh.trunk_cables("X", 9, kDiameters);
  hh.trunk_cables("Y", 8, {3.0, 1.2, 2.2});
  const Both b = audit_both(hh.h, {});
  expect_same(b);
  std::map<std::pair<int, int>, double> expected;
  for (std::size_t i = 0; i < 9; ++i)
    for (std::size_t j = 9; j < b.cables.size(); ++j) {
      const double cl = 2.5 - b.cables[i].radius - b.cables[j].radius;
      if (cl < 0.0) expected[{static_cast<int>(i), static_cast<int>(j)}] = cl;
    }
  ASSERT_FALSE(expected.empty());
  for (const ClashResult* r : {&b.ref, &b.bundle}) {
    std::map<std::pair<int, int>, double> found;
    for (const auto& e : r->clashes) {
      ASSERT_EQ(e.kind, ClashKind::CableCable);
      EXPECT_TRUE(found.emplace(std::make_pair(e.cable, e.other), e.clearance).second) << "one stretch per pair";
    }
    ASSERT_EQ(found.size(), expected.size());
    for (const auto& [pair, cl] : expected) {
      ASSERT_TRUE(found.count(pair)) << b.cables[static_cast<std::size_t>(pair.first)].id << " / "
                                     << b.cables[static_cast<std::size_t>(pair.second)].id;
      EXPECT_NEAR(found[pair], cl, r->tolerance);
    }
  }
}

TEST(BundleAudit, ACableLeavingItsBundleIntoAnother) {
  // Trunk A→B along x; at B its cables part: some go on along x to C, others into a second
  // bundle that climbs and crosses the first 2 above its axis at x = 250. Cables that shared
  // the trunk and the node B clash at the crossing (not within B's breakout), by radii.
  HandHarness hh;
  add_left_fan(hh);
  hh.branch("B", {100, 0, 0});
  hh.segment("A", "B");
  hh.branch("C", {400, 0, 0});
  hh.segment("B", "C");
  hh.port("C0", {440, -40, 0}, {-1, 1, 0});
  hh.port("C1", {440, 40, 0}, {-1, -1, 0});
  hh.segment("C", "C0");
  hh.segment("C", "C1");
  // The second bundle: up from B, then over the first at x = 250, z = 2, then away in y.
  hh.branch("D", {250, 100, 2});
  hh.segment("B", "D", {{150, 0, 40}, {250, -100, 40}, {250, -60, 2}});
  hh.port("D0", {290, 140, 2}, {-1, -1, 0});
  hh.port("D1", {210, 140, 2}, {1, -1, 0});
  hh.segment("D", "D0");
  hh.segment("D", "D1");
  const char* lefts[] = {"L0", "L1", "L2"};
  const char* rights[] = {"C0", "C1", "D0", "D1"};
  for (int i = 0; i < 12; ++i)
    hh.cable("W" + std::to_string(i), lefts[i % 3], rights[i % 4], kDiameters[static_cast<std::size_t>(i) % kDiameters.size()]);
  const Both b = audit_both(hh.h, {});
  expect_same(b);
  // Cables to C0/C1 against cables to D0/D1, at the crossing only.
  std::set<std::pair<int, int>> expected;
  for (int i = 0; i < 12; ++i)
    for (int j = i + 1; j < 12; ++j)
      if ((i % 4 < 2) != (j % 4 < 2) && b.cables[static_cast<std::size_t>(i)].radius + b.cables[static_cast<std::size_t>(j)].radius > 2.0)
        expected.insert({i, j});
  ASSERT_FALSE(expected.empty());
  for (const ClashResult* r : {&b.ref, &b.bundle}) {
    std::set<std::pair<int, int>> found;
    for (const auto& e : r->clashes) {
      if (e.kind != ClashKind::CableCable) continue;
      EXPECT_NEAR(e.point.x(), 250.0, 1.0);
      found.insert({e.cable, e.other});
    }
    EXPECT_EQ(found, expected);
  }
}

TEST(BundleAudit, ATrunkFoldedOnItself) {
  // The trunk turns back on itself in a hairpin whose legs lie 2.2 apart: every cable
  // thicker than 2.2 has one self clash at 2.2 − 2r; cables of the trunk never clash with
  // each other there (bundled); the hairpin bends tighter than any cable may.
  HandHarness hh;
  add_left_fan(hh);
  hh.branch("B", {0, 0, 2.2});
  std::vector<Vec3> hairpin;
  for (int k = 1; k <= 20; ++k) hairpin.emplace_back(10.0 * k, 0, 0);
  for (int k = 0; k <= 10; ++k) {
    const double a = M_PI * k / 10;
    hairpin.emplace_back(200.0 + 1.1 * std::sin(a), 0, 1.1 - 1.1 * std::cos(a));
  }
  for (int k = 19; k >= 1; --k) hairpin.emplace_back(10.0 * k, 0, 2.2);
  hh.segment("A", "B", hairpin);
  hh.port("R0", {-40, -40, 42.2}, {1, 1, -1});
  hh.port("R1", {-40, 40, 42.2}, {1, -1, -1});
  hh.segment("B", "R0");
  hh.segment("B", "R1");
  for (int i = 0; i < 10; ++i)
    hh.cable("W" + std::to_string(i), i % 3 == 0 ? "L0" : i % 3 == 1 ? "L1" : "L2", i % 2 ? "R0" : "R1",
             kDiameters[static_cast<std::size_t>(i) % kDiameters.size()]);
  const Both b = audit_both(hh.h, {});
  expect_same(b);
  for (const ClashResult* r : {&b.ref, &b.bundle}) {
    std::map<int, double> deepest;
    for (const auto& e : r->clashes) {
      ASSERT_EQ(e.kind, ClashKind::Self) << "bundled cables never clash with each other";
      deepest[e.cable] = std::min(deepest.count(e.cable) ? deepest[e.cable] : 0.0, e.clearance);
    }
    for (std::size_t c = 0; c < b.cables.size(); ++c) {
      const double depth = 2.2 - 2.0 * b.cables[c].radius;
      if (depth < -r->tolerance) {
        ASSERT_TRUE(deepest.count(static_cast<int>(c))) << b.cables[c].id;
        EXPECT_NEAR(deepest[static_cast<int>(c)], depth, r->tolerance);
      } else if (depth > r->tolerance) {
        EXPECT_FALSE(deepest.count(static_cast<int>(c))) << b.cables[c].id;
      }
    }
    int bends = 0;
    for (const auto& v : r->violations) bends += v.kind == ViolationKind::BendRadius;
    EXPECT_GE(bends, 10);
  }
}

TEST(BundleAudit, PortsOnAConnector) {
  // The left ports sit on a connector block, which is excused over each cable's exit; the
  // shared pieces next to it are measured by the cables themselves.
  HandHarness hh;
  hh.trunk("T", {-100, 0, 0}, {100, 0, 0}, Vec3::UnitY());
  hh.trunk_cables("T", 10, kDiameters);
  const std::vector<Part> parts{testmesh::box_part("connector", {-190, -50, -10}, {-140, 70, 10}),
                                testmesh::box_part("bracket", {-20, -10, -8}, {20, 10, -2})};
  const Both b = audit_both(hh.h, parts);
  std::size_t attached = 0;
  for (const auto& c : b.cables) attached += c.attachments.size();
  EXPECT_GT(attached, 0u);
  expect_same(b);
}

TEST(BundleAudit, CablesSharingNoPieceAreCheckedPerCable) {
  HandHarness hh;
  hh.port("P0", {0, 0, 0}, {1, 0, 0});
  hh.port("P1", {100, 0, 0}, {-1, 0, 0});
  hh.port("P2", {50, -50, 1}, {0, 1, 0});
  hh.port("P3", {50, 50, 1}, {0, -1, 0});
  hh.segment("P0", "P1");
  hh.segment("P2", "P3");
  hh.cable("W0", "P0", "P1", 2.0);
  hh.cable("W1", "P2", "P3", 2.0);
  const Both b = audit_both(hh.h, {});
  EXPECT_FALSE(b.bundle.bundle_level);
  EXPECT_EQ(differences(b), "");
  ASSERT_EQ(b.bundle.clashes.size(), 1u);
  EXPECT_NEAR(b.bundle.clashes[0].clearance, -1.0, b.bundle.tolerance);
}

TEST(BundleAudit, PairTestsDoNotGrowWithTheCablesPerTrunk) {
  // The same trunk with 12 and with 120 cables (the same diameters): the bundle level
  // measures the same chord pairs; the per-cable audit's grow with the pairs of cables.
  std::int64_t tests[2] = {0, 0}, ref_tests[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    HandHarness hh;
    hh.trunk("T", {-100, 0, 0}, {100, 0, 0}, Vec3::UnitY());
    hh.trunk_cables("T", k == 0 ? 12 : 120, {1.2, 2.0, 3.0});
    const Both b = audit_both(hh.h, {});
    expect_same(b);
    tests[k] = b.bundle.counters.pair_tests;
    ref_tests[k] = b.ref.counters.pair_tests;
  }
  EXPECT_EQ(tests[0], tests[1]);
  EXPECT_GT(ref_tests[1], 20 * ref_tests[0]);
}

TEST(BundleAuditCli, PerCableFlagGivesTheSameReport) {
  // Two crossing trunks written as a harness file: `loom audit` at the bundle level (the
  // default) and with --per-cable report the same clashes.
  HandHarness hh;
  hh.trunk("X", {-100, 0, 0}, {100, 0, 0}, Vec3::UnitY());
  hh.trunk("Y", {0, -100, 2.5}, {0, 100, 2.5}, Vec3::UnitX());
  hh.trunk_cables("X", 9, kDiameters);
  hh.trunk_cables("Y", 8, {3.0, 1.2, 2.2});
  const std::filesystem::path dir = std::filesystem::path(LOOM_BINARY_DIR) / "test_bundle_audit_cli";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  write_harness_xml(hh.h, dir / "harness.xml");
  std::ofstream(dir / "scene.toml") << "[scene]\nname = \"crossing\"\nunits = \"mm\"\n\n[harness]\nfile = \"harness.xml\"\n";
  nlohmann::json reports[2];
  for (int k = 0; k < 2; ++k) {
    const std::string out = (dir / (k ? "per-cable" : "bundle")).string();
    const auto r = testing::run_loom("audit " + (dir / "scene.toml").string() + (k ? " --per-cable" : "") +
                                     " --quiet --threads 2 --render-size 64x48 --out " + out);
    ASSERT_EQ(r.status, 1) << r.out;
    reports[k] = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  }
  const auto& a = reports[0]["clashes"];
  const auto& b = reports[1]["clashes"];
  ASSERT_GT(a.size(), 0u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i]["cable"], b[i]["cable"]);
    EXPECT_EQ(a[i]["other"], b[i]["other"]);
    EXPECT_NEAR(a[i]["clearance"].get<double>(), b[i]["clearance"].get<double>(), 2.0 * reports[0]["tolerance"].get<double>());
  }
  // The flag is the certified method's: refused with the discrete one, before any output.
  const auto bad = testing::run_loom("audit " + (dir / "scene.toml").string() + " --per-cable --method discrete --out " +
                                     (dir / "refused").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.out.find("--per-cable"), std::string::npos) << bad.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "refused"));
}

}  // namespace loom
