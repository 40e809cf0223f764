#pragma once
/// \file Whether a stereo match's disparity is the one its neighbours' surface predicts. A wrong match
/// pairs a left keypoint with a right keypoint of another patch on the same rows, so its disparity has
/// nothing to do with the surface around it (on the rendered globe a 1.7 px disparity among
/// neighbours at ~150 px became a landmark 35 m away and the camera was lost; 11.2% of the new
/// landmarks of a 500-frame run came from wrong matches, most of them 7-165 px off, against 0.6-1.6%
/// of a frame's matches: a wrong match seldom falls in a landmark's gate, so it is proposed as new;
/// docs/results/real_time.md, "Wrong stereo matches become new landmarks"). The disparity of
/// a plane is affine in the left pixel (d = f b n . ray / c), so the matches whose left keypoints lie
/// within a radius are fitted with d = a + g . (p - p_i), robustly (the neighbours further than
/// `sigmas` robust deviations from a first fit are left out of the second), and the match is dropped
/// when its disparity lies outside the fit's prediction interval, `sigmas` x s sqrt(1 + h) with s the
/// neighbours' scatter about the plane (at least the matching noise) and h the leverage of p_i. A
/// neighbourhood that no plane fits (a depth edge, a curved or broken surface) has a wide scatter and
/// judges leniently. A match with too few neighbours within the radius is judged on a radius doubled
/// until it has them, up to a largest radius: the wrong matches are often alone, in the strip at the
/// left image's edge whose true partners lie beyond the right image's (on the rendered globe: 36-116 px
/// off, with no other match within 40 px). One still short of neighbours, or with all on a line, is not judged.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/vision/pixel_neighbours.hpp"

namespace sextant::vision {

struct DisparitySupportOptions {
  double radius_px = 40.0;   ///< the neighbourhood in the left image
  double max_radius_px = 160.0;  ///< radius_px doubled up to this while the neighbours are fewer than min_neighbours
  int min_neighbours = 6;    ///< fewer other matches within max_radius_px (or left after the robust step): not judged
  double sigmas = 4.0;       ///< the prediction interval's half-width in the fit's standard deviations
  double min_sigma_px = 1.0; ///< the scatter about the plane is taken as at least this (the disparity's own noise)
};

/// Throws invalid_input_error unless radius_px, sigmas and min_sigma_px are positive and finite,
/// max_radius_px finite and >= radius_px, and min_neighbours >= 4 (a plane has three parameters; one
/// more leaves a scatter).
inline void require_valid(const DisparitySupportOptions& o) {
  const auto positive_finite = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive_finite(o.radius_px) || !positive_finite(o.sigmas) || !positive_finite(o.min_sigma_px) ||
      !(o.max_radius_px >= o.radius_px) || !std::isfinite(o.max_radius_px) || o.min_neighbours < 4)
    throw invalid_input_error("disparity support: radius_px, sigmas and min_sigma_px must be positive and finite, "
                              "max_radius_px finite and >= radius_px, min_neighbours >= 4");
}

namespace detail {

/// d = a + g . (p - p_i) / radius fitted by least squares to some neighbours of match i.
struct LocalPlane {
  Eigen::Vector3d coefficients;  ///< a, g_u, g_v
  double leverage = 0.0;         ///< h = (A^T A)^-1 (0, 0): the fit's variance at p_i over s^2
  double scatter = 0.0;          ///< s: the residuals' root mean square over n - 3 degrees of freedom
};

class LocalPlaneFit {
 public:
  LocalPlaneFit(std::span<const Eigen::Vector2d> pixels, std::span<const double> disparities, double radius)
      : pixels_(pixels), disparities_(disparities), radius_(radius) {}

  /// The plane through `members` (indices) around match i, or nothing when they lie on a line.
  std::optional<LocalPlane> fit(std::size_t i, std::span<const int> members) const {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const int k : members) {
      const Eigen::Vector3d a = row(i, static_cast<std::size_t>(k));
      normal += a * a.transpose();
      rhs += a * disparities_[static_cast<std::size_t>(k)];
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(normal, Eigen::EigenvaluesOnly);
    if (!(eigen.eigenvalues()(0) > 1e-9 * eigen.eigenvalues()(2))) return std::nullopt;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(normal);
    LocalPlane plane{ldlt.solve(rhs), ldlt.solve(Eigen::Vector3d::UnitX())(0), 0.0};
    double rss = 0.0;
    for (const int k : members) rss += std::pow(residual(plane, i, static_cast<std::size_t>(k)), 2);
    plane.scatter = std::sqrt(rss / static_cast<double>(members.size() - 3));
    return plane;
  }

