// The audit's stretch bookkeeping (routing/stretch_tracker): closed-form sequences of
// observations and the clashes and violations they must give.
#include "routing/audit/stretch_tracker.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace loom;
using namespace loom::audit;

namespace {

PartObservation seen(int part, double key, double s) {
  PartObservation o;
  o.part = part;
  o.key = key;
  o.key_lower = key;
  o.s = s;
  o.point = Vec3(s, key, 0.0);
  return o;
}

/// Steps one observation of each (part, key) at s = 0, 1, 2, …, each step [s, s + 1], then
/// one empty step and a flush.
void run(StretchTracker& t, const std::vector<std::pair<int, double>>& obs) {
  double s = 0.0;
  for (const auto& [part, key] : obs) {
    t.step({seen(part, key, s)}, s, s + 1.0);
    s += 1.0;
  }
  t.step({}, s, s + 1.0);
  t.flush();
}

std::vector<PartInfo> parts(double required, int n = 2) {
  std::vector<PartInfo> p(static_cast<std::size_t>(n));
  for (auto& q : p) q.required = required;
  return p;
}

}  // namespace

TEST(StretchTracker, OneContactStretchIsOneClashAtItsDeepest) {
  const auto info = parts(3.0);
  const std::vector<PartAttachment> none;
  StretchTracker t(4, 1.0, info, none);
  run(t, {{0, 2.0}, {0, 1.0}, {0, -0.5}, {0, -1.0}, {0, -0.2}, {0, 0.5}});
  ASSERT_EQ(t.clashes.size(), 1u);
  const ClashEntry& e = t.clashes[0];
  EXPECT_EQ(e.cable, 4);
  EXPECT_EQ(e.part, 0);
  EXPECT_EQ(e.kind, ClashKind::CableStructure);
  EXPECT_DOUBLE_EQ(e.clearance, -1.0);
  EXPECT_DOUBLE_EQ(e.s, 3.0);
  EXPECT_DOUBLE_EQ(e.s_begin, 2.0);  // the first contact step starts at 2
  EXPECT_DOUBLE_EQ(e.s_end, 5.0);    // the last one ([4, 5]) ends at 5
  EXPECT_TRUE(t.violations.empty()) << "a band with a contact is a clash, not also a violation";
  EXPECT_DOUBLE_EQ(t.min_key, -1.0);
}

TEST(StretchTracker, BandWithoutContactIsOneViolationAtItsSmallestClearance) {
  const auto info = parts(3.0);
  const std::vector<PartAttachment> none;
  StretchTracker t(0, 1.0, info, none);
  run(t, {{0, 2.5}, {0, 1.25}, {0, 2.0}});
  EXPECT_TRUE(t.clashes.empty());
  ASSERT_EQ(t.violations.size(), 1u);
  EXPECT_EQ(t.violations[0].kind, ViolationKind::Clearance);
  EXPECT_DOUBLE_EQ(t.violations[0].value, 1.25);
  EXPECT_DOUBLE_EQ(t.violations[0].limit, 3.0);
  EXPECT_DOUBLE_EQ(t.violations[0].s, 1.0);
}

TEST(StretchTracker, ContactsSeparatedInOneBandAreTwoClashesAndPartsAreApart) {
  const auto info = parts(3.0);
  const std::vector<PartAttachment> none;
  StretchTracker t(0, 1.0, info, none);
  double s = 0.0;
  // Part 0: contact, clear but in band, contact again. Part 1 alongside, in band only.
  for (double k : {-0.3, 1.0, -0.7}) {
    t.step({seen(0, k, s), seen(1, 2.0 - 0.1 * s, s)}, s, s + 1.0);
    s += 1.0;
  }
  t.step({}, s, s + 1.0);
  t.flush();
  ASSERT_EQ(t.clashes.size(), 2u);
  EXPECT_DOUBLE_EQ(t.clashes[0].clearance, -0.3);
  EXPECT_DOUBLE_EQ(t.clashes[1].clearance, -0.7);
  EXPECT_EQ(t.clashes[0].part, 0);
  ASSERT_EQ(t.violations.size(), 1u);
  EXPECT_EQ(t.violations[0].part, 1);
  EXPECT_DOUBLE_EQ(t.violations[0].value, 1.8);
}

