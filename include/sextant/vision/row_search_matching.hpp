#pragma once
/// \file Stereo matching without features in the right image: each left keypoint of a rectified
/// pair is found in the right image by zero-mean normalized cross-correlation (ZNCC) of its patch
/// along the same row, refined to a fraction of a pixel by a parabola through the peak (the search
/// ORB-SLAM2's stereo refines its matches with; here it replaces the right image's detection, which
/// costs as much as the left's). A match must correlate strongly, stand clear of any other peak
/// on the row (repeated texture) and not lie where the search range is cut off. The same search over
/// a few pixels around a right keypoint refines a descriptor match's right x (refine_right_by_correlation).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/vision/features.hpp"
#include "sextant/vision/stereo_matching.hpp"

namespace sextant::vision {

struct RowSearchOptions {
  int half_window = 5;              ///< the patch is (2 h + 1)^2 px around the left keypoint
  double max_disparity = 250.0;     ///< px, as StereoMatchOptions::max_disparity
  double min_correlation = 0.95;     ///< ZNCC of the peak
  /// Outside the peak's own lobe (where the score falls away from it) the row must correlate below
  /// this: a row with two similar places is left unmatched.
  double max_runner_up = 0.9;
  double min_contrast = 2.0;        ///< grey levels: a flatter patch has no well-defined peak
};

namespace detail {

/// The peak's offset from the integer maximum, in (-0.5, 0.5], by a parabola through its neighbours.
inline double parabola_offset(float before, float at, float after) {
  const double curvature = static_cast<double>(before) - 2.0 * at + after;
  if (!(curvature < 0.0)) return 0.0;
  return std::clamp(0.5 * (static_cast<double>(before) - after) / curvature, -0.5, 0.5);
}

struct RowPeak {
  double x = std::nan(""), correlation = 0.0;  ///< x NaN: no match
};

/// Throws invalid_input_error, naming `what`, unless both images are 8-bit grey and of one size.
inline void require_grey_pair(const cv::Mat& left, const cv::Mat& right, const char* what) {
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size())
    throw invalid_input_error(std::string(what) + ": the images must be 8-bit grayscale of one size");
}

/// The right image prepared once per frame for many row searches: its grey levels as floats and the
/// integral images of the levels and their squares (each window's mean and variance in O(1)).
class RightImage {
 public:
  explicit RightImage(const cv::Mat& right) {
    right.convertTo(levels_, CV_32F);
    cv::integral(right, sum_, squares_, CV_64F, CV_64F);
  }
  int cols() const { return levels_.cols; }
  const float* row(int y) const { return levels_.ptr<float>(y); }
  /// Sum of the levels and of their squares over the window of `size` x `size` px at (x, y).
  std::pair<double, double> window_sums(int x, int y, int size) const {
    auto box = [&](const cv::Mat& integral) {
      return integral.at<double>(y + size, x + size) - integral.at<double>(y, x + size) - integral.at<double>(y + size, x) +
             integral.at<double>(y, x);
    };
    return {box(sum_), box(squares_)};
  }

 private:
  cv::Mat levels_, sum_, squares_;
};

/// The right image's x of the left pixel (u, v) by a ZNCC search along row v over the right image's
/// centres from .. to (cut to where the patch fits it and to disparities > 0), or none when the patch
/// leaves the image, is flat, or its peak is weak, ambiguous or at the end of the range.
/// ZNCC(c) = sum T' R / (|T'| sqrt(sum R^2 - (sum R)^2 / n)) with T' the mean-free patch (so sum T'
/// R needs no mean of R), the cross sums accumulated over all centres c of the row at once.
inline RowPeak search_row_between(const cv::Mat& left, const RightImage& right, double u, double v, int from, int to,
                                  const RowSearchOptions& o) {
  const RowPeak none;
  const int h = o.half_window, size = 2 * h + 1, iu = static_cast<int>(std::lround(u)), iv = static_cast<int>(std::lround(v));
  if (iu - h < 0 || iu + h >= left.cols || iv - h < 0 || iv + h >= left.rows) return none;
  const int first = std::max(h, from), last = std::min({to, iu - 1, right.cols() - 1 - h});
  if (last - first < 2) return none;
  const int n = last - first + 1;
  std::vector<float> patch(static_cast<std::size_t>(size * size));
  double mean = 0.0;
  for (int dy = 0; dy < size; ++dy)
    for (int dx = 0; dx < size; ++dx) mean += patch[static_cast<std::size_t>(dy * size + dx)] = left.at<std::uint8_t>(iv - h + dy, iu - h + dx);
  mean /= size * size;
  double norm = 0.0;
  for (float& t : patch) {
    t = static_cast<float>(t - mean);
    norm += static_cast<double>(t) * t;
  }
  if (std::sqrt(norm / (size * size)) < o.min_contrast) return none;
  std::vector<float> cross(static_cast<std::size_t>(n), 0.0f);
  for (int dy = 0; dy < size; ++dy) {
    const float* r = right.row(iv - h + dy) + (first - h);
    for (int dx = 0; dx < size; ++dx) {
      const float t = patch[static_cast<std::size_t>(dy * size + dx)];
      const float* rr = r + dx;
      for (int c = 0; c < n; ++c) cross[static_cast<std::size_t>(c)] += t * rr[c];
    }
  }
  std::vector<float> s(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) {
    const auto [sum, squares] = right.window_sums(first + c - h, iv - h, size);
    const double variance = squares - sum * sum / (size * size);
    s[static_cast<std::size_t>(c)] = variance > 0.0 ? static_cast<float>(cross[static_cast<std::size_t>(c)] / std::sqrt(norm * variance)) : 0.0f;
  }
  const int best = static_cast<int>(std::max_element(s.begin(), s.end()) - s.begin());
  if (!(s[static_cast<std::size_t>(best)] >= o.min_correlation) || best == 0 || best == n - 1) return none;
  // The peak's own lobe: from the best down to where the score stops falling on either side.
  int lo = best, hi = best;
  while (lo > 0 && s[static_cast<std::size_t>(lo - 1)] <= s[static_cast<std::size_t>(lo)]) --lo;
  while (hi < n - 1 && s[static_cast<std::size_t>(hi + 1)] <= s[static_cast<std::size_t>(hi)]) ++hi;
  for (int k = 0; k < n; ++k)
    if ((k < lo || k > hi) && s[static_cast<std::size_t>(k)] >= o.max_runner_up) return none;
  const std::size_t b = static_cast<std::size_t>(best);
  return {first + best + parabola_offset(s[b - 1], s[b], s[b + 1]) + (u - iu), s[b]};
}

/// search_row_between over the whole row: centres iu - max_disparity .. iu - 1.
inline RowPeak search_row(const cv::Mat& left, const RightImage& right, double u, double v, const RowSearchOptions& o) {
  const int iu = static_cast<int>(std::lround(u));
  return search_row_between(left, right, u, v, iu - static_cast<int>(std::floor(o.max_disparity)), iu - 1, o);
}

}  // namespace detail