  double residual(const LocalPlane& plane, std::size_t i, std::size_t k) const {
    return disparities_[k] - row(i, k).dot(plane.coefficients);
  }

 private:
  Eigen::Vector3d row(std::size_t i, std::size_t k) const {
    const Eigen::Vector2d offset = (pixels_[k] - pixels_[i]) / radius_;
    return {1.0, offset.x(), offset.y()};
  }

  std::span<const Eigen::Vector2d> pixels_;
  std::span<const double> disparities_;
  double radius_;
};

inline double median_of_absolute(std::vector<double> values) {
  for (double& v : values) v = std::abs(v);
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// The other matches within radius_px of match i, the radius doubled (at most to max_radius_px) while
/// they are fewer than min_neighbours; returns the radius used.
inline double neighbourhood(const PixelNeighbours& neighbours, std::size_t i, const DisparitySupportOptions& o,
                            std::vector<int>& others) {
  for (double radius = o.radius_px;; radius = std::min(2.0 * radius, o.max_radius_px)) {
    neighbours.within(i, radius, others);
    std::erase(others, static_cast<int>(i));
    if (static_cast<int>(others.size()) >= o.min_neighbours || radius >= o.max_radius_px) return radius;
  }
}

/// The members whose first-fit residuals lie within `sigmas` robust deviations (1.4826 x the median
/// absolute residual, at least min_sigma_px): those a robust second fit keeps.
inline std::vector<int> robust_inliers(std::span<const int> members, const std::vector<double>& residuals,
                                       const DisparitySupportOptions& o) {
  const double scale = std::max(o.min_sigma_px, 1.4826 * median_of_absolute(residuals));
  std::vector<int> inliers;
  for (std::size_t n = 0; n < members.size(); ++n)
    if (std::abs(residuals[n]) <= o.sigmas * scale) inliers.push_back(members[n]);
  return inliers;
}

/// The second, robust fit: the plane of the neighbours robust_inliers keeps from the first fit;
/// nothing when too few are left.
inline std::optional<LocalPlane> robust_plane(const LocalPlaneFit& fitter, std::size_t i, std::span<const int> others,
                                              const DisparitySupportOptions& o) {
  const auto first = fitter.fit(i, others);
  if (!first) return std::nullopt;
  std::vector<double> residuals;
  for (const int k : others) residuals.push_back(fitter.residual(*first, i, static_cast<std::size_t>(k)));
  const auto inliers = robust_inliers(others, residuals, o);
  if (static_cast<int>(inliers.size()) < o.min_neighbours) return std::nullopt;
  return fitter.fit(i, inliers);
}

}  // namespace detail

/// For each match (left keypoint `pixels[i]`, disparity `disparities[i]`), whether it is kept: its
/// disparity lies within the prediction interval of the plane fitted to its neighbours' (those within
/// radius_px, or a wider radius up to max_radius_px where they are too few), or it is not judged (too
/// few neighbours even so, on a line, or too few left by the robust step).
/// Throws invalid_input_error for options out of range (require_valid), lists of different lengths,
/// or a disparity that is not finite.
inline std::vector<bool> disparity_supported(std::span<const Eigen::Vector2d> pixels, std::span<const double> disparities,
                                             const DisparitySupportOptions& o = {}) {
  require_valid(o);
  if (pixels.size() != disparities.size())
    throw invalid_input_error("disparity support: " + std::to_string(pixels.size()) + " pixels for " +
                              std::to_string(disparities.size()) + " disparities");
  for (const double d : disparities)
    if (!std::isfinite(d)) throw invalid_input_error("disparity support: a disparity is not finite");
  const detail::PixelNeighbours neighbours(pixels);
  std::vector<bool> kept(pixels.size(), true);
  std::vector<int> others;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const double radius = detail::neighbourhood(neighbours, i, o, others);
    if (static_cast<int>(others.size()) < o.min_neighbours) continue;
    const auto plane = detail::robust_plane(detail::LocalPlaneFit(pixels, disparities, radius), i, others, o);
    if (!plane) continue;
    const double s = std::max(o.min_sigma_px, plane->scatter);
    kept[i] = std::abs(disparities[i] - plane->coefficients(0)) <= o.sigmas * s * std::sqrt(1.0 + plane->leverage);
  }
  return kept;
}

}  // namespace sextant::vision
