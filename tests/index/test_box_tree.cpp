// BoxTree::overlapping against brute force: random boxes and queries with fixed seeds
// (sparse, dense, far from the origin, flat, points), exact touches and one-ulp gaps,
// degenerate inputs (no boxes, empty boxes, all equal), moves, concurrent queries, bad
// input, and a rapidcheck invariant.
#include "index/box_tree.hpp"
#include "index/random_boxes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <iomanip>
#include <limits>
#include <stdexcept>
#include <thread>

using namespace loom;
using loom::test::box;
using loom::test::random_boxes;

namespace {

std::vector<std::uint32_t> brute_overlapping(const std::vector<AABB>& boxes, const AABB& q) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    if (boxes_overlap(boxes[i], q)) out.push_back(i);
  return out;
}

/// Every query's answer equals brute force; the query is printed at full precision on failure.
void expect_brute(const std::vector<AABB>& boxes, const std::vector<AABB>& queries) {
  const BoxTree tree(boxes);
  std::vector<std::uint32_t> got;
  for (const AABB& q : queries) {
    tree.overlapping(q, got);
    ASSERT_EQ(got, brute_overlapping(boxes, q)) << std::setprecision(17) << "query min (" << q.min.transpose()
                                                << ") max (" << q.max.transpose() << "), " << boxes.size() << " boxes";
  }
}

}  // namespace

TEST(BoxTree, MatchesBruteForceOnRandomBoxes) {
  for (unsigned seed : {1u, 2u, 3u}) {
    expect_brute(random_boxes(seed, 3000, 1.0, 0.01), random_boxes(seed + 10, 300, 1.0, 0.05));   // sparse
    expect_brute(random_boxes(seed, 1500, 1.0, 0.08), random_boxes(seed + 20, 200, 1.0, 0.1));    // dense
    expect_brute(random_boxes(seed, 2000, 1.0, 0.002), random_boxes(seed + 30, 300, 1.0, 0.0));   // point queries
    expect_brute(random_boxes(seed, 500, 1.0, 0.01), {box(Vec3::Constant(-1), Vec3::Constant(2))});  // all
  }
}

TEST(BoxTree, FarFromOriginAndThinBoxes) {
  // A section 5 km from the origin: float boxes alone would merge millimetre gaps.
  const Vec3 far(5000.0, -5000.0, 3000.0);
  expect_brute(random_boxes(7, 2000, 1.0, 0.005, far), random_boxes(17, 300, 1.0, 0.003, far));
  // Flat boxes and queries (zero thickness in z).
  std::vector<AABB> flat = random_boxes(8, 1000, 1.0, 0.02), flat_q = random_boxes(18, 200, 1.0, 0.02);
  for (auto& b : flat) b.min.z() = b.max.z() = 0.25;
  for (auto& b : flat_q) b.min.z() = b.max.z() = 0.25;
  expect_brute(flat, flat_q);
}

TEST(BoxTree, TouchingCountsAndOneUlpApartDoesNot) {
  std::vector<AABB> row;
  for (int i = 0; i < 50; ++i) row.push_back(box(Vec3(i, 0, 0), Vec3(i + 1, 1, 1)));
  const BoxTree tree(row);
  std::vector<std::uint32_t> got;
  tree.overlapping(box(Vec3(10, 1, 1), Vec3(10, 1, 1)), got);  // a shared corner of boxes 9 and 10
  EXPECT_EQ(got, (std::vector<std::uint32_t>{9, 10}));
  const double past = std::nextafter(50.0, 1e9);  // one ulp past the last box
  tree.overlapping(box(Vec3(past, 0, 0), Vec3(60, 1, 1)), got);
  EXPECT_TRUE(got.empty());
  tree.overlapping(box(Vec3(20.5, std::nextafter(1.0, 2.0), 0), Vec3(30, 2, 1)), got);  // one ulp above in y
  EXPECT_TRUE(got.empty());
}

TEST(BoxTree, DegenerateInputs) {
  std::vector<std::uint32_t> got{7};
  BoxTree none({});
  none.overlapping(box(Vec3::Zero(), Vec3::Ones()), got);
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(none.size(), 0u);
  // Empty boxes keep their indices but overlap nothing, even an all-covering query.
  const BoxTree some({AABB(), box(Vec3::Zero(), Vec3::Ones()), AABB()});
  EXPECT_EQ(some.size(), 3u);
  some.overlapping(box(Vec3::Constant(-1e9), Vec3::Constant(1e9)), got);
  EXPECT_EQ(got, (std::vector<std::uint32_t>{1}));
  some.overlapping(AABB(), got);  // an empty query
  EXPECT_TRUE(got.empty());
  const BoxTree only_empty({AABB(), AABB()});
  only_empty.overlapping(box(Vec3::Zero(), Vec3::Ones()), got);
  EXPECT_TRUE(got.empty());
  // All boxes the same point, queried at that point.
  const std::vector<AABB> points(30, box(Vec3(1, 2, 3), Vec3(1, 2, 3)));
  expect_brute(points, {points[0], box(Vec3(1, 2, 3.5), Vec3(1, 2, 4))});
}

TEST(BoxTree, MovedTreeAndConcurrentQueriesAnswerTheSame) {
  const auto boxes = random_boxes(5, 4000, 1.0, 0.01);
  const auto queries = random_boxes(6, 400, 1.0, 0.03);
  BoxTree a(boxes);
  BoxTree b(std::move(a));
  BoxTree c({});
  c = std::move(b);
  std::vector<std::vector<std::uint32_t>> got(queries.size());
  auto run = [&](std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; ++i) c.overlapping(queries[i], got[i]);
  };
  std::thread t1(run, 0, queries.size() / 2), t2(run, queries.size() / 2, queries.size());
  t1.join();
  t2.join();
  for (std::size_t i = 0; i < queries.size(); ++i) EXPECT_EQ(got[i], brute_overlapping(boxes, queries[i])) << i;
}

