#pragma once
/// \file The image half of the stereo front-end: one rectified pair in, its stereo features out,
/// each a 3D point in the left camera frame (the thesis's PointInCamera3D measurement) with its left
/// keypoint and descriptor, strongest first; the time of each stage (the thesis's Figure 26 split).
/// The left and right images are detected in parallel, each by its own detector.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <numeric>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sextant/vision/disparity_support.hpp"
#include "sextant/vision/features.hpp"
#include "sextant/vision/row_search_matching.hpp"
#include "sextant/vision/slant_noise.hpp"
#include "sextant/vision/slanted_correlation.hpp"
#include "sextant/vision/stereo_matching.hpp"
#include "sextant/vision/stereo_triangulation.hpp"

namespace sextant::vision {

/// Where a left feature's partner comes from: a feature detected in the right image too (matched
/// along the rows by descriptor), or a correlation search along the right image's row (no right
/// detection: half the detector's work).
enum class StereoCorrespondence { detect_both, row_search };

struct FrontEndOptions {
  DetectorOptions detector{};
  StereoMatchOptions matching{};
  bool parallel_detection = true;  ///< detect_both: left and right on two threads
  StereoCorrespondence correspondence = StereoCorrespondence::detect_both;
  RowSearchOptions row_search{};   ///< row_search's settings
  RightRefinementOptions right_refinement{};  ///< detect_both: the right x by correlation (off by default)
  /// Each match's disparity by correlation along the surface's slant (vision/slanted_correlation.hpp: the
  /// right image warped by the disparity's second-order shape, fitted to the match's neighbours), after
  /// right_refinement: the right image's stretch on a slanted surface no longer shortens it.
  bool slanted_correlation = false;
  SlantedCorrelationOptions slanted{};
  /// px: a match of smaller disparity is dropped before triangulation (significant_disparity gives
  /// the bound for a number of standard deviations). 0 keeps every match: a wrong match at a pixel of
  /// disparity on the rendered globe becomes a landmark 170 m deep that the sparse filters' mean
  /// recovery cannot hold (docs/results/real_time.md, "A disparity floor").
  double min_disparity = 0.0;
  /// A match is dropped when its disparity is not borne out by its neighbours' (vision/disparity_support.hpp),
  /// judged among the matches the floor keeps: a wrong match far off the surface never becomes a landmark.
  bool disparity_support = false;
  DisparitySupportOptions support{};
  /// Each point's noise scaled by 1 / cos of the slant of the surface around it (vision/slant_noise.hpp):
  /// features seen obliquely weigh less instead of being dropped or trusted as frontal ones.
  bool slant_noise = false;
  SlantNoiseOptions slant{};
};

/// One stereo match as a measurement.
struct StereoFeature {
  Eigen::Vector2d left_px = Eigen::Vector2d::Zero(), right_px = Eigen::Vector2d::Zero();
  float size = 0.0f, response = 0.0f;  ///< of the left keypoint
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< in the left camera frame (x right, y down, z forward)
  double noise_scale = 1.0;  ///< its noise against the stereo model's (FrontEndOptions::slant_noise; 1 without)
};

/// Seconds per stage of one frame.
struct FrontEndTimes {
  double detect = 0.0, match = 0.0, triangulate = 0.0;
};

struct StereoFrame {
  std::vector<StereoFeature> features;  ///< strongest left response first
  cv::Mat descriptors;                  ///< row i: the left descriptor of features[i]
  std::size_t left_keypoints = 0, right_keypoints = 0;
  std::size_t below_min_disparity = 0;  ///< matches dropped by FrontEndOptions::min_disparity
  std::size_t without_support = 0;      ///< matches dropped by FrontEndOptions::disparity_support
  std::size_t right_refined = 0;        ///< matches whose right x FrontEndOptions::right_refinement moved
  std::size_t slant_refined = 0;        ///< matches whose disparity FrontEndOptions::slanted_correlation measured
  std::size_t slant_unmeasured = 0;     ///< and matches it dropped, unmeasured (SlantedCorrelationOptions::drop_unmeasured)
  FrontEndTimes times;
};

class StereoFrontEnd {
 public:
  StereoFrontEnd(StereoRig rig, FrontEndOptions options = {})
      : rig_(rig), options_(options), left_(make_detector(options.detector)), right_(make_detector(options.detector)) {
    if (!(options.min_disparity >= 0.0) || !std::isfinite(options.min_disparity))
      throw invalid_input_error("stereo front-end: min_disparity " + std::to_string(options.min_disparity) +
                                " px must be finite and >= 0");
    if (options.slant_noise) require_valid(options.slant);
    if (options.disparity_support) require_valid(options.support);
    require_valid(options.right_refinement);
    if (options.slanted_correlation) require_valid(options.slanted);
  }

  const StereoRig& rig() const { return rig_; }
  const FrontEndOptions& options() const { return options_; }

