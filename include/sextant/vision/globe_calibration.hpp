#pragma once
/// \file The rendered globe's stereo pair (sim/globe_render.hpp) as the vision code meets any
/// rectified pair: its rig (the principal point at the image's centre) and the calibration a saved
/// sequence carries (calib.yaml), with the camera's prior.

#include "sextant/core/gaussian.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/sim/globe_camera.hpp"
#include "sextant/vision/stereo_sequence.hpp"
#include "sextant/vision/stereo_triangulation.hpp"

namespace sextant::vision {

inline StereoRig globe_rig(const sim::GlobeCameraOptions& o) {
  return {o.stereo.focal_px, 0.5 * o.image_width, 0.5 * o.image_height, o.stereo.baseline};
}

inline StereoCalibration globe_calibration(const sim::GlobeCameraOptions& o, const Gaussian<Vector12d, 12>& prior) {
  const StereoRig rig = globe_rig(o);
  StereoCalibration c;
  c.K << rig.focal_px, 0, rig.cx, 0, rig.focal_px, rig.cy, 0, 0, 1;
  c.baseline = rig.baseline;
  c.width = o.image_width;
  c.height = o.image_height;
  c.dt = o.dt;
  c.initial_state = prior.mean;
  c.initial_sigma = prior.cov.diagonal().cwiseSqrt();
  return c;
}

}  // namespace sextant::vision
