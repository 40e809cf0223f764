#pragma once
/// \file What an update step reports.

#include <cstddef>
#include <vector>

#include "sextant/core/observation.hpp"

namespace sextant {

struct UpdateResult {
  std::size_t corrected = 0;             ///< observations of known landmarks used in the correction
  std::size_t initialized = 0;           ///< new landmarks added to the map
  std::vector<LandmarkId> rejected;      ///< observations rejected by the Mahalanobis gate
  /// Observations the sensor model cannot use at the current estimate (unobservable_error: a point
  /// behind or too near the camera, outside its field of view, a disparity <= 0 or below the
  /// smallest for a new landmark), skipped one by one; a new landmark listed here is not added.
  std::vector<LandmarkId> unusable;
  /// The pose had been lost: a copy moved to where the gate's rejected sightings put it explained
  /// the sightings since better, and replaced the estimate (EKF-SLAM and SEIF-SLAM,
  /// core/lost_pose_recovery.hpp).
  bool pose_reacquired = false;
  /// With the gate on (EKF-SLAM, SEIF-SLAM): the predictive log-likelihood of the sightings of known landmarks,
  /// sum of -(min(NIS, gate) + log det S + Z log 2 pi) / 2: a rejected sighting counts as one on the
  /// gate's edge. Two hypotheses about the pose are compared by it (core/pose_reacquisition.hpp).
  double log_likelihood = 0.0;
};

}  // namespace sextant
