// Broad phase against brute force: random boxes with fixed seeds (sparse, dense, thin,
// far from the origin), degenerate inputs (empty, one box, all equal, points, touching
// faces), thread counts, bad input, and a rapidcheck invariant; the bounded form's filter,
// estimate and statuses.
#include "index/box_pairs.hpp"
#include "index/random_boxes.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

using namespace loom;
using loom::test::box;
using loom::test::random_boxes;

namespace {

std::vector<BoxPair> brute_pairs(const std::vector<AABB>& boxes) {
  std::vector<BoxPair> out;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
      if (boxes_overlap(boxes[i], boxes[j])) out.emplace_back(i, j);
  return out;
}

void expect_brute(const std::vector<AABB>& boxes, int threads) {
  const auto got = overlapping_box_pairs(boxes, threads);
  const auto want = brute_pairs(boxes);
  ASSERT_EQ(got.size(), want.size()) << boxes.size() << " boxes, " << threads << " threads";
  EXPECT_EQ(got, want);
}

}  // namespace

TEST(BoxPairs, MatchesBruteForceOnRandomBoxes) {
  for (unsigned seed : {1u, 2u, 3u}) {
    expect_brute(random_boxes(seed, 3000, 1.0, 0.01), 2);   // sparse
    expect_brute(random_boxes(seed, 1500, 1.0, 0.08), 2);   // dense: many pairs per box
    expect_brute(random_boxes(seed, 2000, 1.0, 0.002), 1);  // tiny boxes, few pairs
  }
}

TEST(BoxPairs, FarFromOriginAndThinBoxes) {
  // A section 5 km from the origin: float boxes alone would merge millimetre gaps.
  expect_brute(random_boxes(7, 2000, 1.0, 0.005, Vec3(5000.0, -5000.0, 3000.0)), 2);
  // Flat boxes (zero thickness in z), like block boxes of a cable lying in a plane.
  std::vector<AABB> flat = random_boxes(8, 1000, 1.0, 0.02);
  for (auto& b : flat) b.min.z() = b.max.z() = 0.25;
  expect_brute(flat, 2);
}

TEST(BoxPairs, TouchingFacesCountAndNearMissesDoNot) {
  // Boxes in a row: each touches the next exactly, then a row apart by one double step.
  std::vector<AABB> row;
  for (int i = 0; i < 50; ++i) row.push_back(box(Vec3(i, 0, 0), Vec3(i + 1, 1, 1)));
  const auto touching = overlapping_box_pairs(row, 2);
  ASSERT_EQ(touching.size(), 49u);
  for (std::uint32_t i = 0; i < 49; ++i) EXPECT_EQ(touching[i], BoxPair(i, i + 1));
  std::vector<AABB> apart;
  for (int i = 0; i < 50; ++i) {
    const double lo = std::nextafter(static_cast<double>(i), 1e9);  // one ulp past the previous max
    apart.push_back(box(Vec3(lo, 0, 0), Vec3(i + 1, 1, 1)));
  }
  EXPECT_TRUE(overlapping_box_pairs(apart, 2).empty());
}

TEST(BoxPairs, DegenerateInputs) {
  EXPECT_TRUE(overlapping_box_pairs({}, 2).empty());
  EXPECT_TRUE(overlapping_box_pairs({box(Vec3::Zero(), Vec3::Ones())}, 2).empty());
  // All boxes equal: every pair overlaps.
  std::vector<AABB> same(40, box(Vec3(0.1, 0.2, 0.3), Vec3(0.4, 0.5, 0.6)));
  EXPECT_EQ(overlapping_box_pairs(same, 2).size(), 40u * 39u / 2u);
  // All boxes the same point.
  std::vector<AABB> points(30, box(Vec3(1, 2, 3), Vec3(1, 2, 3)));
  EXPECT_EQ(overlapping_box_pairs(points, 2).size(), 30u * 29u / 2u);
  // Distinct points: no pairs.
  std::vector<AABB> spread;
  for (int i = 0; i < 30; ++i) spread.push_back(box(Vec3(i, 0, 0), Vec3(i, 0, 0)));
  EXPECT_TRUE(overlapping_box_pairs(spread, 2).empty());
}

TEST(BoxPairs, SameAnswerOnOneAndTwoThreads) {
  const auto boxes = random_boxes(11, 5000, 1.0, 0.02);
  EXPECT_EQ(overlapping_box_pairs(boxes, 1), overlapping_box_pairs(boxes, 2));
}

TEST(BoxPairs, BadBoxIsNamed) {
  std::vector<AABB> boxes = random_boxes(3, 10, 1.0, 0.1);
  boxes[4].max.y() = std::numeric_limits<double>::quiet_NaN();
  try {
    overlapping_box_pairs(boxes, 1);
    FAIL() << "a NaN corner was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("box 4"), std::string::npos) << e.what();
  }
  boxes = random_boxes(3, 10, 1.0, 0.1);
  std::swap(boxes[6].min.x(), boxes[6].max.x());  // inverted
  boxes[6].min.x() += 1.0;
  EXPECT_THROW(overlapping_box_pairs(boxes, 1), std::invalid_argument);
  std::vector<AABB> empty_box(3, box(Vec3::Zero(), Vec3::Ones()));
  empty_box[1] = AABB();  // default box is empty (inverted, infinite)
  EXPECT_THROW(overlapping_box_pairs(empty_box, 1), std::invalid_argument);
}

