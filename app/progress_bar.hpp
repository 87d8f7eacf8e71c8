#pragma once
/// The command line's progress bars: ProgressEvent reports drawn on a terminal.

#include "core/progress.hpp"

#include <cstddef>
#include <cstdio>
#include <functional>
#include <mutex>
#include <string>

namespace loom {

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
