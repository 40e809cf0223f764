#pragma once
/// \file A landmark-SLAM data set as the back-ends and the evaluation consume it: the models, the
/// prior, the step stream and, where known, the ground truth. Readers (MRPT rawlogs, MRCLAM) fill it.

#include <map>
#include <string>
#include <vector>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant::io {

template <class MotionT, class SensorT>
struct LandmarkDataset {
  using Motion = MotionT;
  using Sensor = SensorT;
  using State = typename Motion::State;
  std::string path;  ///< where it was read from (a file, or a directory and what in it)
  Motion motion;
  Sensor sensor;
  Gaussian<State, Motion::kDim> prior;
  std::vector<Step<typename Motion::Control, typename Sensor::Measurement>> steps;
  std::vector<State> true_poses;  ///< [k]: after step k, [0] the start; empty without ground truth
  std::map<LandmarkId, typename Sensor::Landmark> true_landmarks;
  bool has_ground_truth() const { return !true_poses.empty(); }
};

}  // namespace sextant::io
