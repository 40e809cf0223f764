#pragma once
/// \file A stereo match as a 3D point in the left camera's frame, the measurement of the thesis's
/// visual SLAM (PointInCamera3D): depth z = f b / d from the disparity d, then x and y along the left
/// pixel's ray; its covariance propagated from the pixel noise (StereoPointNoise).

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/vision/stereo_matching.hpp"

namespace sextant::vision {

/// A rectified pair: shared focal length and principal point, the right camera `baseline` along +x.
struct StereoRig {
  double focal_px = 600.0;
  double cx = 320.0, cy = 240.0;  ///< px
  double baseline = 0.1;          ///< m
};

/// The smallest disparity that `sigmas` of its standard deviations (sqrt(2) pixel_sigma: u_left and
/// u_right each noisy) set apart from zero, the disparity of a point at infinity. Below it the depth
/// z = f b / d is mostly noise: its first-order standard deviation sqrt(2) sigma z / d exceeds
/// z / sigmas, and a Gaussian in xyz puts more than the normal tail beyond `sigmas` behind the camera.
inline double significant_disparity(double pixel_sigma, double sigmas) { return sigmas * std::sqrt(2.0) * pixel_sigma; }

/// The match's point in the left camera frame (x right, y down, z forward). Throws
/// invalid_input_error for a disparity <= 0 (no finite depth).
inline Eigen::Vector3d triangulate(const StereoRig& rig, const StereoMatch& match) {
  const double d = match.disparity();
  if (!(d > 0.0)) throw invalid_input_error("stereo triangulation: disparity " + std::to_string(d) + " px is not positive");
  const double z = rig.focal_px * rig.baseline / d;
  return {(match.left_px.x() - rig.cx) * z / rig.focal_px, (match.left_px.y() - rig.cy) * z / rig.focal_px, z};
}

}  // namespace sextant::vision