TEST(BoxTree, SelfPairsMatchBruteForce) {
  const auto boxes = random_boxes(9, 2000, 1.0, 0.02);
  std::vector<BoxPair> want;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
      if (boxes_overlap(boxes[i], boxes[j])) want.emplace_back(i, j);
  EXPECT_EQ(BoxTree(boxes).self_pairs(), want);
}

TEST(BoxTree, CountOverlappingIsTheListSizeUpToItsCap) {
  for (unsigned seed : {4u, 5u}) {
    const auto boxes = random_boxes(seed, 2000, 1.0, 0.05);
    const BoxTree tree(boxes);
    for (const AABB& q : random_boxes(seed + 40, 100, 1.0, 0.1)) {
      const std::size_t want = brute_overlapping(boxes, q).size();
      EXPECT_EQ(tree.count_overlapping(q, 1'000'000), want);
      for (std::size_t cap : {std::size_t{0}, std::size_t{1}, std::size_t{3}, want, want + 1})
        EXPECT_EQ(tree.count_overlapping(q, cap), std::min(want, cap)) << "cap " << cap;
      // The kept count: the listed boxes the predicate accepts.
      const std::function<bool(std::uint32_t)> even = [](std::uint32_t i) { return i % 2 == 0; };
      const auto listed = brute_overlapping(boxes, q);
      const auto kept = static_cast<std::size_t>(std::count_if(listed.begin(), listed.end(), even));
      const BoxTree::OverlapCount c = tree.count_overlapping(q, 1'000'000, even);
      EXPECT_EQ(c.all, want);
      EXPECT_EQ(c.kept, kept);
      EXPECT_EQ(tree.count_overlapping(q, 1'000'000, {}).kept, want);  // no predicate: every box
    }
  }
  // Degenerate: all boxes equal, and no boxes.
  const std::vector<AABB> same(50, box(Vec3::Zero(), Vec3::Ones()));
  EXPECT_EQ(BoxTree(same).count_overlapping(box(Vec3::Ones(), Vec3::Constant(2)), 1000), 50u);
  EXPECT_EQ(BoxTree(std::vector<AABB>{}).count_overlapping(box(Vec3::Zero(), Vec3::Ones()), 1000), 0u);
}

TEST(BoxTree, FilteredSelfPairsMatchBruteForceAndStopAtTheirLimit) {
  const auto boxes = random_boxes(11, 2000, 1.0, 0.03);
  auto keep = [](std::uint32_t i, std::uint32_t j) { return (i + j) % 3 != 0; };
  std::vector<BoxPair> want;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
      if (boxes_overlap(boxes[i], boxes[j]) && keep(i, j)) want.emplace_back(i, j);
  ASSERT_GT(want.size(), 100u);
  const BoxTree tree(boxes);
  BoxTree::PairFilter filter;
  filter.keep = keep;
  EXPECT_EQ(tree.self_pairs(filter), want);
  filter.max_pairs = want.size();  // exactly enough
  EXPECT_EQ(tree.self_pairs(filter), want);
  filter.max_pairs = want.size() - 1;
  EXPECT_THROW(tree.self_pairs(filter), std::length_error);
}

TEST(BoxTree, BadInputIsNamed) {
  std::vector<AABB> boxes = random_boxes(3, 10, 1.0, 0.1);
  boxes[4].min.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    BoxTree t(boxes);
    FAIL() << "a NaN corner was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("box 4"), std::string::npos) << e.what();
  }
  boxes = random_boxes(3, 10, 1.0, 0.1);
  boxes[2].max.y() = boxes[2].min.y() - 1.0;  // inverted but not the empty box
  EXPECT_THROW(BoxTree{boxes}, std::invalid_argument);
  boxes[2] = box(Vec3::Zero(), Vec3(std::numeric_limits<double>::infinity(), 1, 1));
  EXPECT_THROW(BoxTree{boxes}, std::invalid_argument);
  const BoxTree ok(random_boxes(3, 10, 1.0, 0.1));
  std::vector<std::uint32_t> got;
  EXPECT_THROW(ok.overlapping(box(Vec3::Zero(), Vec3(1, std::nan(""), 1)), got), std::invalid_argument);
  EXPECT_THROW(ok.overlapping(box(Vec3::Ones(), Vec3::Zero()), got), std::invalid_argument);
}

RC_GTEST_PROP(BoxTree, OverlappingEqualsBruteForce, ()) {
  const int n = *rc::gen::inRange(0, 200);
  const int grid = *rc::gen::inRange(1, 6);  // coarse integer corners: many exact touches
  auto gen_box = [&] {
    Vec3 lo, hi;
    for (int k = 0; k < 3; ++k) {
      const int a = *rc::gen::inRange(0, grid + 1), b = *rc::gen::inRange(0, grid + 1);
      lo[k] = std::min(a, b) * 0.1;
      hi[k] = std::max(a, b) * 0.1;
    }
    return box(lo, hi);
  };
  std::vector<AABB> boxes;
  for (int i = 0; i < n; ++i) boxes.push_back(gen_box());
  const BoxTree tree(boxes);
  std::vector<std::uint32_t> got;
  for (int k = 0; k < 5; ++k) {
    const AABB q = gen_box();
    tree.overlapping(q, got);
    RC_ASSERT(got == brute_overlapping(boxes, q));
  }
}
