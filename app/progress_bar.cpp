#include "app/progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace loom {

namespace {

/// Width of the stage name column (the longest stage name, "simplify", fits).
constexpr int kStageColumn = 8;
/// Seconds per minute and per hour, for m:ss and h:mm:ss.
constexpr long kMinute = 60;
constexpr long kHour = 3600;

/// A rate in about three significant digits: 0.25, 9.5, 950, 8090, 12.3k, 4.56M.
std::string short_number(double v) {
  char buf[32];
  if (v >= 1e9) std::snprintf(buf, sizeof buf, "%.3gG", v / 1e9);
  else if (v >= 1e6) std::snprintf(buf, sizeof buf, "%.3gM", v / 1e6);
  else if (v >= 1e4) std::snprintf(buf, sizeof buf, "%.3gk", v / 1e3);
  else if (v >= 100) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// A duration: 4.2s below a minute, else m:ss or h:mm:ss.
std::string duration(double seconds) {
  char buf[32];
  if (!(seconds < kMinute)) {
    const long s = std::lround(seconds);
    if (s >= kHour) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / kHour, s % kHour / kMinute, s % kMinute);
    else std::snprintf(buf, sizeof buf, "%ld:%02ld", s / kMinute, s % kMinute);
  } else {
    std::snprintf(buf, sizeof buf, "%.1fs", std::max(0.0, seconds));
  }
  return buf;
}

}  // namespace

ProgressBar::ProgressBar(std::FILE* out, Options opt)
    : out_(out), opt_(std::move(opt)),
      enabled_(out != nullptr && !opt_.quiet && (opt_.force || ::isatty(::fileno(out)) == 1)) {}

namespace {
ProgressBar::Options quiet_options(bool quiet) {
  ProgressBar::Options o;
  o.quiet = quiet;
  return o;
}
}  // namespace

ProgressBar::ProgressBar(std::FILE* out, bool quiet) : ProgressBar(out, quiet_options(quiet)) {}

ProgressBar::~ProgressBar() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (enabled_ && line_open_) {
    std::fputc('\n', out_);
    std::fflush(out_);
  }
}

double ProgressBar::now() const {
  if (opt_.clock) return opt_.clock();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

ProgressFn ProgressBar::fn() {
  if (!enabled_) return {};
  return [this](const ProgressEvent& e) { report(e); };
}

std::size_t ProgressBar::redraws() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return redraws_;
}

void ProgressBar::report(const ProgressEvent& e) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const double t = now();
  const bool complete = e.done >= e.total;
  if (e.stage == stage_ && stage_done_ && complete) return;  // the completion again: already drawn
  if (e.stage != stage_ || stage_done_) {
    // A new stage (or a new run of the last one): the previous line stays as it was.
    if (line_open_) std::fputc('\n', out_);
    line_open_ = false;
    stage_ = e.stage;
    stage_done_ = false;
    stage_start_ = t;
  } else if (!complete && t - last_draw_ < opt_.min_interval) {
    return;  // throttled
  }
  draw_locked(e, t, complete);
}

void ProgressBar::draw_locked(const ProgressEvent& e, double t, bool final_line) {
  const double elapsed = t - stage_start_;
  // Before one redraw interval has passed, a rate (and an ETA) is start-up noise.
  const double rate = elapsed >= opt_.min_interval && elapsed > 0.0 ? static_cast<double>(e.done) / elapsed : 0.0;
  const std::string unit = e.unit.empty() ? std::string() : " " + e.unit;
  std::string line = "\r";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%-*s ", kStageColumn, e.stage.c_str());
  line += buf;
  const double frac = e.total > 0 ? std::min(1.0, static_cast<double>(e.done) / static_cast<double>(e.total)) : 1.0;
  const int width = std::max(1, opt_.bar_width);
  const int filled = static_cast<int>(std::floor(frac * width));
  line += "[" + std::string(static_cast<std::size_t>(filled), '#') + std::string(static_cast<std::size_t>(width - filled), '.') + "]";
  std::snprintf(buf, sizeof buf, "  %zu/%zu", e.done, e.total);
  line += buf + unit;
  if (!final_line) {
    std::snprintf(buf, sizeof buf, "  %3.0f%%", 100.0 * frac);
    line += buf;
  }
  if (rate > 0.0) line += "  " + short_number(rate) + unit + "/s";
  if (final_line) {
    line += "  in " + duration(elapsed);
  } else {
    line += "  " + duration(elapsed);
    if (rate > 0.0 && e.total > e.done) line += "  ETA " + duration(static_cast<double>(e.total - e.done) / rate);
  }
  line += "\x1b[K";  // clear what a longer previous line left
  if (final_line) line += "\n";
  std::fputs(line.c_str(), out_);
  std::fflush(out_);
  ++redraws_;
  last_draw_ = t;
  line_open_ = !final_line;
  stage_done_ = final_line;
}

}  // namespace loom
