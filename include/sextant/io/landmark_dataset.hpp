#pragma once
/// \file A landmark-SLAM data set as the back-ends and the evaluation consume it: the models, the
/// prior, the step stream and, where known, the ground truth. Readers (MRPT rawlogs, MRCLAM) fill it.

#include <map>
#include <string>
#include <vector>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/io/implausible_values.hpp"

namespace sextant::io {

/// Where the landmark ids of a data set's observations come from.
enum class LandmarkIds {
  measured,           ///< the data carries them (known data association)
  from_ground_truth,  ///< the data has none; each observation took the id of the true landmark
                      ///< that explains it best from the true pose (for scoring, and an oracle run)
  absent,             ///< none, and no ground truth: the observations carry kNoLandmarkId and
                      ///< only a run with data association can use them
};

/// The id observations carry when the data has none.
inline constexpr LandmarkId kNoLandmarkId = ~LandmarkId{0};

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
  LandmarkIds ids = LandmarkIds::measured;
  ImplausibleValues implausible;  ///< legal values beyond the reader's plausible limits, for warnings
  bool has_ground_truth() const { return !true_poses.empty(); }
};

}  // namespace sextant::io
