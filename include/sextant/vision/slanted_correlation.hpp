#pragma once
/// \file A stereo match's disparity by correlation along the surface's slant. On a slanted surface
/// the right image is the left one stretched along the rows: the disparity of a plane is affine in
/// the left pixel, d(p) = d0 + g . (p - p0) (disparity_support.hpp), and on the rendered globe g
/// reaches 0.3 px/px at a 45 degree slant and 0.5 at 60 (|g| = b / z = d / f, ~0.3 at the orbit's
/// distance, times the slant's tangent). A square window correlated unwarped, or a keypoint detected in each image,
/// then measures the disparity short where the surface turns away (by 0.09-0.14 px beyond 45 degrees
/// on the rendered globe), and so does a warp by the plane, by the curvature of the disparity across
/// the patch. Here the left patch around the keypoint is compared with the right image sampled
/// where the disparity's second-order shape, fitted robustly to the match's neighbours (the match
/// left out), puts each of its pixels; the disparity at the keypoint is the peak of the warped
/// patch's zero-mean normalized cross-correlation nearest the match's own, climbed to on a
/// quarter-pixel grid and refined by a parabola (docs/results/real_time.md, "Disparities measured
/// along the slant").

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/vision/disparity_support.hpp"
#include "sextant/vision/row_search_matching.hpp"
#include "sextant/vision/stereo_matching.hpp"

namespace sextant::vision {

struct SlantedCorrelationOptions {
  double search_px = 4.0;        ///< px of disparity each side of the match's
  double step_px = 0.25;         ///< the search grid, refined by a parabola through the peak
  int half_window = 5;           ///< the left patch is (2 h + 1)^2 px around the keypoint
  double min_correlation = 0.9;  ///< ZNCC the peak needs; a match below keeps its disparity
  double min_contrast = 2.0;     ///< grey levels: a flatter patch keeps its disparity
  /// A match whose disparity the correlation does not measure (flat patch, weak peak, peak beyond
  /// the search) is dropped instead of keeping its own: on the rendered globe its disparity error is
  /// 1-2 px RMS, against 0.03-0.1 px for the measured ones below a 60 degree slant.
  bool drop_unmeasured = false;
  /// The disparity around the match to second order (false: a plane, which leaves the curvature's
  /// shortening: beyond a 45 degree slant on the rendered globe a mean error of -0.08 px against -0.01).
  bool curvature = true;
  /// The neighbourhood the disparity's shape is fitted to (radius, robust step, fewest neighbours);
  /// a match with fewer neighbours, or neighbours that do not determine the shape, is correlated unwarped.
  DisparitySupportOptions neighbours{.min_neighbours = 12};
};

/// Throws invalid_input_error unless search_px is in (0, 64], step_px in (0, search_px], half_window
/// >= 1, min_correlation in (-1, 1], min_contrast finite and the neighbourhood's options valid (require_valid).
inline void require_valid(const SlantedCorrelationOptions& o) {
  if (!(o.search_px > 0.0 && o.search_px <= 64.0) || !(o.step_px > 0.0 && o.step_px <= o.search_px) || o.half_window < 1 ||
      !(o.min_correlation > -1.0 && o.min_correlation <= 1.0) || !std::isfinite(o.min_contrast))
    throw invalid_input_error("slanted correlation: search_px must be in (0, 64], step_px in (0, search_px], half_window "
                              ">= 1, min_correlation in (-1, 1], min_contrast finite");
  require_valid(o.neighbours);
}

namespace detail {

/// The disparity around a match to second order, d(p) = d0 + g . q + q^T C q / 2 with q = p - p0:
/// the right image's stretch (g) and how it changes across the patch (C, which on a curved surface
/// shortens a plane's warp by C's trace times the window's second moment / 2; on the rendered globe
/// 0.03 px at a 45 degree slant, 0.11 at 60-75).
struct DisparityShape {
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  Eigen::Matrix2d curvature = Eigen::Matrix2d::Zero();
  double at(const Eigen::Vector2d& q) const { return gradient.dot(q) + 0.5 * q.dot(curvature * q); }
};

/// Least squares of d = a + g . q + (c_uu q_u^2 + 2 c_uv q_u q_v + c_vv q_v^2) / 2 over the members
/// (q scaled by the radius; N = 3: the plane's terms only), zero-padded to six coefficients, or nothing
/// when the members do not determine them.
template <int N>
std::optional<Eigen::Matrix<double, 6, 1>> fit_disparity(std::span<const Eigen::Vector2d> pixels, std::span<const double> disparities,
                                                        std::size_t i, std::span<const int> members, double radius) {
  Eigen::Matrix<double, N, N> normal = Eigen::Matrix<double, N, N>::Zero();
  Eigen::Matrix<double, N, 1> rhs = Eigen::Matrix<double, N, 1>::Zero();
  for (const int k : members) {
    const Eigen::Vector2d q = (pixels[static_cast<std::size_t>(k)] - pixels[i]) / radius;
    Eigen::Matrix<double, 6, 1> terms;
    terms << 1.0, q.x(), q.y(), 0.5 * q.x() * q.x(), q.x() * q.y(), 0.5 * q.y() * q.y();
    const auto a = terms.template head<N>();
    normal += a * a.transpose();
    rhs += a * disparities[static_cast<std::size_t>(k)];
  }
  // The pivots of the factorization of the scaled normal equations: a tiny one means the members do
  // not determine the coefficients (too few, or on a line or a conic).
  const Eigen::LDLT<Eigen::Matrix<double, N, N>> ldlt(normal);
  const auto pivots = ldlt.vectorD();
  if (ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-6 * pivots.maxCoeff())) return std::nullopt;
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  c.template head<N>() = ldlt.solve(rhs);
  return c;
}

inline std::optional<Eigen::Matrix<double, 6, 1>> fit_disparity(std::span<const Eigen::Vector2d> pixels, std::span<const double> disparities,
                                                               std::size_t i, std::span<const int> members, double radius,
                                                               bool curvature) {
  return curvature ? fit_disparity<6>(pixels, disparities, i, members, radius) : fit_disparity<3>(pixels, disparities, i, members, radius);
}

inline DisparityShape shape_from(const Eigen::Matrix<double, 6, 1>& c, double radius) {
  DisparityShape shape;
  shape.gradient = c.segment<2>(1) / radius;
  shape.curvature << c(3), c(4), c(4), c(5);
  shape.curvature /= radius * radius;
  return shape;
}

/// The shape of match i's neighbourhood: the quadratic (or plane) of its neighbours (the match left
/// out), refitted to those robust_inliers keeps from the first fit (as robust_plane); zero where too few.
inline DisparityShape disparity_shape(std::span<const Eigen::Vector2d> pixels, std::span<const double> disparities,
                                      std::size_t i, std::span<const int> others, double radius, const DisparitySupportOptions& o,
                                      bool curvature) {
  const auto first = fit_disparity(pixels, disparities, i, others, radius, curvature);
  if (!first) return {};
  const DisparityShape scaled = shape_from(*first, 1.0);
  std::vector<double> residuals;
  for (const int k : others) {
    const Eigen::Vector2d q = (pixels[static_cast<std::size_t>(k)] - pixels[i]) / radius;
    residuals.push_back(disparities[static_cast<std::size_t>(k)] - (*first)(0) - scaled.at(q));
  }
  const auto inliers = robust_inliers(others, residuals, o);
  if (static_cast<int>(inliers.size()) < o.min_neighbours) return {};
  const auto second = fit_disparity(pixels, disparities, i, inliers, radius, curvature);
  return second ? shape_from(*second, radius) : DisparityShape{};
}

/// Each match's disparity shape from its neighbours (o.min_neighbours of them at least, within
/// o.radius_px doubled up to o.max_radius_px).
inline std::vector<DisparityShape> disparity_shapes(std::span<const StereoMatch> matches, const DisparitySupportOptions& o,
                                                    bool curvature) {
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> disparities;
  for (const auto& m : matches) pixels.push_back(m.left_px), disparities.push_back(m.disparity());
  const PixelNeighbours neighbours(pixels);
  std::vector<DisparityShape> shapes(matches.size());
  std::vector<int> others;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const double radius = neighbourhood(neighbours, i, o, others);
    if (static_cast<int>(others.size()) >= o.min_neighbours) shapes[i] = disparity_shape(pixels, disparities, i, others, radius, o, curvature);
  }
  return shapes;
}

