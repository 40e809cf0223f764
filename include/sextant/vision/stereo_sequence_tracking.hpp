#pragma once
/// \file A stereo sequence through a StereoTracker, one frame after another or pipelined: frame
/// k+1's front-end (detect, match, triangulate) on a second thread while frame k is associated and
/// filtered, as a live camera allows (frame k+1 has arrived by then). The front-end reads no filter
/// state, so both give the same frames; only the wall clock differs, and it is what this measures.

#include <chrono>
#include <cstddef>
#include <exception>
#include <future>
#include <opencv2/core.hpp>
#include <utility>

#include "sextant/core/seconds_since.hpp"
#include "sextant/vision/stereo_front_end.hpp"

namespace sextant::vision {

/// One rectified pair as the camera delivers it.
struct StereoPair {
  cv::Mat left, right;
};

/// Wall-clock seconds over a sequence, the camera's own time (delivering the pairs) and what the
/// caller does with each result left out.
struct SequenceClock {
  std::size_t frames = 0;
  double seconds = 0.0;
  double frames_per_second() const { return seconds > 0.0 ? static_cast<double>(frames) / seconds : 0.0; }
};

/// Tracks frames 0..n-1 with `tracker`: `pair_of(k)` gives frame k's StereoPair, `dt_of(k)` the time
/// since the previous frame, `on_frame(k, tracked)` receives each TrackedFrame in order. With
/// `pipelined`, frame k+1's observe runs on its own thread during frame k's incorporate. Either way
/// an exception propagates once on_frame has received every frame the tracker incorporated (a bad
/// pair k+1 in the pipeline: after frame k's), so the caller and the tracker agree on where it stopped.
template <class Tracker, class PairOf, class DtOf, class OnFrame>
SequenceClock track_sequence(Tracker& tracker, std::size_t n, PairOf&& pair_of, DtOf&& dt_of, OnFrame&& on_frame,
                             bool pipelined) {
  using Clock = std::chrono::steady_clock;
  SequenceClock clock{n, 0.0};
  if (!pipelined) {
    for (std::size_t k = 0; k < n; ++k) {
      const StereoPair pair = pair_of(k);
      const auto start = Clock::now();
      auto tracked = tracker.track(pair.left, pair.right, {}, dt_of(k));
      clock.seconds += seconds_since(start);
      on_frame(k, tracked);
    }
    return clock;
  }
  if (n == 0) return clock;
  StereoPair pair = pair_of(0);
  auto start = Clock::now();
  StereoFrame frame = tracker.observe(pair.left, pair.right);
  clock.seconds += seconds_since(start);
  for (std::size_t k = 0; k < n; ++k) {
    const bool has_next = k + 1 < n;
    if (has_next) pair = pair_of(k + 1);
    start = Clock::now();
    std::future<StereoFrame> next;
    if (has_next) next = std::async(std::launch::async, [&] { return tracker.observe(pair.left, pair.right); });
    auto tracked = [&] {
      try {
        return tracker.incorporate(frame, {}, dt_of(k));
      } catch (...) {
        if (next.valid()) next.wait();
        throw;
      }
    }();
    std::exception_ptr next_failed;
    if (has_next) try {
        frame = next.get();
      } catch (...) {
        next_failed = std::current_exception();
      }
    clock.seconds += seconds_since(start);
    on_frame(k, tracked);
    if (next_failed) std::rethrow_exception(next_failed);
  }
  return clock;
}

}  // namespace sextant::vision
