#pragma once
/// \file OpenCV's worker threads set for a scope and restored after it: the runner's stereo runs and
/// the front-end benchmark both run AKAZE/ORB with one OpenCV thread (docs/results/real_time.md,
/// "Camera rate": the two images already use both cores).

#include <opencv2/core.hpp>

namespace sextant::vision {

/// Sets OpenCV's worker threads for its lifetime and restores the previous setting; 0 leaves it.
class OpenCvThreads {
 public:
  explicit OpenCvThreads(int threads) : previous_(cv::getNumThreads()) {
    if (threads > 0) cv::setNumThreads(threads);
  }
  ~OpenCvThreads() { cv::setNumThreads(previous_); }
  OpenCvThreads(const OpenCvThreads&) = delete;
  OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
  int previous_;
};

}  // namespace sextant::vision