/// The left patch around a keypoint, mean-free, and where the disparity's shape puts each of its
/// pixels in the right image's row before the disparity at the keypoint is subtracted.
struct LeftPatch {
  std::vector<float> values;
  std::vector<double> right_x;  ///< pixel's x - shape.at(pixel - keypoint)
  double norm = 0.0;  ///< sum of the squared mean-free values
  int iv = 0, h = 0;
};

/// The patch of half width h around the keypoint, or false where it leaves the image or is flatter
/// than min_contrast (grey levels RMS).
inline bool take_patch(const cv::Mat& left, const Eigen::Vector2d& keypoint, const DisparityShape& shape, int h,
                       double min_contrast, LeftPatch& out) {
  const int iu = static_cast<int>(std::lround(keypoint.x())), iv = static_cast<int>(std::lround(keypoint.y()));
  if (iu - h < 0 || iu + h >= left.cols || iv - h < 0 || iv + h >= left.rows) return false;
  out.iv = iv;
  out.h = h;
  const int size = 2 * h + 1;
  out.values.resize(static_cast<std::size_t>(size * size));
  out.right_x.resize(out.values.size());
  double mean = 0.0;
  for (int dy = 0; dy < size; ++dy)
    for (int dx = 0; dx < size; ++dx) {
      const auto n = static_cast<std::size_t>(dy * size + dx);
      const Eigen::Vector2d pixel(iu - h + dx, iv - h + dy);
      mean += out.values[n] = left.at<std::uint8_t>(iv - h + dy, iu - h + dx);
      out.right_x[n] = pixel.x() - shape.at(pixel - keypoint);
    }
  mean /= size * size;
  out.norm = 0.0;
  for (float& t : out.values) {
    t = static_cast<float>(t - mean);
    out.norm += static_cast<double>(t) * t;
  }
  return std::sqrt(out.norm / (size * size)) >= min_contrast;
}