  /// Detect, match along the rows, triangulate. Throws invalid_input_error for empty or non-8-bit
  /// images or a left and right of different sizes; a pair without features gives an empty frame.
  StereoFrame process(const cv::Mat& left, const cv::Mat& right) {
    if (left.size() != right.size())
      throw invalid_input_error("stereo front-end: left image " + size_text(left) + " and right image " +
                                size_text(right) + " differ in size");
    using Clock = std::chrono::steady_clock;
    StereoFrame out;
    auto start = Clock::now();
    auto lap = [&](double& seconds) {
      const auto now = Clock::now();
      seconds = std::chrono::duration<double>(now - start).count();
      start = now;
    };
    Features left_features;
    std::vector<StereoMatch> matches;
    if (options_.correspondence == StereoCorrespondence::row_search) {
      left_features = detect(left, *left_);
      out.left_keypoints = left_features.keypoints.size();
      lap(out.times.detect);
      matches = search_rows(left, right, left_features, options_.row_search);
    } else {
      auto [l, r] = detect_both(left, right);
      left_features = std::move(l);
      out.left_keypoints = left_features.keypoints.size();
      out.right_keypoints = r.keypoints.size();
      lap(out.times.detect);
      matches = match_stereo(left_features, r, options_.matching);
      out.right_refined = refine_right_by_correlation(left, right, matches, options_.right_refinement);
    }
    if (options_.slanted_correlation) {
      const auto refined = refine_right_along_slant(left, right, matches, options_.slanted);
      out.slant_refined = refined.measured;
      out.slant_unmeasured = refined.dropped;
    }
    strongest_first(matches, left_features);
    lap(out.times.match);
    triangulate_matches(matches, left_features, out);
    lap(out.times.triangulate);
    return out;
  }

 private:
  static std::string size_text(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

  std::pair<Features, Features> detect_both(const cv::Mat& left, const cv::Mat& right) {
    if (!options_.parallel_detection) return {detect(left, *left_), detect(right, *right_)};
    auto right_job = std::async(std::launch::async, [&] { return detect(right, *right_); });
    Features l = detect(left, *left_);
    return {std::move(l), right_job.get()};
  }

  static void strongest_first(std::vector<StereoMatch>& matches, const Features& left) {
    std::stable_sort(matches.begin(), matches.end(), [&](const StereoMatch& a, const StereoMatch& b) {
      return left.keypoints[static_cast<std::size_t>(a.left)].response > left.keypoints[static_cast<std::size_t>(b.left)].response;
    });
  }

  void triangulate_matches(std::vector<StereoMatch>& matches, const Features& left, StereoFrame& out) const {
    const auto too_small = [&](const StereoMatch& m) { return m.disparity() < options_.min_disparity; };
    out.below_min_disparity = static_cast<std::size_t>(std::erase_if(matches, too_small));
    if (options_.disparity_support) out.without_support = drop_unsupported(matches);
    out.features.reserve(matches.size());
    out.descriptors.create(static_cast<int>(matches.size()), left.descriptors.cols, left.descriptors.type());
    for (std::size_t i = 0; i < matches.size(); ++i) {
      const StereoMatch& m = matches[i];
      const cv::KeyPoint& k = left.keypoints[static_cast<std::size_t>(m.left)];
      out.features.push_back({m.left_px, m.right_px, k.size, k.response, triangulate(rig_, m)});
      left.descriptors.row(m.left).copyTo(out.descriptors.row(static_cast<int>(i)));
    }
    if (options_.slant_noise) scale_noise_by_slant(out.features);
  }

  /// Drops the matches whose disparity their neighbours' plane does not predict; returns how many.
  std::size_t drop_unsupported(std::vector<StereoMatch>& matches) const {
    std::vector<Eigen::Vector2d> pixels;
    std::vector<double> disparities;
    for (const auto& m : matches) pixels.push_back(m.left_px), disparities.push_back(m.disparity());
    const auto kept = disparity_supported(pixels, disparities, options_.support);
    std::vector<StereoMatch> supported;
    supported.reserve(matches.size());
    for (std::size_t i = 0; i < matches.size(); ++i)
      if (kept[i]) supported.push_back(matches[i]);
    const std::size_t dropped = matches.size() - supported.size();
    matches = std::move(supported);
    return dropped;
  }

  void scale_noise_by_slant(std::vector<StereoFeature>& features) const {
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Vector3d> points;
    for (const auto& f : features) pixels.push_back(f.left_px), points.push_back(f.point);
    const auto scales = slant_noise_scales(pixels, points, options_.slant);
    for (std::size_t i = 0; i < features.size(); ++i) features[i].noise_scale = scales[i];
  }

  StereoRig rig_;
  FrontEndOptions options_;
  cv::Ptr<cv::Feature2D> left_, right_;
};

}  // namespace sextant::vision
