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
    const Eigen::Matrix<double, M, M> P_mm = symmetric_diagonal_block<M>(cov_.view(), offset_of(slot));
    if (auto sighting = Reacquisition::sighting(sensor_, x_, landmark_mean(slot), observation, P_mm))
      out.push_back(std::move(*sighting));
  }
  return out;
}

}  // namespace sextant
