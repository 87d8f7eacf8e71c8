// The command line's ProgressBar: drawing, throttling and thread-safety, also behind a
// ProgressCounter fed from many threads. Time is an injected clock; nothing asserts on real time.
#include "app/progress_bar.hpp"
#include "common/progress_recorder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace loom {
namespace {

/// A temporary file (not a terminal) that the bar writes into.
struct TempFile {
  std::FILE* f = std::tmpfile();
  ~TempFile() {
    if (f) std::fclose(f);
  }
  /// Everything written so far.
  std::string text() const {
    std::fflush(f);
    std::rewind(f);
    std::string s;
    for (int c; (c = std::fgetc(f)) != EOF;) s += static_cast<char>(c);
    return s;
  }
};

/// A clock the test sets by hand (seconds).
struct ManualClock {
  std::shared_ptr<std::atomic<double>> t = std::make_shared<std::atomic<double>>(0.0);
  ProgressBar::Clock fn() const {
    auto p = t;
    return [p] { return p->load(); };
  }
  void set(double s) const { t->store(s); }
};

ProgressBar::Options forced(const ManualClock& clock) {
  ProgressBar::Options o;
  o.force = true;
  o.clock = clock.fn();
  return o;
}

bool has(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

TEST(ProgressBar, ForcedBarShowsCountsRateEtaAndFinalLine) {
  TempFile tf;
  ManualClock clock;
  {
    ProgressBar bar(tf.f, forced(clock));
    ASSERT_TRUE(bar.enabled());
    const ProgressFn fn = bar.fn();
    ASSERT_TRUE(static_cast<bool>(fn));
    fn({"audit", 0, 40, "cables"});
    clock.set(2.0);
    fn({"audit", 10, 40, "cables"});  // 10 cables in 2 s: 5 cables/s, 30 left: ETA 6 s
    const std::string running = tf.text();
    EXPECT_TRUE(has(running, "audit")) << running;
    EXPECT_TRUE(has(running, "10/40 cables")) << running;
    EXPECT_TRUE(has(running, " 25%")) << running;
    EXPECT_TRUE(has(running, "5 cables/s")) << running;
    EXPECT_TRUE(has(running, "ETA 6.0s")) << running;
    EXPECT_TRUE(has(running, "[######..................]")) << running;  // 6 of 24 = 25 %
    EXPECT_EQ(running.find('\n'), std::string::npos) << "a running stage stays on one line";
    clock.set(4.0);
    fn({"audit", 40, 40, "cables"});
    EXPECT_EQ(bar.redraws(), 3u);
  }
  const std::string s = tf.text();
  const std::string last = s.substr(s.rfind('\r'));
  EXPECT_TRUE(has(last, "40/40 cables")) << last;
  EXPECT_TRUE(has(last, "10 cables/s")) << last;  // the mean: 40 in 4 s
  EXPECT_TRUE(has(last, "in 4.0s")) << last;
  EXPECT_TRUE(has(last, "[########################]")) << last;
  EXPECT_FALSE(has(last, "ETA")) << last;
  EXPECT_EQ(s.back(), '\n') << "the final line ends the stage";
  EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 1) << "the destructor adds nothing after a completed stage";
}

TEST(ProgressBar, NotATerminalOrQuietDrawsNothing) {
  TempFile tf;
  {
    ProgressBar bar(tf.f);  // a regular file is not a terminal
    EXPECT_FALSE(bar.enabled());
    EXPECT_FALSE(static_cast<bool>(bar.fn())) << "library code gets no function, so it skips reporting";
    bar.report({"load", 1, 2, "parts"});
    bar.report({"load", 2, 2, "parts"});
    EXPECT_EQ(bar.redraws(), 0u);
  }
  {
    ProgressBar::Options o;
    o.force = true;
    o.quiet = true;  // --quiet wins over force
    ProgressBar bar(tf.f, o);
    EXPECT_FALSE(bar.enabled());
    bar.report({"load", 2, 2, "parts"});
  }
  EXPECT_TRUE(tf.text().empty()) << tf.text();
}

TEST(ProgressBar, ManyReportsFewRedraws) {
  TempFile tf;
  ManualClock clock;
  ProgressBar bar(tf.f, forced(clock));
  // 10 000 reports, one per millisecond: 10 s of work, a redraw per 0.1 s at most.
  constexpr std::size_t kEvents = 10000;
  constexpr double kStep = 0.001;
  for (std::size_t i = 0; i < kEvents; ++i) {
    clock.set(static_cast<double>(i) * kStep);
    bar.report({"plan", i, kEvents, "segments"});
  }
  clock.set(static_cast<double>(kEvents) * kStep);
  bar.report({"plan", kEvents, kEvents, "segments"});
  // Oracle: the first draw, one per full 0.1 s interval (99 or 100 by rounding), the final.
  const auto intervals = static_cast<std::size_t>(std::lround(static_cast<double>(kEvents) * kStep / 0.1));
  EXPECT_GE(bar.redraws(), intervals);
  EXPECT_LE(bar.redraws(), intervals + 2);
  const std::string s = tf.text();
  EXPECT_EQ(static_cast<std::size_t>(std::count(s.begin(), s.end(), '\r')), bar.redraws());
  EXPECT_TRUE(has(s.substr(s.rfind('\r')), "10000/10000 segments")) << "completion is never throttled";
}

TEST(ProgressBar, NewStageEndsTheRunningLineAndRepeatsAreIgnored) {
  TempFile tf;
  ManualClock clock;
  {
    ProgressBar bar(tf.f, forced(clock));
    bar.report({"load", 1, 3, "parts"});  // left running
    bar.report({"index", 0, 1, "indices"});
    bar.report({"index", 1, 1, "indices"});
    bar.report({"index", 1, 1, "indices"});  // a repeated completion: not drawn again
    EXPECT_EQ(bar.redraws(), 3u);
    bar.report({"render", 0, 0, "rows"});  // an empty stage is complete at once
    EXPECT_EQ(bar.redraws(), 4u);
    bar.report({"audit", 2, 5, "cables"});  // left running: the destructor ends the line
  }
  const std::string s = tf.text();
  EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 4) << s;
  EXPECT_TRUE(has(s, "1/3 parts")) << s;
  EXPECT_TRUE(has(s, "0/0 rows")) << s;
  EXPECT_EQ(s.back(), '\n');
}

