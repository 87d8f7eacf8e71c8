#pragma once
/// Wall time of a stage on a monotonic clock (std::chrono::steady_clock), for the timings
/// that reports and benchmarks carry.

#include <chrono>

namespace loom {

/// Measures the time since it was started (constructed, or restarted).
class Stopwatch {
 public:
  using Clock = std::chrono::steady_clock;
  /// Starts now.
  Stopwatch() = default;
  /// Starts again from now.
  void restart() { start_ = Clock::now(); }
  /// Milliseconds since the start.
  double ms() const { return std::chrono::duration<double, std::milli>(Clock::now() - start_).count(); }
  /// Seconds since the start.
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  Clock::time_point start_ = Clock::now();
};

}  // namespace loom
