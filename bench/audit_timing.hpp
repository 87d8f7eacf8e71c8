#pragma once
/// Timing of audit runs for the audit benches: wall clock and process CPU time, best of
/// several runs of check_clashes.
#include "core/part.hpp"
#include "index/obstacle_index.hpp"
#include "routing/audit/clash_check.hpp"

#include <chrono>
#include <ctime>
#include <utility>
#include <vector>

namespace loom::bench {

/// Wall clock, ms (steady clock, arbitrary origin).
inline double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Process CPU time (all threads), ms: the work done, robust to other load on the machine.
inline double cpu_ms() { return 1000.0 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

/// One audit, timed: its result and the best run's times.
struct Timed {
  ClashResult res;
  double ms = 0.0;   ///< wall clock, best run
  double cpu = 0.0;  ///< process CPU time of that run
};

/// check_clashes(cables, parts, index, req), best of `reps` runs (by wall clock).
inline Timed timed_check(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                         const ObstacleIndex* index, const ClashRequest& req, int reps) {
  Timed t;
  t.ms = 1e300;
  for (int i = 0; i < reps; ++i) {
    const double t0 = now_ms(), c0 = cpu_ms();
    ClashResult r = check_clashes(cables, parts, index, req);
    const double dt = now_ms() - t0, dc = cpu_ms() - c0;
    if (dt < t.ms) {
      t.ms = dt;
      t.cpu = dc;
      t.res = std::move(r);
    }
  }
  return t;
}

}  // namespace loom::bench
