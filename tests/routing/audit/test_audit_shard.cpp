// Sharded audit, in one process: the parts of a scene divided among K = 1..4 shards by
// plan_shards, each shard audited on its own parts (the non-first through the wire
// format), the reports merged — against the audit of the whole scene. The scene has what
// every merge rule needs: clashes with structure and keep-out zones, clearance shortfalls,
// bundled cables (bundle level), clamps over structure and over gaps, a moving part.
#include "routing/audit/audit_shard.hpp"
#include "routing/audit/shard_plan.hpp"
#include "common/support_fixtures.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace loom {
namespace {

using test::box_part;

/// 24 boxes over a 1000 × 1000 mm floor, 0–200 mm high (every fifth a keep-out zone),
/// one of them rotating about z.
std::vector<Part> scattered_boxes() {
  std::mt19937 rng(7);
  auto u = [&](double lo, double hi) { return lo + (hi - lo) * (static_cast<double>(rng()) / rng.max()); };
  std::vector<Part> parts;
  for (int k = 0; k < 24; ++k) {
    const Vec3 lo(u(0, 950), u(0, 950), u(40, 160));
    const Vec3 hi = lo + Vec3(u(20, 80), u(20, 80), u(20, 60));
    parts.push_back(box_part("box-" + std::to_string(k), lo, hi, k % 5 == 4 ? PartRole::KeepOut : PartRole::Structure));
  }
  // A floor plate to clamp to, and a door swinging over the cables' way.
  parts.push_back(box_part("floor", {0, 0, 0}, {1000, 1000, 10}));
  Part door = box_part("door", {600, 560, 60}, {640, 700, 140});
  Motion m;
  m.kind = MotionKind::Rotate;
  m.axis_point = {600, 560, 0};
  m.axis = Vec3::UnitZ();
  m.from = 0;
  m.to = 60;
  door.motion = m;
  parts.push_back(door);
  return parts;
}

/// A Y harness A → N → {B, C} with 3 + 2 cables, and a single cable D → E across the floor;
/// clamps every 150 mm along the trunk and the single cable.
Harness y_harness() {
  Harness h;
  h.name = "y";
  h.source_file = "y.xml";
  h.ports = {{"A", {0, 500, 100}, {1, 0, 0}, 1},    {"B", {1000, 200, 100}, {-1, 0, 0}, 2},
             {"C", {1000, 800, 100}, {-1, 0, 0}, 3}, {"D", {500, 0, 30}, {0, 1, 0}, 4},
             {"E", {500, 1000, 30}, {0, -1, 0}, 5}};
  h.branches.push_back({"N", Vec3(500, 500, 100), 6});
  auto seg = [&](const char* from, const char* to, std::vector<Vec3> path) {
    Segment s;
    s.from = from, s.to = to, s.path = std::move(path), s.interp = Interp::BSpline;
    h.segments.push_back(s);
  };
  seg("A", "N", {{200, 450, 110}, {350, 520, 90}});
  seg("N", "B", {{700, 350, 120}, {850, 250, 100}});
  seg("N", "C", {{700, 650, 80}, {850, 760, 100}});
  seg("D", "E", {{520, 300, 25}, {480, 700, 35}});
  auto cable = [&](const std::string& id, const char* a, const char* b, double d) {
    Cable c;
    c.id = id, c.ports[0] = a, c.ports[1] = b, c.physical.diameter = d, c.physical.min_bend_radius = 5 * d;
    h.cables.push_back(c);
  };
  for (int k = 0; k < 3; ++k) cable("AB" + std::to_string(k), "A", "B", 4 + k);
  for (int k = 0; k < 2; ++k) cable("AC" + std::to_string(k), "A", "C", 5);
  cable("DE", "D", "E", 6);
  for (int k = 1; k < 7; ++k) {
    Clamp c;
    c.id = "K" + std::to_string(k);
    c.position = {75.0 * k, 500, 100};
    c.segment = 0;
    h.clamps.push_back(c);
    c.id = "L" + std::to_string(k);
    c.position = {500, 150.0 * k, 30};
    c.segment = 3;
    h.clamps.push_back(c);
  }
  return h;
}

Scene test_scene() {
  Scene sc;
  sc.name = "shards";
  sc.parts = scattered_boxes();
  sc.harness = y_harness();
  sc.has_harness = true;
  sc.routing.clearance = {2.0, "test"};
  sc.routing.clamp_spacing = {300.0, "test"};
  sc.routing.clamp_reach = {25.0, "test"};
  sc.routing.supports = true;
  return sc;
}

/// A chord of the widest cable (2r): the resolution of a stretch's ends.
constexpr double kChord = 6.0;

AuditOptions one_thread() {
  AuditOptions o;
  o.check.threads = 1;
  return o;
}

/// The audit of `sc` sharded K ways, merged.
AuditReport sharded(const Scene& sc, int k) {
  std::vector<ShardPartBox> boxes;
  for (const Part& p : sc.parts) boxes.push_back({p.mesh.bounds(), p.mesh.triangle_count(), p.motion.has_value()});
  std::vector<AuditCable> routed;
  const ShardPlan plan = plan_shards(boxes, cable_polylines(audit_cable_inputs(sc.harness, routed), 32), k);
  std::vector<ShardPart> parts;
  for (const Part& p : sc.parts) parts.push_back({p.name, p.role == PartRole::KeepOut, p.mesh.triangle_count()});
  std::vector<AuditReport> reports;
  for (int r = 0; r < k; ++r) {
    Scene own = sc;
    own.parts.clear();
    AuditShard shard;
    shard.cable_passes = r == 0;
    for (std::size_t p = 0; p < sc.parts.size(); ++p)
      if (plan.owner[p] == r) own.parts.push_back(sc.parts[p]), shard.part_ids.push_back(static_cast<int>(p));
    AuditOptions o = one_thread();
    o.shard = &shard;
    AuditReport rep = run_audit(own, o);
    reports.push_back(r == 0 ? rep : shard_report_from_bytes(shard_report_bytes(rep)));
  }
  return merge_audit_shards(std::move(reports), parts, sc.harness, sc.routing);
}

TEST(AuditShard, MergedShardsFindWhatOneProcessFinds) {
  const Scene sc = test_scene();
  const AuditReport whole = run_audit(sc, one_thread());
  // The scene is built to exercise every rule: make sure it does.
  ASSERT_GE(whole.result.clashes.size(), 3u);
  ASSERT_FALSE(whole.supports.spans.empty());
  ASSERT_FALSE(whole.motion.clashes.empty());
  const double tol = whole.result.tolerance;
  for (int k = 1; k <= 4; ++k) {
    SCOPED_TRACE("K = " + std::to_string(k));
    const AuditReport m = sharded(sc, k);
    EXPECT_EQ(m.part_names, whole.part_names);
    EXPECT_EQ(m.triangles, whole.triangles);
    EXPECT_EQ(m.exit_code(), whole.exit_code());
    ASSERT_EQ(m.result.clashes.size(), whole.result.clashes.size());
    for (std::size_t i = 0; i < m.result.clashes.size(); ++i) {
      const ClashEntry &a = m.result.clashes[i], &b = whole.result.clashes[i];
      EXPECT_EQ(a.kind, b.kind) << i;
      EXPECT_EQ(a.cable, b.cable) << i;
      EXPECT_EQ(a.part, b.part) << i;
      EXPECT_EQ(a.other, b.other) << i;
      EXPECT_EQ(a.keep_out, b.keep_out) << i;
      EXPECT_EQ(a.inside, b.inside) << i;
      EXPECT_NEAR(a.clearance, b.clearance, tol) << i;
      // The stretch to one chord (≤ 2r); the deepest point within the tolerance in depth
      // (along a flat contact, such as an axis inside a part, any of its points is deepest).
      EXPECT_NEAR(a.s_begin, b.s_begin, kChord) << i;
      EXPECT_NEAR(a.s_end, b.s_end, kChord) << i;
    }
    ASSERT_EQ(m.result.violations.size(), whole.result.violations.size());
    for (std::size_t i = 0; i < m.result.violations.size(); ++i) {
      EXPECT_EQ(m.result.violations[i].kind, whole.result.violations[i].kind) << i;
      EXPECT_EQ(m.result.violations[i].part, whole.result.violations[i].part) << i;
      EXPECT_NEAR(m.result.violations[i].value, whole.result.violations[i].value, tol) << i;
    }
    for (std::size_t c = 0; c < m.result.cables.size(); ++c)
      EXPECT_NEAR(m.result.cables[c].min_clearance, whole.result.cables[c].min_clearance, tol) << c;
    ASSERT_EQ(m.supports.clamps.size(), whole.supports.clamps.size());
    for (std::size_t c = 0; c < m.supports.clamps.size(); ++c) {
      EXPECT_EQ(m.supports.clamps[c].part, whole.supports.clamps[c].part) << c;
      EXPECT_EQ(m.supports.clamps[c].distance, whole.supports.clamps[c].distance) << c;
    }
    ASSERT_EQ(m.supports.spans.size(), whole.supports.spans.size());
    for (std::size_t i = 0; i < m.supports.spans.size(); ++i) {
      EXPECT_EQ(m.supports.spans[i].cable, whole.supports.spans[i].cable);
      EXPECT_EQ(m.supports.spans[i].from_s, whole.supports.spans[i].from_s);
      EXPECT_EQ(m.supports.spans[i].to_s, whole.supports.spans[i].to_s);
    }
    ASSERT_EQ(m.motion.clashes.size(), whole.motion.clashes.size());
    for (std::size_t i = 0; i < m.motion.clashes.size(); ++i) {
      EXPECT_EQ(m.motion.clashes[i].part, whole.motion.clashes[i].part);
      EXPECT_NEAR(m.motion.clashes[i].clearance, whole.motion.clashes[i].clearance, tol);
    }
  }
}

TEST(AuditShard, WireFormatKeepsEveryBitAndInfinity) {
  const Scene sc = test_scene();
  AuditReport rep = run_audit(sc, one_thread());
  rep.result.cables[0].min_clearance = std::numeric_limits<double>::infinity();
  const AuditReport back = shard_report_from_bytes(shard_report_bytes(rep));
  ASSERT_EQ(back.result.clashes.size(), rep.result.clashes.size());
  for (std::size_t i = 0; i < rep.result.clashes.size(); ++i) {
    EXPECT_EQ(back.result.clashes[i].clearance, rep.result.clashes[i].clearance);
    EXPECT_EQ(back.result.clashes[i].point, rep.result.clashes[i].point);
    EXPECT_EQ(back.result.clashes[i].s_end, rep.result.clashes[i].s_end);
  }
  EXPECT_EQ(back.result.cables[0].min_clearance, std::numeric_limits<double>::infinity());
  EXPECT_EQ(back.supports.clamps.size(), rep.supports.clamps.size());
  EXPECT_EQ(back.motion.clashes.size(), rep.motion.clashes.size());
  EXPECT_EQ(back.result.counters.samples, rep.result.counters.samples);
  EXPECT_THROW(shard_report_from_bytes({1, 2, 3}), std::runtime_error);
}

TEST(ShardPlan, EveryPartOwnedOnceAndTheWorkBalanced) {
  std::mt19937 rng(3);
  std::vector<ShardPartBox> boxes;
  for (int k = 0; k < 400; ++k) {
    const Vec3 c(rng() % 1000, rng() % 1000, rng() % 100);
    AABB b;
    b.extend(c);
    b.extend(c + Vec3(5, 5, 5));
    boxes.push_back({b, 100 + rng() % 900, k == 17});
  }
  // Two diagonal cables, each as 100 chords.
  std::vector<std::vector<Vec3>> cables(2);
  for (int i = 0; i <= 100; ++i) {
    cables[0].emplace_back(10.0 * i, 10.0 * i, 0.0);
    cables[1].emplace_back(10.0 * i, 1000.0 - 10.0 * i, 50.0);
  }
  for (int k = 1; k <= 7; ++k) {
    const ShardPlan plan = plan_shards(boxes, cables, k);
    ASSERT_EQ(plan.owner.size(), boxes.size());
    ASSERT_EQ(plan.region_work.size(), static_cast<std::size_t>(k));
    EXPECT_EQ(plan.owner[17], 0);  // pinned
    double sum = 0.0;
    for (double w : plan.region_work) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-12);
    // Items are small against the whole: each region within a few percent of its share.
    for (double w : plan.region_work) EXPECT_NEAR(w, 1.0 / k, 0.03) << k;
    for (std::size_t p = 0; p < boxes.size(); ++p) {
      if (p == 17) continue;
      const Vec3 c = boxes[p].box.center();
      EXPECT_TRUE(plan.regions[static_cast<std::size_t>(plan.owner[p])].contains(c)) << p;
    }
    EXPECT_EQ(plan.owner, plan_shards(boxes, cables, k).owner);  // deterministic
  }
  EXPECT_THROW(plan_shards(boxes, cables, 0), std::invalid_argument);
  // Fewer items than regions: the rest own nothing.
  const ShardPlan tiny = plan_shards({boxes[0]}, {}, 3);
  EXPECT_EQ(tiny.owner[0], 0);
  EXPECT_EQ(tiny.region_triangles[1] + tiny.region_triangles[2], 0u);
}

}  // namespace
}  // namespace loom
