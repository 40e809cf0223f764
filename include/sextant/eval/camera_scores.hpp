#pragma once
/// \file Scores of a camera trajectory and map against ground truth, for states whose first six
/// entries are the position p and the yxz Euler angles eta (models/euler_camera_12d.hpp): position
/// error and NEES (eqs. 108, 110; 3 dof), orientation error and NEES (eqs. 112-114, see
/// eval/rotation_error.hpp), landmark error and NEES (eqs. 109, 111), and the same errors after
/// the best rigid alignment to the truth.

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <vector>

#include "sextant/core/gaussian.hpp"
#include "sextant/eval/alignment.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/eval/pooled_run.hpp"
#include "sextant/eval/rotation_error.hpp"
#include "sextant/models/euler_camera_12d.hpp"

namespace sextant::eval {

struct CameraScores {
  std::vector<double> position_error, position_nees;  ///< error per step; NEES (3 dof) per sampled step
  std::vector<double> rotation_error;                 ///< per step, rad (eq. 112)
  std::vector<double> rotation_nees;                  ///< per sampled step, rotation vector, 3 dof
  std::vector<double> rotation_angle_nees;            ///< per sampled step, the thesis's scalar form (<= rotation_nees)
  std::vector<double> map_error, map_nees;            ///< per landmark of the map
  std::vector<double> position_error_aligned, map_error_aligned;
};

/// means[k] (every step) and poses[i] (mean and covariance after step poses[i].step) are scored
/// against true_poses[k + 1] (true_poses[0] is the start): errors from every mean, NEES from every
/// covariance given (and of the map unless map_has_covariance is false).
template <class Pose, class PoseEstimate>
CameraScores score_camera(const std::vector<Pose>& means, const std::vector<SampledPose<PoseEstimate>>& poses,
                          const std::vector<Pose>& true_poses, const std::vector<LandmarkEstimate<3>>& map,
                          const std::map<LandmarkId, Eigen::Vector3d>& true_landmarks, bool map_has_covariance = true) {
  CameraScores out;
  std::vector<Eigen::Vector3d> estimated, truth;
  auto true_rotation = [&](std::size_t k) { return euler_yxz::rotation(true_poses[k + 1].template segment<3>(3)); };
  for (std::size_t k = 0; k < means.size(); ++k) {
    const Eigen::Vector3d eta = means[k].template segment<3>(3);
    out.position_error.push_back((means[k].template head<3>() - true_poses[k + 1].template head<3>()).norm());
    out.rotation_error.push_back(so3::log(true_rotation(k).transpose() * euler_yxz::rotation(eta)).norm());
    estimated.push_back(means[k].template head<3>());
    truth.push_back(true_poses[k + 1].template head<3>());
  }
  for (const auto& [k, pose] : poses) {
    const Eigen::Vector3d e = pose.mean.template head<3>() - true_poses[k + 1].template head<3>();
    out.position_nees.push_back(nees_or_infinity(e, pose.cov.template topLeftCorner<3, 3>()));
    const Eigen::Vector3d eta = pose.mean.template segment<3>(3);
    const auto r = rotation_error(true_rotation(k), euler_yxz::rotation(eta), euler_yxz::body_jacobian(eta),
                                  pose.cov.template block<3, 3>(3, 3));
    out.rotation_nees.push_back(r.nees);
    out.rotation_angle_nees.push_back(r.nees_angle);
  }
  out.position_error_aligned = aligned_errors<3>(estimated, truth);
  const auto evaluation = evaluate_map(map, true_landmarks);
  out.map_error = evaluation.errors;
  if (map_has_covariance) out.map_nees = evaluation.nees;
  std::vector<Eigen::Vector3d> map_estimated, map_truth;
  for (const auto& landmark : map) {
    map_estimated.push_back(landmark.mean);
    map_truth.push_back(true_landmarks.at(landmark.id));
  }
  out.map_error_aligned = aligned_errors<3>(map_estimated, map_truth);
  return out;
}

/// Averages of one run's scores, as the thesis's Tables 8-9 give them, with the share of NEES
/// values inside the one-sided 95% bound (7.81 for 3 dof); NaN where there is nothing to score.
struct CameraSummary {
  double position_mae = 0, rotation_mae = 0, map_mae = 0, position_mae_aligned = 0, map_mae_aligned = 0;
  double position_anees = 0, rotation_anees = 0;
  double position_nees_inside = 0, rotation_nees_inside = 0, map_nees_inside = 0;
};

inline CameraSummary summarize_camera(const CameraScores& s, double confidence = 0.95) {
  CameraSummary out;
  out.position_mae = mean_or_nan(s.position_error);
  out.rotation_mae = mean_or_nan(s.rotation_error);
  out.map_mae = mean_or_nan(s.map_error);
  out.position_mae_aligned = mean_or_nan(s.position_error_aligned);
  out.map_mae_aligned = mean_or_nan(s.map_error_aligned);
  const double bound = nees_upper_bound(3, confidence);
  out.position_anees = mean_or_nan(s.position_nees);
  out.rotation_anees = mean_or_nan(s.rotation_nees);
  out.position_nees_inside = fraction_at_most_or_nan(s.position_nees, bound);
  out.rotation_nees_inside = fraction_at_most_or_nan(s.rotation_nees, bound);
  out.map_nees_inside = fraction_at_most_or_nan(s.map_nees, bound);
  return out;
}

}  // namespace sextant::eval
