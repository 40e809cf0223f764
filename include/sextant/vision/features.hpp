#pragma once
/// \file Feature detection for the stereo front-end (issue 12): KAZE (the thesis's detector), AKAZE or
/// ORB keypoints with their descriptors, on an 8-bit grayscale image.

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant::vision {

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  ///< one row per keypoint
};

/// ORB (Rublee et al., ICCV 2011: FAST corners ranked by Harris score, steered BRIEF, 256 bits) costs
/// a tenth of AKAZE's time on the rendered globe at 8 pyramid levels, a 27th at one (5.9 and 2.6 ms a
/// 640 x 480 image on one core against 62-75 for AKAZE's 2 layers, benchmarks/front_end_benchmark.cpp),
/// at integer-pixel corners: docs/results/real_time.md, "ORB: the detector a frame can afford".
enum class Detector { kaze, akaze, orb };

/// AKAZE by default: on the rendered globe it finds as many features as KAZE, its stereo matches are
/// as often right (99.5% against 98.5% for upright KAZE at the same ratio test) and it runs 5x faster
/// (66 against ~330 ms per 640 x 480 image on the 2-core machine).
struct DetectorOptions {
  Detector detector = Detector::akaze;
  float threshold = 0.001f;  ///< AKAZE's and KAZE's response threshold (OpenCV's default for both)
  /// Sublevels per octave of the nonlinear scale space (OpenCV's default 4). AKAZE's time is mostly
  /// building those levels: 2 halves it on the rendered globe; docs/results/real_time.md measures
  /// what that does to the association and the map.
  int octave_layers = 4;
  int orb_features = 2000;  ///< ORB: the strongest keypoints kept per image (by Harris score)
  /// ORB: pyramid levels, each 1.2 times coarser (OpenCV's default 8). A corner found on level l is
  /// located to 1.2^l pixels of the full image; 1 keeps every corner at full resolution (no scale
  /// invariance: for a camera whose distance to the scene changes little between frames).
  int orb_levels = 8;
};

/// A descriptor pair's largest distance for the map association (MapAssociationOptions::
/// max_descriptor_distance) that suits the detector's descriptor: 60 of AKAZE's 486 MLDB bits (measured
/// on the rendered globe, docs/results/globe_stereo.md), 50 of ORB's 256 bits (ORB-SLAM's TH_LOW, Mur-Artal
/// et al. 2015), 0.3 for KAZE's unit-length float descriptors (L2).
inline double default_max_descriptor_distance(Detector d) {
  switch (d) {
    case Detector::akaze: return 60.0;
    case Detector::orb: return 50.0;
    case Detector::kaze: return 0.3;
  }
  return 60.0;
}

/// Throws invalid_input_error naming the first setting a detector cannot be built with.
inline void require_valid(const DetectorOptions& o) {
  const auto refuse = [](const std::string& what) { throw invalid_input_error("feature detection: " + what); };
  if (!(o.threshold > 0.0f) || !std::isfinite(o.threshold))
    refuse("threshold " + std::to_string(o.threshold) + " must be finite and > 0");
  if (o.octave_layers < 1) refuse("octave_layers " + std::to_string(o.octave_layers) + " must be >= 1");
  if (o.orb_features < 1) refuse("orb_features " + std::to_string(o.orb_features) + " must be >= 1");
  if (o.orb_levels < 1) refuse("orb_levels " + std::to_string(o.orb_levels) + " must be >= 1");
}

inline cv::Ptr<cv::Feature2D> make_detector(const DetectorOptions& o) {
  require_valid(o);
  if (o.detector == Detector::akaze)
    return cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, o.threshold, 4, o.octave_layers);
  if (o.detector == Detector::orb)
    return cv::ORB::create(o.orb_features, 1.2f, o.orb_levels, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  return cv::KAZE::create(false, true, o.threshold, 4, o.octave_layers);  // upright: a rectified pair needs no rotation invariance
}

/// Keypoints and descriptors of `image` (CV_8UC1). Throws invalid_input_error for an empty image
/// or another pixel type; an image without features gives none.
inline Features detect(const cv::Mat& image, cv::Feature2D& detector) {
  if (image.empty()) throw invalid_input_error("feature detection: the image is empty");
  if (image.type() != CV_8UC1) throw invalid_input_error("feature detection: the image is not 8-bit grayscale");
  Features out;
  detector.detectAndCompute(image, cv::noArray(), out.keypoints, out.descriptors);
  return out;
}

}  // namespace sextant::vision