/// detect_both's right x refined by correlation (FrontEndOptions::right_refinement): the keypoint
/// the descriptor match chose lies where the right detector put it, whose own localization error adds
/// to the left's (0.68 px RMS disparity error on the rendered globe); the left patch's ZNCC peak along
/// the row within `radius` px of it, refined by the parabola, measures the same point's shift instead
/// (0.54 px RMS, docs/results/real_time.md, "The right x by correlation").
struct RightRefinementOptions {
  int radius = 0;  ///< px each side of the right keypoint's x; 0 = off (the keypoint's x)
  /// The correlation a refined x needs and the ambiguity guard around it; a match whose search fails
  /// keeps the keypoint's x. max_disparity is not used.
  RowSearchOptions correlation{.min_correlation = 0.9};
};

inline void require_valid(const RightRefinementOptions& o) {
  if (o.radius < 0 || o.radius > 64)
    throw invalid_input_error("stereo front-end: right refinement radius " + std::to_string(o.radius) + " px must be in [0, 64]");
  if (o.correlation.half_window < 1 || !(o.correlation.min_correlation > -1.0 && o.correlation.min_correlation <= 1.0))
    throw invalid_input_error("stereo front-end: right refinement needs a window of at least 3 px and a minimum correlation in (-1, 1]");
}

/// Replaces each match's right x by its correlation peak within o.radius px (same row; matches whose
/// search fails are left as they are); returns how many moved. Images as search_rows'.
inline std::size_t refine_right_by_correlation(const cv::Mat& left, const cv::Mat& right, std::vector<StereoMatch>& matches,
                                               const RightRefinementOptions& o) {
  if (o.radius == 0 || matches.empty()) return 0;
  detail::require_grey_pair(left, right, "stereo right refinement");
  const detail::RightImage prepared(right);
  std::vector<double> x(matches.size(), std::nan(""));
  cv::parallel_for_(cv::Range(0, static_cast<int>(matches.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const StereoMatch& m = matches[static_cast<std::size_t>(i)];
      const int centre = static_cast<int>(std::lround(m.right_px.x()));
      x[static_cast<std::size_t>(i)] =
          detail::search_row_between(left, prepared, m.left_px.x(), m.left_px.y(), centre - o.radius, centre + o.radius, o.correlation).x;
    }
  });
  std::size_t moved = 0;
  for (std::size_t i = 0; i < matches.size(); ++i)
    if (!std::isnan(x[i])) {
      matches[i].right_px.x() = x[i];
      ++moved;
    }
  return moved;
}

/// Matches of the left keypoints in a rectified pair (8-bit grey images of one size, else
/// invalid_input_error) by searching the right image's rows; StereoMatch::right is -1 (no right
/// keypoint) and `distance` is 1 - ZNCC.
inline std::vector<StereoMatch> search_rows(const cv::Mat& left, const cv::Mat& right, const Features& left_features,
                                            const RowSearchOptions& o = {}) {
  detail::require_grey_pair(left, right, "stereo row search");
  const detail::RightImage prepared(right);
  std::vector<detail::RowPeak> peaks(left_features.keypoints.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(peaks.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const cv::Point2f& p = left_features.keypoints[static_cast<std::size_t>(i)].pt;
      peaks[static_cast<std::size_t>(i)] = detail::search_row(left, prepared, p.x, p.y, o);
    }
  });
  std::vector<StereoMatch> out;
  for (std::size_t i = 0; i < peaks.size(); ++i) {
    if (std::isnan(peaks[i].x)) continue;
    const cv::Point2f& p = left_features.keypoints[i].pt;
    out.push_back({static_cast<int>(i), -1, Eigen::Vector2d(p.x, p.y), Eigen::Vector2d(peaks[i].x, p.y),
                   1.0 - peaks[i].correlation});
  }
  return out;
}

}  // namespace sextant::vision
