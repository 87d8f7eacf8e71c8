#pragma once
// A ProgressFn that records a counter's events and notes whether two were ever delivered
// at once (the tests of ProgressCounter and of the command line's bar behind it).
#include "core/progress.hpp"

#include <atomic>
#include <thread>
#include <vector>

namespace loom {

/// Records a counter's events and checks they are never delivered concurrently.
struct ProgressRecorder {
  std::atomic<int> inside{0};
  std::atomic<bool> overlapped{false};
  std::vector<ProgressEvent> events;  // written only inside the (exclusive) callback
  ProgressFn fn() {
    return [this](const ProgressEvent& e) {
      if (inside.fetch_add(1) != 0) overlapped = true;
      events.push_back(e);
      std::this_thread::yield();  // widen the window an overlap would need
      inside.fetch_sub(1);
    };
  }
};

}  // namespace loom
