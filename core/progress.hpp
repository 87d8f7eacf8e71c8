#pragma once
/// Progress of long stages. Library code says how far a stage is through a ProgressFn
/// (counts of items, never fractions or timings); the command line draws the reports as
/// bars on a terminal (app/progress_bar.hpp). No global state: whoever wants reports passes
/// a function, whoever does not leaves it empty.

#include <atomic>
#include <cstddef>
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

}  // namespace loom