TEST(ProgressCounter, ConcurrentReportsAreSerialisedAndIncreasing) {
  constexpr int kThreads = 8;
  constexpr std::size_t kPerThread = 5000;
  constexpr std::size_t kTotal = kThreads * kPerThread;
  ProgressRecorder rec;
  TempFile tf;
  ManualClock clock;
  ProgressBar::Options o = forced(clock);
  o.min_interval = 0.0;  // draw every report: the most contention on the bar
  ProgressBar bar(tf.f, o);
  const ProgressFn draw = bar.fn();
  const ProgressFn record = rec.fn();
  {
    ProgressCounter c([&](const ProgressEvent& e) { record(e); draw(e); }, "audit", kTotal, "cables");
    std::vector<std::thread> workers;
    for (int t = 0; t < kThreads; ++t)
      workers.emplace_back([&] {
        for (std::size_t i = 0; i < kPerThread; ++i) c.add();
      });
    // Meanwhile, other threads report to the bar directly.
    std::vector<std::thread> direct;
    for (int t = 0; t < 2; ++t)
      direct.emplace_back([&, t] {
        for (std::size_t i = 0; i < kPerThread; ++i) bar.report({"other" + std::to_string(t), i, kPerThread, "x"});
      });
    for (auto& w : workers) w.join();
    for (auto& w : direct) w.join();
    c.finish();
  }
  EXPECT_FALSE(rec.overlapped.load()) << "the callback ran concurrently";
  ASSERT_FALSE(rec.events.empty());
  for (std::size_t i = 1; i < rec.events.size(); ++i) EXPECT_LT(rec.events[i - 1].done, rec.events[i].done) << i;
  EXPECT_EQ(rec.events.back().done, kTotal);
  // Every drawn line is whole: it starts with a stage name right after its '\r'.
  const std::string s = tf.text();
  std::size_t lines = 0;
  for (std::size_t p = s.find('\r'); p != std::string::npos; p = s.find('\r', p + 1)) {
    const std::string head = s.substr(p + 1, 5);
    EXPECT_TRUE(head == "audit" || head == "other") << "torn line at " << p << ": " << s.substr(p, 40);
    ++lines;
  }
  EXPECT_EQ(lines, bar.redraws());
}

}  // namespace
}  // namespace loom
