#pragma once
// EkfSlam's re-acquisition of a lost pose (see ../ekf_slam.hpp and core/pose_reacquisition.hpp).

#include <algorithm>
#include <memory>
#include <new>

namespace sextant {

template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::reacquire_pose(const Eigen::Matrix<double, X, 1>& d) {
  if (!d.allFinite()) throw invalid_input_error("reacquire_pose: the offset contains NaN or Inf");
  const State moved = Space::plus(x_, d);
  const Eigen::Matrix<double, X, X> P_xx = symmetric_diagonal_block<X>(cov_.view(), 0) + d * d.transpose();
  if (!Space::is_finite(moved) || !P_xx.allFinite()) throw numerical_error("reacquire_pose: the moved pose is not finite");
  cov_.view().template topLeftCorner<X, X>() = P_xx;
  x_ = moved;
}

/// After update()'s commit. A probation under way scores the update's sightings in both hypotheses
/// and, once over, keeps the one that explained them better; otherwise an update that accepted
/// nothing adds its rejections to the record and may start a probation. The estimate changes only
/// when a candidate wins; a candidate that cannot take an update is dropped, and the attempt is
/// skipped when memory for it runs out, so update() keeps its strong guarantee.
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::follow_up_reacquisition(std::span<const ObservationType> observations, UpdateResult& result) {
  if (!reacquisition_.on()) return;
  try {
    if (probation_.active()) {
      double candidate_log_likelihood = 0.0;
      try {
        candidate_log_likelihood = probation_.candidate().update(observations).log_likelihood;
      } catch (const error&) {
        probation_.drop();
      }
      if (probation_.active()) end_probation_if_over(candidate_log_likelihood, result);
      if (result.pose_reacquired || probation_.active()) return;
    }
    if (result.corrected > 0) return reacquisition_.accepted();
    if (result.rejected.empty()) return;
    if (const auto d = reacquisition_.add_rejected(rejected_sightings(observations, result), sensor_)) start_probation(*d);
  } catch (const std::bad_alloc&) {
    probation_.drop();
    reacquisition_.forget_record();
  }
}

/// The candidate: this filter moved by d, following the updates without re-acquiring itself.
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::start_probation(const Eigen::Matrix<double, X, 1>& d) {
  auto candidate = std::make_unique<EkfSlam>(*this);
  candidate->reacquisition_ = Reacquisition{};
  try {
    candidate->reacquire_pose(d);
  } catch (const error&) {
    return;
  }
  probation_.start(std::move(candidate));
}

/// Counts the update in both hypotheses; at the end of the probation the candidate's state
/// replaces this one's if it explained the sightings better (and the record and drift start over).
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::end_probation_if_over(double candidate_log_likelihood, UpdateResult& result) {
  if (!probation_.count(result.corrected + result.rejected.size(), result.log_likelihood, candidate_log_likelihood,
                        options_.reacquisition.probation))
    return;
  const bool won = probation_.candidate_won();
  const auto candidate = probation_.release();
  reacquisition_.forget_record();
  if (!won) return;
  x_ = candidate->x_;
  propagated_ = candidate->propagated_;
  landmarks_ = std::move(candidate->landmarks_);
  cov_ = std::move(candidate->cov_);
  reacquisition_.accepted();
  result.pose_reacquired = true;
}

/// The update's rejected sightings as the re-acquisition test reads them: each with the robot's
/// estimate, the landmark's mean and S = J_m P_m J_m^T + Q. One the model cannot predict is left out.
template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::rejected_sightings(std::span<const ObservationType> observations,
                                                 const UpdateResult& result) const
    -> std::vector<typename Reacquisition::Sighting> {
  std::vector<typename Reacquisition::Sighting> out;
  for (const auto& observation : observations) {
    if (std::find(result.rejected.begin(), result.rejected.end(), observation.landmark_id) == result.rejected.end()) continue;
    const std::size_t slot = landmarks_.slot(observation.landmark_id);
    const Landmark m = landmark_mean(slot);
    try {
      const auto p = with_noise_scale(sensor_.predict(x_, m), observation.noise_scale);
      const Eigen::Matrix<double, M, M> P_mm = symmetric_diagonal_block<M>(cov_.view(), offset_of(slot));
      out.push_back({observation.landmark_id, x_, m, observation.z,
                     symmetrized(p.J_z_m * P_mm * p.J_z_m.transpose() + p.Q)});
    } catch (const error&) {
    }
  }
  return out;
}

}  // namespace sextant
