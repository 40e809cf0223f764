#pragma once
/// \file How much worse than the stereo model a feature seen obliquely is: each stereo point's
/// noise scale (Observation::noise_scale) from the slant of the surface around it. A patch of
/// surface whose normal makes the angle theta with the viewing ray is foreshortened by cos theta
/// in the image, and differently in the two cameras, so a keypoint's position on the surface and
/// the disparity of its match are uncertain in proportion to the surface length a pixel covers,
/// 1 / cos theta (the incidence-angle law of range sensors). The slant is estimated from the
/// frame's own stereo points: the plane through the points whose left keypoints lie within a
/// radius, its normal against the ray. On the rendered globe the re-observations' error against
/// the truth grows with the slant as this law says (docs/results/real_time.md, "Oblique features
/// weighed, not dropped").

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/vision/pixel_neighbours.hpp"

namespace sextant::vision {

struct SlantNoiseOptions {
  double radius_px = 40.0;    ///< the neighbourhood in the left image that the plane is fitted to
  int min_neighbours = 6;     ///< fewer points (the feature included) give no slant: scale 1
  double max_scale = 10.0;    ///< at grazing incidence (theta near 90 degrees) the scale stops here
};

/// Throws invalid_input_error unless radius_px is positive and finite, min_neighbours >= 3 (a plane
/// needs three points) and max_scale finite and >= 1.
inline void require_valid(const SlantNoiseOptions& o) {
  if (!(o.radius_px > 0.0) || !std::isfinite(o.radius_px) || o.min_neighbours < 3 || !(o.max_scale >= 1.0) ||
      !std::isfinite(o.max_scale))
    throw invalid_input_error("slant noise: radius_px must be positive and finite, min_neighbours >= 3, max_scale "
                              "finite and >= 1");
}

namespace detail {

/// The unit normal of the plane through the points (the direction of least spread).
inline Eigen::Vector3d plane_normal(std::span<const Eigen::Vector3d> points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(scatter);
  return eigen.eigenvectors().col(0);
}

}  // namespace detail

/// 1 / cos theta for each point, theta the angle between the ray to it and the normal of the plane
/// through its neighbours (points whose pixels lie within radius_px of its pixel), at most
/// max_scale; 1 where fewer than min_neighbours points are near. `pixels[i]` is point i's left
/// keypoint. Throws invalid_input_error for options out of range (require_valid) or lists of different lengths.
inline std::vector<double> slant_noise_scales(std::span<const Eigen::Vector2d> pixels,
                                              std::span<const Eigen::Vector3d> points, const SlantNoiseOptions& o = {}) {
  require_valid(o);
  if (pixels.size() != points.size())
    throw invalid_input_error("slant noise: " + std::to_string(pixels.size()) + " pixels for " +
                              std::to_string(points.size()) + " points");
  const detail::PixelNeighbours neighbours(pixels);
  std::vector<double> scales(points.size(), 1.0);
  std::vector<int> indices;
  std::vector<Eigen::Vector3d> near;
  for (std::size_t i = 0; i < points.size(); ++i) {
    neighbours.within(i, o.radius_px, indices);
    near.clear();
    for (const int k : indices) near.push_back(points[static_cast<std::size_t>(k)]);
    if (near.size() < static_cast<std::size_t>(o.min_neighbours)) continue;
    const double cos_theta = std::abs(detail::plane_normal(near).dot(points[i].normalized()));
    scales[i] = std::min(o.max_scale, 1.0 / std::max(cos_theta, 1.0 / o.max_scale));
  }
  return scales;
}

}  // namespace sextant::vision
