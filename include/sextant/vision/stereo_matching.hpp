#pragma once
/// \file Left-right matching of a rectified stereo pair: a left feature's partner lies on the same
/// row (|dv| <= max_row_difference) at a disparity uL - uR in (0, max_disparity]; among those, the
/// nearest descriptor wins if it is clearly nearer than the second (Lowe's ratio test) and the
/// right feature picks the same left one back (mutual best).

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "sextant/vision/features.hpp"

namespace sextant::vision {

struct StereoMatchOptions {
  double max_row_difference = 1.5;  ///< px: rectified rows agree up to detection noise
  double max_disparity = 250.0;     ///< px: nearest depth f b / max_disparity
  double ratio = 0.7;               ///< best distance < ratio x second best (0.8: 98.7% right, 0.7: 99.5%)
};

struct StereoMatch {
  int left = 0, right = 0;  ///< keypoint indices
  Eigen::Vector2d left_px, right_px;
  double distance = 0.0;    ///< descriptor distance

  double disparity() const { return left_px.x() - right_px.x(); }
};

namespace detail {

inline double descriptor_distance(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  const int norm = a.type() == CV_8U ? cv::NORM_HAMMING : cv::NORM_L2;
  return cv::norm(a.row(i), b.row(j), norm);
}

inline Eigen::Vector2d pixel(const cv::KeyPoint& k) { return {k.pt.x, k.pt.y}; }

/// The nearest and second-nearest descriptor distances among the candidates offered, with the
/// nearest's payload: what Lowe's ratio test compares. A tie with the nearest counts as the second.
template <class Payload>
struct NearestTwo {
  double best = std::numeric_limits<double>::infinity(), second = best;
  Payload nearest{};
  void offer(double distance, const Payload& candidate) {
    if (distance < best) {
      second = best;
      best = distance;
      nearest = candidate;
    } else if (distance < second) {
      second = distance;
    }
  }
  /// best < ratio x second (an only candidate, second = inf, passes).
  bool clearly_nearest(double ratio) const { return best < ratio * second; }
};

inline bool on_epipolar_segment(const Eigen::Vector2d& left, const Eigen::Vector2d& right, const StereoMatchOptions& o) {
  const double disparity = left.x() - right.x();
  return std::abs(left.y() - right.y()) <= o.max_row_difference && disparity > 0.0 && disparity <= o.max_disparity;
}

/// Indices 0 .. n-1 sorted by a key each (a keypoint's row, a point's x), so that those whose key lies
/// within a tolerance of a value are found by binary search instead of a scan of all.
class SortedIndex {
 public:
  explicit SortedIndex(const std::vector<double>& keys) : order_(keys.size()) {
    for (std::size_t j = 0; j < order_.size(); ++j) order_[j] = static_cast<int>(j);
    std::sort(order_.begin(), order_.end(),
              [&](int a, int b) { return keys[static_cast<std::size_t>(a)] < keys[static_cast<std::size_t>(b)]; });
    keys_.reserve(order_.size());
    for (int j : order_) keys_.push_back(keys[static_cast<std::size_t>(j)]);
  }
  /// Indices with |key - value| <= tolerance, in the order of their keys.
  std::span<const int> band(double value, double tolerance) const {
    const auto lo = std::lower_bound(keys_.begin(), keys_.end(), value - tolerance);
    const auto hi = std::upper_bound(lo, keys_.end(), value + tolerance);
    return {order_.data() + (lo - keys_.begin()), static_cast<std::size_t>(hi - lo)};
  }

 private:
  std::vector<int> order_;
  std::vector<double> keys_;
};

/// The keypoints of one image sorted by row: the candidates on an epipolar band.
inline SortedIndex row_index(const Features& f) {
  std::vector<double> rows;
  rows.reserve(f.keypoints.size());
  for (const cv::KeyPoint& k : f.keypoints) rows.push_back(k.pt.y);
  return SortedIndex(rows);
}

/// For feature i of `from`, the best candidate of `to` that passes the ratio test, or -1.
inline int best_partner(const Features& from, int i, const Features& to, const SortedIndex& to_rows,
                        const StereoMatchOptions& o, bool from_is_left, double& best_distance) {
  NearestTwo<int> candidates{.nearest = -1};
  const Eigen::Vector2d p = pixel(from.keypoints[static_cast<std::size_t>(i)]);
  for (const int j : to_rows.band(p.y(), o.max_row_difference)) {
    const Eigen::Vector2d q = pixel(to.keypoints[static_cast<std::size_t>(j)]);
    if (!(from_is_left ? on_epipolar_segment(p, q, o) : on_epipolar_segment(q, p, o))) continue;
    candidates.offer(descriptor_distance(from.descriptors, i, to.descriptors, j), j);
  }
  if (candidates.nearest < 0 || !candidates.clearly_nearest(o.ratio)) return -1;
  best_distance = candidates.best;
  return candidates.nearest;
}

}  // namespace detail

/// Matches of a rectified pair; each left and each right feature in at most one.
inline std::vector<StereoMatch> match_stereo(const Features& left, const Features& right, const StereoMatchOptions& o = {}) {
  std::vector<StereoMatch> out;
  if (left.keypoints.empty() || right.keypoints.empty()) return out;
  const detail::SortedIndex left_rows = detail::row_index(left), right_rows = detail::row_index(right);
  for (int i = 0; i < static_cast<int>(left.keypoints.size()); ++i) {
    double distance = 0.0, back_distance = 0.0;
    const int j = detail::best_partner(left, i, right, right_rows, o, true, distance);
    if (j < 0 || detail::best_partner(right, j, left, left_rows, o, false, back_distance) != i) continue;
    out.push_back({i, j, detail::pixel(left.keypoints[static_cast<std::size_t>(i)]),
                   detail::pixel(right.keypoints[static_cast<std::size_t>(j)]), distance});
  }
  return out;
}

}  // namespace sextant::vision