TEST(StretchTracker, InsideAClosedPartReportsMinusTheRadius) {
  const auto info = parts(0.0);
  const std::vector<PartAttachment> none;
  StretchTracker t(0, 2.0, info, none);
  PartObservation o = seen(0, -2.0 - 5.0, 1.0);  // axis 5 deep inside
  o.inside = true;
  t.step({o}, 0.0, 2.0);
  t.flush();
  ASSERT_EQ(t.clashes.size(), 1u);
  EXPECT_DOUBLE_EQ(t.clashes[0].clearance, -2.0);
  EXPECT_TRUE(t.clashes[0].inside);
}

TEST(StretchTracker, AttachedPartIsExcusedOnlyOverItsRange) {
  const auto info = parts(3.0);
  std::vector<PartAttachment> port{{0, 0.0, 1.5, "J1"}};
  StretchTracker t(0, 1.0, info, port);
  run(t, {{0, -0.5}, {0, -0.4}, {0, -0.3}});  // s = 0, 1 excused; s = 2 is not
  ASSERT_EQ(t.clashes.size(), 1u);
  EXPECT_DOUBLE_EQ(t.clashes[0].clearance, -0.3);
  EXPECT_DOUBLE_EQ(t.clashes[0].s, 2.0);
}

// A deferred observation (key known within [key_lower, key]) is measured only if it can be
// the deepest of its stretch; then its exact key is the one reported.
TEST(StretchTracker, DeferredObservationsAreMeasuredOnlyWhenTheyCanBeTheDeepest) {
  const auto info = parts(3.0);
  const std::vector<PartAttachment> none;
  int measured = 0;
  StretchTracker t(0, 1.0, info, none, [&](PartObservation& o) {
    ++measured;
    o.key = o.key_lower + 0.01;  // the exact value, somewhere in the bounds
    o.deferred.reset();
  });
  PartObservation exact = seen(0, 1.0, 0.0);
  PartObservation cannot = seen(0, 2.5, 1.0);  // lower bound 2.0 above the exact 1.0
  cannot.key_lower = 2.0;
  cannot.deferred = DeferredChord{};
  PartObservation can = seen(0, 2.0, 2.0);  // lower bound 0.5 below 1.0: may be deepest
  can.key_lower = 0.5;
  can.deferred = DeferredChord{};
  t.step({exact}, 0.0, 1.0);
  t.step({cannot}, 1.0, 2.0);
  t.step({can}, 2.0, 3.0);
  t.flush();
  EXPECT_EQ(measured, 1);
  ASSERT_EQ(t.violations.size(), 1u);
  EXPECT_DOUBLE_EQ(t.violations[0].value, 0.51);
  EXPECT_DOUBLE_EQ(t.violations[0].s, 2.0);
}

TEST(StretchTracker, ADeferredObservationWithoutAResolverIsALogicError) {
  const auto info = parts(3.0);
  const std::vector<PartAttachment> none;
  StretchTracker t(0, 1.0, info, none);
  PartObservation o = seen(0, 2.0, 0.0);
  o.key_lower = 1.0;
  o.deferred = DeferredChord{};
  t.step({o}, 0.0, 1.0);
  EXPECT_THROW(t.flush(), std::logic_error);
}

TEST(StretchTracker, NothingSeenGivesNothing) {
  const auto info = parts(3.0);
  const std::vector<PartAttachment> none;
  StretchTracker t(0, 1.0, info, none);
  run(t, {});
  EXPECT_TRUE(t.clashes.empty());
  EXPECT_TRUE(t.violations.empty());
  EXPECT_EQ(t.min_key, std::numeric_limits<double>::infinity());
}