TEST(BoxPairs, BoundedFormKeepsTheFilteredPairsAndEstimatesExactlyWhenAllAreCounted) {
  const auto boxes = random_boxes(12, 800, 1.0, 0.04);  // ≤ kBoxPairSample: every box counted
  const auto all = brute_pairs(boxes);
  ASSERT_GT(all.size(), 100u);
  BoxPairRequest req;
  req.filter.keep = [](std::uint32_t i, std::uint32_t j) { return (i ^ j) & 1u; };
  req.max_overlaps = all.size();  // exactly the work: allowed
  req.threads = 2;
  const BoxPairResult r = overlapping_box_pairs(boxes, req);
  ASSERT_EQ(r.status, BoxPairStatus::Done);
  EXPECT_DOUBLE_EQ(r.estimated_overlaps, static_cast<double>(all.size()));
  std::vector<BoxPair> kept;
  for (const BoxPair& p : all)
    if ((p.first ^ p.second) & 1u) kept.push_back(p);
  EXPECT_EQ(r.pairs, kept);
  EXPECT_DOUBLE_EQ(r.estimated_kept, static_cast<double>(kept.size()));
  req.max_overlaps = all.size() - 1;
  const BoxPairResult over = overlapping_box_pairs(boxes, req);
  EXPECT_EQ(over.status, BoxPairStatus::TooManyOverlaps);
  EXPECT_TRUE(over.pairs.empty());
  req.max_overlaps = all.size();
  req.filter.max_pairs = kept.size() - 1;
  EXPECT_EQ(overlapping_box_pairs(boxes, req).status, BoxPairStatus::TooManyKept);
  // The unbounded form makes no estimate.
  EXPECT_EQ(overlapping_box_pairs(boxes, BoxPairRequest{}).estimated_overlaps, 0.0);
}

TEST(BoxPairs, SampledEstimateIsCloseAndNamesABusyBox) {
  // More boxes than the sample: a uniform field, and one with a dense cluster.
  for (bool cluster : {false, true}) {
    auto boxes = random_boxes(13, 6000, 1.0, 0.03);
    if (cluster)
      for (std::size_t i = 0; i < 1500; ++i) boxes[i] = box(Vec3::Constant(0.5), Vec3::Constant(0.52));
    const double truth = static_cast<double>(brute_pairs(boxes).size());
    BoxPairRequest req;
    req.max_overlaps = static_cast<std::size_t>(10 * truth);
    const BoxPairResult r = overlapping_box_pairs(boxes, req);
    ASSERT_EQ(r.status, BoxPairStatus::Done);
    EXPECT_NEAR(r.estimated_overlaps / truth, 1.0, 0.25) << "cluster " << cluster << ": " << r.estimated_overlaps
                                                         << " vs " << truth;
    if (cluster) {
      EXPECT_LT(r.busiest, 1500u);  // one of the 1,500 equal boxes overlaps the most
    }
  }
}

TEST(BoxPairs, KeptPairsFarBeyondTheLimitAreRefusedFromTheEstimate) {
  // More boxes than the sample; a filter that keeps a third of the pairs.
  const auto boxes = random_boxes(14, 6000, 1.0, 0.03);
  const auto all = brute_pairs(boxes);
  auto keep = [](std::uint32_t i, std::uint32_t j) { return (i + j) % 3 == 0; };
  double truth = 0.0;
  for (const BoxPair& p : all) truth += keep(p.first, p.second) ? 1.0 : 0.0;
  std::atomic<std::size_t> calls{0};
  BoxPairRequest req;
  req.max_overlaps = 10 * all.size();
  req.filter.keep = [&](std::uint32_t i, std::uint32_t j) {
    ++calls;
    return keep(i, j);
  };
  const BoxPairResult r = overlapping_box_pairs(boxes, req);
  ASSERT_EQ(r.status, BoxPairStatus::Done);
  EXPECT_NEAR(r.estimated_kept / truth, 1.0, 0.25) << r.estimated_kept << " vs " << truth;
  // Three times the limit: refused before the enumeration, which would call the filter once
  // per overlapping pair.
  calls = 0;
  req.filter.max_pairs = static_cast<std::size_t>(truth / 3);
  const BoxPairResult over = overlapping_box_pairs(boxes, req);
  EXPECT_EQ(over.status, BoxPairStatus::TooManyKept);
  EXPECT_TRUE(over.pairs.empty());
  EXPECT_LT(calls.load(), all.size() / 2) << "the pairs were enumerated";
}

RC_GTEST_PROP(BoxPairs, EqualsBruteForce, ()) {
  const int n = *rc::gen::inRange(0, 200);
  const int grid = *rc::gen::inRange(1, 6);  // coarse integer corners: many exact touches
  std::vector<AABB> boxes;
  for (int i = 0; i < n; ++i) {
    Vec3 lo, hi;
    for (int k = 0; k < 3; ++k) {
      const int a = *rc::gen::inRange(0, grid + 1), b = *rc::gen::inRange(0, grid + 1);
      lo[k] = std::min(a, b) * 0.1;
      hi[k] = std::max(a, b) * 0.1;
    }
    boxes.push_back(box(lo, hi));
  }
  RC_ASSERT(overlapping_box_pairs(boxes, 2) == brute_pairs(boxes));
}