/// ZNCC of the patch against the right image (grey levels as floats) where the disparity d0 at the
/// keypoint puts each of its pixels (linear interpolation along the row); -2 where a sample leaves
/// the image.
inline double warped_zncc(const LeftPatch& patch, const cv::Mat& right, double d0) {
  const int size = 2 * patch.h + 1;
  double sum = 0.0, squares = 0.0, cross = 0.0;
  for (int dy = 0; dy < size; ++dy) {
    const float* row = right.ptr<float>(patch.iv - patch.h + dy);
    for (int dx = 0; dx < size; ++dx) {
      const auto n = static_cast<std::size_t>(dy * size + dx);
      const double x = patch.right_x[n] - d0, fx = std::floor(x);
      const int ix = static_cast<int>(fx);
      if (ix < 0 || ix + 1 >= right.cols) return -2.0;
      const double w = x - fx, r = (1.0 - w) * row[ix] + w * row[ix + 1];
      sum += r;
      squares += r * r;
      cross += patch.values[n] * r;
    }
  }
  const double variance = squares - sum * sum / (size * size);
  return variance > 0.0 ? cross / std::sqrt(patch.norm * variance) : 0.0;
}

/// The disparity at the keypoint where the warped patch's correlation peaks nearest `d`: climbed to
/// on the grid of o.step_px from d, refined by a parabola; NaN when the patch leaves the image or is
/// flat, or the peak is weak or lies beyond o.search_px.
inline double slanted_disparity(const cv::Mat& left, const cv::Mat& right, const Eigen::Vector2d& keypoint, double d,
                                const DisparityShape& shape, const SlantedCorrelationOptions& o) {
  LeftPatch patch;
  if (!take_patch(left, keypoint, shape, o.half_window, o.min_contrast, patch)) return std::nan("");
  const int k = static_cast<int>(std::floor(o.search_px / o.step_px)), n = 2 * k + 1;
  std::vector<double> s(static_cast<std::size_t>(n), std::nan(""));
  const auto score = [&](int c) {
    double& at = s[static_cast<std::size_t>(c)];
    if (std::isnan(at)) at = warped_zncc(patch, right, d + (c - k) * o.step_px);
    return at;
  };
  int c = k;
  for (;;) {
    if (c == 0 || c == n - 1) return std::nan("");
    const double before = score(c - 1), here = score(c), after = score(c + 1);
    if (before > here && before >= after) --c;
    else if (after > here) ++c;
    else break;
  }
  if (!(score(c) >= o.min_correlation)) return std::nan("");
  const double offset = parabola_offset(static_cast<float>(score(c - 1)), static_cast<float>(score(c)), static_cast<float>(score(c + 1)));
  return d + (c - k + offset) * o.step_px;
}

}  // namespace detail

struct SlantedRefinement {
  std::size_t measured = 0;  ///< matches whose right x the slanted correlation set
  std::size_t dropped = 0;   ///< unmeasured matches dropped (SlantedCorrelationOptions::drop_unmeasured)
};

/// Replaces each match's right x by the one its slanted correlation finds; a match whose search fails
/// keeps its own, or is dropped with o.drop_unmeasured. Images: 8-bit grey of one size, and every
/// match's pixels finite (else invalid_input_error, the matches untouched).
inline SlantedRefinement refine_right_along_slant(const cv::Mat& left, const cv::Mat& right, std::vector<StereoMatch>& matches,
                                                  const SlantedCorrelationOptions& o) {
  if (matches.empty()) return {};
  detail::require_grey_pair(left, right, "slanted correlation");
  for (std::size_t i = 0; i < matches.size(); ++i)
    if (!matches[i].left_px.allFinite() || !matches[i].right_px.allFinite())
      throw invalid_input_error("slanted correlation: match " + std::to_string(i) + " has a pixel that is not finite");
  const auto shapes = detail::disparity_shapes(matches, o.neighbours, o.curvature);
  cv::Mat levels;  // the right image's grey levels as floats, sampled between pixels
  right.convertTo(levels, CV_32F);
  std::vector<double> disparity(matches.size(), std::nan(""));
  cv::parallel_for_(cv::Range(0, static_cast<int>(matches.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const auto n = static_cast<std::size_t>(i);
      disparity[n] = detail::slanted_disparity(left, levels, matches[n].left_px, matches[n].disparity(), shapes[n], o);
    }
  });
  SlantedRefinement out;
  std::vector<StereoMatch> kept;
  kept.reserve(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (!std::isnan(disparity[i])) {
      matches[i].right_px.x() = matches[i].left_px.x() - disparity[i];
      ++out.measured;
    } else if (o.drop_unmeasured) {
      ++out.dropped;
      continue;
    }
    kept.push_back(matches[i]);
  }
  matches = std::move(kept);
  return out;
}

}  // namespace sextant::vision
