// Supports audit: a straight bundle 20 mm above two plates with a 600 mm gap between them,
// clamped every 200 mm. Known answer: the clamps over the gap are out of reach (27 mm =
// reach 25 + radius 2; the plate edge is ≥ 201 mm away), so the one unsupported span runs
// from the last clamp on the first plate to the first clamp on the second. Without any
// structure every cable is one span from port to port; without clamp_spacing in the scene
// no span is checked (clamps are still listed); keep-out zones and moving parts hold nothing.
#include "routing/audit/audit.hpp"
#include "routing/audit/report_json.hpp"
#include "common/support_fixtures.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace loom {
namespace {

using test::box_part;

constexpr double kLength = 2000.0;  ///< port to port along x, mm
constexpr double kHeight = 20.0;    ///< centreline above the plates' top face
constexpr double kDiameter = 4.0;

/// One straight cable A → B at height kHeight, clamps at the given x (segment given).
Harness straight(const std::vector<double>& clamp_x) { return test::straight_cable(kLength, kHeight, kDiameter, clamp_x); }

AuditReport audit(const Harness& h, std::vector<Part> parts, bool spacing_given) {
  Scene sc;
  sc.name = "plate";
  sc.harness = h;
  sc.has_harness = true;
  sc.parts = std::move(parts);
  sc.routing.clearance = {1.0, "test"};
  sc.routing.clamp_spacing = {450.0, "test"};
  sc.routing.clamp_reach = {25.0, "test"};
  sc.routing.supports = spacing_given;
  AuditOptions o;
  o.check.threads = 1;
  return run_audit(sc, o);
}

std::vector<Part> two_plates() {
  return {box_part("plate-1", {-50, -100, -10}, {800, 100, 0}), box_part("plate-2", {1400, -100, -10}, {2050, 100, 0}),
          // A keep-out zone right beside the clamp at 1000: it holds nothing.
          box_part("keep", {990, 5, 10}, {1010, 15, 30}, PartRole::KeepOut)};
}

const std::vector<double> kEvery200 = {200, 400, 600, 800, 1000, 1200, 1400, 1600, 1800};

TEST(Supports, GapWiderThanTheSpacingIsOneSpan) {
  const AuditReport rep = audit(straight(kEvery200), two_plates(), true);
  ASSERT_EQ(rep.supports.spans.size(), 1u);
  const UnsupportedSpan& sp = rep.supports.spans[0];
  EXPECT_NEAR(sp.from_s, 800.0, 1e-6);
  EXPECT_NEAR(sp.to_s, 1400.0, 1e-6);
  EXPECT_DOUBLE_EQ(sp.spacing, 450.0);
  EXPECT_NEAR((sp.point - Vec3(1100, 0, kHeight)).norm(), 0.0, 1e-6);
  EXPECT_EQ(rep.exit_code(), 1);
  ASSERT_EQ(rep.supports.clamps.size(), kEvery200.size());
  for (std::size_t k = 0; k < kEvery200.size(); ++k) {
    const ClampLoad& c = rep.supports.clamps[k];
    const double x = kEvery200[k];
    const bool over_plate = x <= 800 || x >= 1400;
    EXPECT_EQ(c.supports(), over_plate) << c.id;
    if (over_plate) {
      EXPECT_EQ(rep.part_names[static_cast<std::size_t>(c.part)], x <= 800 ? "plate-1" : "plate-2");
      EXPECT_NEAR(c.distance, kHeight, 1e-3);  // straight down to the top face
    }
    EXPECT_DOUBLE_EQ(c.bundle_diameter, kDiameter);
  }
  const auto j = audit_report_json(rep);
  ASSERT_EQ(j["clamps"].size(), kEvery200.size());
  EXPECT_EQ(j["clamps"][0]["segment"], "A/B");
  EXPECT_TRUE(j["clamps"][4]["part"].is_null());
  bool found = false;
  for (const auto& v : j["violations"])
    if (v["kind"] == "unsupported-span") {
      found = true;
      EXPECT_EQ(v["cable"], "C1");
      EXPECT_NEAR(v["length"].get<double>(), 600.0, 1e-6);
    }
  EXPECT_TRUE(found);
}

TEST(Supports, ClampsCloseTheGapWhenWithinReach) {
  // A third plate under the gap brings the clamps at 1000 and 1200 within reach.
  std::vector<Part> parts = two_plates();
  parts.push_back(box_part("plate-3", {900, -100, -10}, {1300, 100, kHeight - 2 - 24}));  // 24 mm below the surface
  const AuditReport rep = audit(straight(kEvery200), parts, true);
  EXPECT_TRUE(rep.supports.spans.empty());
  EXPECT_EQ(rep.supports.clamps[4].part, 3);
  // 1 mm farther, beyond the reach: the span is back.
  parts.back() = box_part("plate-3", {900, -100, -10}, {1300, 100, kHeight - 2 - 26});
  EXPECT_EQ(audit(straight(kEvery200), parts, true).supports.spans.size(), 1u);
}

TEST(Supports, AMovingPartHoldsNoClamp) {
  // The third plate within reach as above, but it slides along x (a door, a seat rail):
  // a clamp there would ride it, so the gap stays one span and its clamps hold nothing.
  std::vector<Part> parts = two_plates();
  parts.push_back(box_part("plate-3", {900, -100, -10}, {1300, 100, kHeight - 2 - 24}));
  Motion slide;
  slide.kind = MotionKind::Translate;
  slide.axis = Vec3::UnitY();
  slide.from = 0.0;
  slide.to = 50.0;
  parts.back().motion = slide;
  const AuditReport rep = audit(straight(kEvery200), parts, true);
  EXPECT_EQ(rep.supports.spans.size(), 1u);
  EXPECT_EQ(rep.supports.clamps[4].part, -1);
  EXPECT_FALSE(holds_clamps(parts.back()));
  EXPECT_TRUE(holds_clamps(parts.front()));
}

TEST(Supports, WithoutStructureEveryCableIsOneSpan) {
  const AuditReport rep = audit(straight(kEvery200), {}, true);
  ASSERT_EQ(rep.supports.spans.size(), 1u);
  EXPECT_DOUBLE_EQ(rep.supports.spans[0].from_s, 0.0);
  EXPECT_NEAR(rep.supports.spans[0].to_s, kLength, 1e-6);
  for (const ClampLoad& c : rep.supports.clamps) EXPECT_FALSE(c.supports());
}

TEST(Supports, PortsSupportAShortCable) {
  Harness h = straight({});
  h.ports[1].position.x() = 440.0;
  EXPECT_TRUE(audit(h, {}, true).supports.spans.empty());
  h.ports[1].position.x() = 460.0;
  EXPECT_EQ(audit(h, {}, true).supports.spans.size(), 1u);
}

TEST(Supports, UncheckedUnlessTheSceneSetsTheSpacing) {
  const AuditReport rep = audit(straight(kEvery200), {}, false);
  EXPECT_TRUE(rep.supports.spans.empty());
  EXPECT_EQ(rep.supports.clamps.size(), kEvery200.size());
  EXPECT_EQ(rep.exit_code(), 0);
}

TEST(Supports, AClampWithoutSegmentHoldsTheNearestWithinReach) {
  Harness h = straight({});
  h.clamps.push_back({"near", {600, 10, kHeight}, -1, "", 0.0, false, 3});   // 10 mm off the axis
  h.clamps.push_back({"far", {600, 100, kHeight}, -1, "", 0.0, false, 4});   // beyond reach + radius
  const AuditReport rep = audit(h, two_plates(), true);
  EXPECT_EQ(rep.supports.clamps[0].segment, 0);
  EXPECT_TRUE(rep.supports.clamps[0].supports());
  EXPECT_EQ(rep.supports.clamps[1].segment, -1);
  ASSERT_FALSE(rep.supports.notes.empty());
  EXPECT_NE(rep.supports.notes[0].find("'far'"), std::string::npos);
}

}  // namespace
}  // namespace loom
