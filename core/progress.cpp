#include "core/progress.hpp"

#include <algorithm>
#include <utility>

namespace loom {

// --- ProgressCounter ----------------------------------------------------------------------

ProgressCounter::ProgressCounter(ProgressFn fn, std::string stage, std::size_t total, std::string unit)
    : fn_(std::move(fn)), stage_(std::move(stage)), total_(total), unit_(std::move(unit)) {
  if (fn_ && total_ > 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    report_locked(0);
  }
}

void ProgressCounter::add(std::size_t n) {
  const std::size_t d = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (!fn_ || total_ == 0) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;  // the reporting thread's count, or the next, covers this
  const std::size_t shown = std::min(std::max(d, done_.load(std::memory_order_relaxed)), total_ - 1);
  if (shown > last_reported_) report_locked(shown);
}

void ProgressCounter::finish() {
  if (!fn_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  report_locked(total_);
}

void ProgressCounter::report_locked(std::size_t done) {
  last_reported_ = done;
  fn_(ProgressEvent{stage_, done, total_, unit_});
}

}  // namespace loom
