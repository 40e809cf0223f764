#pragma once
// A one-line progress bar on stderr for long runs; silent when stderr is not a terminal (CI logs,
// pipes), so output files and captured logs stay clean. Safe to advance from several threads.
#include <cstdio>
#include <mutex>
#include <string>
#include <unistd.h>

namespace sextant::runner {

class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total)
      : label_(std::move(label)), total_(total), enabled_(total > 0 && isatty(STDERR_FILENO)) {}
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ~ProgressBar() {
    if (enabled_ && drawn_) std::fprintf(stderr, "\r%*s\r", 80, "");
  }

  /// Counts one more unit of work done and redraws when the shown percentage changes.
  void advance() {
    std::lock_guard lock(mutex_);
    ++done_;
    if (!enabled_) return;
    const int percent = static_cast<int>(100 * done_ / total_);
    if (percent == shown_) return;
    shown_ = percent;
    const int width = 30, filled = width * percent / 100;
    std::fprintf(stderr, "\r%-36.36s [%s%s] %3d%%", label_.c_str(), std::string(filled, '=').c_str(),
                 std::string(width - filled, ' ').c_str(), percent);
    std::fflush(stderr);
    drawn_ = true;
  }

 private:
  std::string label_;
  std::size_t total_, done_ = 0;
  bool enabled_, drawn_ = false;
  int shown_ = -1;
  std::mutex mutex_;
};

}  // namespace sextant::runner
