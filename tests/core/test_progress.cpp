// ProgressCounter's event sequence: starts at 0, completes only on finish(), never
// decreases.
#include "core/progress.hpp"
#include "common/progress_recorder.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

namespace loom {
namespace {

TEST(ProgressCounter, SequenceStartsAtZeroAndCompletesOnlyOnFinish) {
  ProgressRecorder rec;
  {
    ProgressCounter c(rec.fn(), "simplify", 3, "parts");
    for (int i = 0; i < 5; ++i) c.add();  // more adds than items: still not "complete"
    c.finish();
    c.finish();
  }
  ASSERT_GE(rec.events.size(), 2u);
  EXPECT_EQ(rec.events.front().done, 0u);
  EXPECT_EQ(rec.events.front().stage, "simplify");
  EXPECT_EQ(rec.events.front().unit, "parts");
  for (std::size_t i = 0; i + 1 < rec.events.size(); ++i) EXPECT_LT(rec.events[i].done, 3u);
  EXPECT_EQ(rec.events.back().done, 3u);
  EXPECT_EQ(rec.events.back().total, 3u);
  EXPECT_EQ(std::count_if(rec.events.begin(), rec.events.end(), [](const ProgressEvent& e) { return e.done == 3; }), 1);

  ProgressRecorder empty;
  {
    ProgressCounter c(empty.fn(), "audit", 0, "cables");
    c.finish();
  }
  ASSERT_EQ(empty.events.size(), 1u);
  EXPECT_EQ(empty.events[0].done, 0u);
  EXPECT_EQ(empty.events[0].total, 0u);

  ProgressCounter none(ProgressFn(), "audit", 10, "cables");  // no function: no-ops
  none.add();
  none.finish();
}

}  // namespace
}  // namespace loom
