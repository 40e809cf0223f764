#pragma once
/// \file An OpenCV view of a GrayImage (core/gray_image.hpp; the globe renderer draws them), for the front-end.

#include <cstdint>
#include <opencv2/core.hpp>

#include "sextant/core/gray_image.hpp"

namespace sextant::vision {

/// A CV_8UC1 cv::Mat over the image's pixels, without a copy: valid while `image` lives and is not
/// resized. OpenCV's detectors and matchers only read it.
inline cv::Mat as_mat(const GrayImage& image) {
  return cv::Mat(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
}

}  // namespace sextant::vision
