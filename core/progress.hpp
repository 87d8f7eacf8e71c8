#pragma once
/// Progress of long stages. Library code says how far a stage is through a
/// ProgressFn (counts of items, never fractions or timings); the command line draws the
/// reports as bars on a terminal with a ProgressBar. No global state: whoever wants
/// reports passes a function, whoever does not leaves it empty.

#include <atomic>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <mutex>
#include <string>

namespace loom {

/// How far one stage of work is.
struct ProgressEvent {
  std::string stage;      ///< what runs: "load", "index", "simplify", "plan", "audit", "render"
  std::size_t done = 0;   ///< items finished so far (never decreases within a stage)
  std::size_t total = 0;  ///< items in the stage; done == total: the stage is complete
  std::string unit;       ///< what an item is, plural: "parts", "cables", "rows", …
};

/// Receives progress reports; may be empty (nothing is reported). Library code calls it
/// one call at a time (never concurrently), but not necessarily from the caller's thread
/// (ProgressCounter forwards from TBB workers). It must be cheap: it may be called once per
/// item.
using ProgressFn = std::function<void(const ProgressEvent&)>;

/// Counts the finished items of one stage from any number of threads and forwards the count
/// to a ProgressFn, one call at a time, with `done` increasing. Reports 0/total on
/// construction (if total > 0); add() reports at most total − 1 (while another thread is
/// reporting, add() skips its report instead of waiting, so workers never queue behind the
/// terminal); finish() reports total/total, the "stage complete" event, exactly once (0/0
/// for an empty stage). An empty function makes every call a no-op.
class ProgressCounter {
 public:
  /// Starts the stage `stage` of `total` items counted in `unit`.
  ProgressCounter(ProgressFn fn, std::string stage, std::size_t total, std::string unit);
  ProgressCounter(const ProgressCounter&) = delete;
  ProgressCounter& operator=(const ProgressCounter&) = delete;

  /// Adds `n` finished items; thread-safe.
  void add(std::size_t n = 1);
  /// Reports the stage complete (done = total). Later calls do nothing. Thread-safe.
  void finish();

 private:
  void report_locked(std::size_t done);

  ProgressFn fn_;
  std::string stage_;
  std::size_t total_;
  std::string unit_;
  std::atomic<std::size_t> done_{0};
  std::mutex mutex_;              ///< serialises calls of fn_
  std::size_t last_reported_ = 0;  ///< guarded by mutex_
  bool finished_ = false;          ///< guarded by mutex_
};

/// Draws progress reports as one updating line per stage on a terminal:
///   `audit    [#########...........]  12/40 cables  30%  3.1 cables/s  0:04  ETA 0:09`
/// and, when the stage completes, a final line with the count, the mean rate and the time
/// it took, ended by a newline. A running line is redrawn at most once per
/// Options::min_interval, so a report per item costs a clock read and a compare. It draws
/// only when the stream is a terminal (isatty) and not quiet, unless forced (tests).
/// report() is thread-safe.
class ProgressBar {
 public:
  /// Seconds on a monotonic clock.
  using Clock = std::function<double()>;

  /// How to draw.
  struct Options {
    bool quiet = false;  ///< --quiet / --json: draw nothing
    bool force = false;  ///< draw even when the stream is not a terminal (tests)
    /// Least time between two redraws of a running stage (seconds): ≈10 Hz, as smooth as
    /// the eye needs and negligible next to any work worth a bar.
    double min_interval = 0.1;
    int bar_width = 24;  ///< characters between the brackets
    Clock clock;         ///< empty: std::chrono::steady_clock
  };

  /// Draws on `out` (e.g. stderr) if it is a terminal and not quiet, or if forced.
  ProgressBar(std::FILE* out, Options opt);
  /// Draws on `out` if it is a terminal and not `quiet` (the command line's --quiet/--json).
  explicit ProgressBar(std::FILE* out, bool quiet = false);
  /// Ends a line left running (a stage that did not complete, e.g. after an error).
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// True when reports are drawn.
  bool enabled() const { return enabled_; }
  /// Draws (or, throttled, skips) one report. Thread-safe.
  void report(const ProgressEvent& e);
  /// A ProgressFn drawing on this bar (which must outlive it); empty when not enabled, so
  /// library code skips the reporting altogether.
  ProgressFn fn();
  /// Lines drawn or redrawn so far (for tests of the throttling).
  std::size_t redraws() const;

 private:
  double now() const;
  void draw_locked(const ProgressEvent& e, double t, bool final_line);

  std::FILE* out_;
  Options opt_;
  bool enabled_;
  mutable std::mutex mutex_;
  std::string stage_;        ///< stage of the current line; empty: none
  bool line_open_ = false;   ///< a running line is on screen (no newline yet)
  bool stage_done_ = false;  ///< the current stage's final line was drawn
  double stage_start_ = 0.0;
  double last_draw_ = 0.0;
  std::size_t redraws_ = 0;
};

}  // namespace loom
