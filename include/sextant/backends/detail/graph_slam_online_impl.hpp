#pragma once
// GraphSLAM's online mode (see ../graph_slam.hpp, GraphOptions::incremental): one Gauss-Newton step
// a frame on the reduced pose system, refactorized from the oldest pose the frame's factors reach
// (docs/derivations/incremental_graph_slam.md).

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace sextant {

/// What one online step changes, computed before anything is committed.
template <class Motion, class Sensor>
struct GraphSlam<Motion, Sensor>::OnlinePlan {
  std::vector<State> theta;
  Eigen::VectorXd theta_landmarks;
  Eigen::VectorXd g;
  std::vector<char> pose_moved, landmark_redo;
  /// The sources of the pose factors this step adds, numbered on from the old ones (a source: which
  /// factor and on which poses, no linearization yet).
  std::vector<typename Online::PoseFactor> added_factors;
  std::vector<std::size_t> factor_redo;  ///< old and added factors to linearize (again), by number
  std::vector<std::pair<std::size_t, typename Online::PoseFactor>> new_factors;
  std::vector<std::pair<std::size_t, typename Online::LandmarkLinearization>> new_landmarks;  ///< by slot
  Eigen::VectorXd delta_poses, delta_landmarks;
  std::vector<State> poses;  ///< theta + delta
  Eigen::Matrix<double, X, X> newest_cov;
  OnlineStepSummary summary;
};

/// The landmark's measurements at the linearization points theta (poses) and theta_j.
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::linearize_landmark_online(std::size_t slot, const OnlinePlan& plan) const ->
    typename Online::LandmarkLinearization {
  typename Online::LandmarkLinearization lin;
  lin.records = measurements_[slot].size();
  const Landmark theta_j = plan.theta_landmarks.template segment<M>(M * static_cast<Eigen::Index>(slot));
  Eigen::Matrix<double, M, M> H = Eigen::Matrix<double, M, M>::Zero();
  for (const auto& record : measurements_[slot]) {
    const auto info = measurement_information(slot, record, plan.theta[record.pose], theta_j);
    if (!info) continue;
    lin.terms.push_back({record.pose, info->aa, info->ab, info->a});
    H += info->bb;
    lin.b += info->b;
  }
  if (!lin.terms.empty()) lin.H = cholesky_or_throw(H, "information of landmark " + std::to_string(landmarks_.id_at(slot)));
  return lin;
}

/// A factor on poses only (the prior, motion k, a marginalized landmark) at the poses' theta.
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::linearize_pose_factor_online(const typename Online::PoseFactor& which,
                                                             const OnlinePlan& plan) const -> typename Online::PoseFactor {
  auto theta_of = [&](std::size_t p) -> const State& { return plan.theta[p]; };
  if (which.source == Online::Source::marginal) {
    auto out = marginal_information(linear_factors_[which.index], theta_of);
    out.index = which.index;
    return out;
  }
  if (which.source == Online::Source::prior) {
    const PriorInformation prior = prior_information_at(plan.theta[0]);
    return {which.source, 0, {0}, prior.Lambda, prior.g, prior.cost};
  }
  const std::size_t k = which.index;
  const auto info = motion_information(k, plan.theta[k], plan.theta[k + 1]);
  typename Online::PoseFactor out{which.source, k, {k, k + 1}, Eigen::MatrixXd(2 * X, 2 * X), Eigen::VectorXd(2 * X),
                                  info.squared_norm};
  out.Lambda << info.aa, info.ab, info.ab.transpose(), info.bb;
  out.g << info.a, info.b;
  return out;
}

/// The linearization points of the step: new poses and landmarks at their current means, variables
/// whose last step exceeded the threshold at theta + delta; marks the landmarks to linearize again.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::plan_linearization_points(OnlinePlan& plan) const {
  const Online& on = online_;
  const std::size_t old_poses = on.theta.size(), old_slots = on.landmarks.size();
  plan.theta = on.theta;
  plan.pose_moved.assign(poses_.size(), 0);
  for (std::size_t p = 0; p < old_poses; ++p) {
    const Eigen::Matrix<double, X, 1> step = on.delta_poses.template segment<X>(X * p);
    if (!Online::moved(step, entry_sigma_[p], options_.relinearize_threshold)) continue;
    plan.theta[p] = Space::plus(plan.theta[p], step);
    if (!Space::is_finite(plan.theta[p])) throw numerical_error("GraphSLAM (online): pose " + std::to_string(p) + " moved to NaN or Inf");
    plan.pose_moved[p] = 1;
    ++plan.summary.relinearized_poses;
  }
  for (std::size_t p = old_poses; p < poses_.size(); ++p) plan.theta.push_back(poses_[p]);
  plan.theta_landmarks = on.theta_landmarks;
  plan.theta_landmarks.conservativeResize(M * static_cast<Eigen::Index>(landmarks_.size()));
  plan.landmark_redo.resize(landmarks_.size(), 0);
  for (std::size_t j = 0; j < landmarks_.size(); ++j) {
    auto theta_j = plan.theta_landmarks.template segment<M>(M * static_cast<Eigen::Index>(j));
    if (j >= old_slots) {
      theta_j = landmark_mean(j);
      plan.landmark_redo[j] = 1;
      continue;
    }
    if (on.landmarks[j].terms.empty()) continue;
    const Landmark step = on.delta_landmarks.template segment<M>(M * static_cast<Eigen::Index>(j));
    const Landmark sigma = on.landmarks[j].H.reconstructedMatrix().diagonal().cwiseMax(0.0).cwiseSqrt().cwiseInverse();
    if (!Online::moved(step, sigma, options_.relinearize_threshold)) continue;
    theta_j += step;
    plan.landmark_redo[j] = 1;
    ++plan.summary.relinearized_landmarks;
  }
}

/// The pose factors of the step: the new ones (every one when the state is rebuilt) and those on
/// moved poses; the landmarks seen from moved poses are linearized again too.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::plan_pose_factors(OnlinePlan& plan) const {
  const Online& on = online_;
  const std::size_t old_poses = on.theta.size();
  auto& added = plan.added_factors;
  if (old_poses == 0) {
    added.push_back({Online::Source::prior, 0, {0}, {}, {}});
    for (std::size_t f = 0; f < linear_factors_.size(); ++f)
      added.push_back({Online::Source::marginal, f, linear_factors_[f].poses, {}, {}});
  }
  for (std::size_t k = old_poses == 0 ? 0 : old_poses - 1; k + 1 < poses_.size(); ++k)
    added.push_back({Online::Source::motion, k, {k, k + 1}, {}, {}});
  std::vector<char> redo(on.pose_factors.size() + added.size(), 0);
  std::fill(redo.begin() + static_cast<std::ptrdiff_t>(on.pose_factors.size()), redo.end(), char{1});
  for (std::size_t p = 0; p < old_poses; ++p) {
    if (!plan.pose_moved[p]) continue;
    for (std::size_t f : on.factors_of_pose[p]) redo[f] = 1;
    for (std::size_t j : on.landmarks_of_pose[p]) plan.landmark_redo[j] = 1;
  }
  for (std::size_t f = 0; f < redo.size(); ++f)
    if (redo[f]) plan.factor_redo.push_back(f);
}

/// Stages in S (and plan.g) the removal of the old linearizations and the addition of the new.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::stage_online_factors(OnlinePlan& plan) {
  Online& on = online_;
  plan.g = on.g;
  plan.g.conservativeResize(X * static_cast<Eigen::Index>(poses_.size()));
  plan.g.tail(X * static_cast<Eigen::Index>(poses_.size() - on.theta.size())).setZero();
  for (std::size_t p = on.theta.size(); p < poses_.size(); ++p) on.S.append_row();
  const std::size_t old_factors = on.pose_factors.size();
  auto source = [&](std::size_t f) -> const typename Online::PoseFactor& {
    return f < old_factors ? on.pose_factors[f] : plan.added_factors[f - old_factors];
  };
  for (std::size_t f : plan.factor_redo) {
    if (f < old_factors) Online::add(on.S, plan.g, on.pose_factors[f], -1.0);
    auto lin = linearize_pose_factor_online(source(f), plan);
    Online::add(on.S, plan.g, lin, +1.0);
    plan.new_factors.emplace_back(f, std::move(lin));
  }
  for (std::size_t j = 0; j < plan.landmark_redo.size(); ++j) {
    if (!plan.landmark_redo[j]) continue;
    if (j < on.landmarks.size()) Online::add(on.S, plan.g, on.landmarks[j], -1.0);
    auto lin = linearize_landmark_online(j, plan);
    Online::add(on.S, plan.g, lin, +1.0);
    plan.new_landmarks.emplace_back(j, std::move(lin));
    ++plan.summary.linearized_landmarks;
  }
  if (!plan.g.allFinite()) throw numerical_error("GraphSLAM (online): the linearized system is not finite");
}

/// The estimate theta + delta and the landmarks' steps (thesis eq. 73), not yet kept.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::plan_estimate(OnlinePlan& plan, const Eigen::VectorXd& delta_poses) const {
  auto lin = [&](std::size_t j) -> const typename Online::LandmarkLinearization& {
    const auto it = std::lower_bound(plan.new_landmarks.begin(), plan.new_landmarks.end(), j,
                                     [](const auto& entry, std::size_t slot) { return entry.first < slot; });
    return it != plan.new_landmarks.end() && it->first == j ? it->second : online_.landmarks[j];
  };
  plan.delta_poses = delta_poses;
  plan.delta_landmarks.resize(M * static_cast<Eigen::Index>(landmarks_.size()));
  for (std::size_t j = 0; j < landmarks_.size(); ++j)
    plan.delta_landmarks.template segment<M>(M * static_cast<Eigen::Index>(j)) = Online::landmark_step(lin(j), delta_poses);
  plan.poses.reserve(poses_.size());
  for (std::size_t p = 0; p < poses_.size(); ++p) {
    plan.poses.push_back(Space::plus(plan.theta[p], delta_poses.template segment<X>(X * p)));
    if (!Space::is_finite(plan.poses.back())) throw numerical_error("GraphSLAM (online): the step of pose " + std::to_string(p) + " is not finite");
  }
  if (!plan.delta_landmarks.allFinite()) throw numerical_error("GraphSLAM (online): a landmark's step is not finite");
  plan.newest_cov = symmetrized(online_.S.last_inverse_block());
  if (!plan.newest_cov.allFinite()) throw numerical_error("GraphSLAM (online): the newest pose's covariance is not finite");
}

/// Keeps the step: the new linearizations, the indices of what each pose touches, the steps delta
/// and the estimate theta + delta.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::commit_online_step(OnlinePlan& plan) {
  Online& on = online_;
  const std::size_t old_factors = on.pose_factors.size();
  on.S.commit();
  on.theta = std::move(plan.theta);
  on.theta_landmarks = std::move(plan.theta_landmarks);
  on.g = std::move(plan.g);
  on.pose_factors.resize(old_factors + plan.added_factors.size());
  on.factors_of_pose.resize(poses_.size());
  on.landmarks_of_pose.resize(poses_.size());
  for (auto& [f, lin] : plan.new_factors) {
    if (f >= old_factors)
      for (std::size_t p : lin.poses) on.factors_of_pose[p].push_back(f);
    on.pose_factors[f] = std::move(lin);
  }
  on.landmarks.resize(landmarks_.size());
  for (auto& [j, lin] : plan.new_landmarks) {
    for (std::size_t r = on.landmarks[j].records; r < measurements_[j].size(); ++r) {
      auto& seen = on.landmarks_of_pose[measurements_[j][r].pose];
      if (seen.empty() || seen.back() != j) seen.push_back(j);
    }
    on.landmarks[j] = std::move(lin);
  }
  on.delta_poses = std::move(plan.delta_poses);
  on.delta_landmarks = std::move(plan.delta_landmarks);
  landmarks_.means().stacked() = on.theta_landmarks + on.delta_landmarks;
  poses_ = std::move(plan.poses);
  newest_cov_ = plan.newest_cov;
  on.last_step = plan.summary;
}

/// Online bookkeeping of remove_landmark (before the store moves its last slot into `slot`): the
/// landmark's contribution stays in S, now held by the newest linear factor (`held`, its blocks);
/// the last slot's linearization and indices move into `slot`.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::remove_landmark_online(std::size_t slot, std::optional<typename Online::PoseFactor> held) {
  Online& on = online_;
  if (held) {
    for (std::size_t p : held->poses) on.factors_of_pose[p].push_back(on.pose_factors.size());
    on.pose_factors.push_back(std::move(*held));
  }
  const std::size_t last = on.landmarks.size() - 1;
  for (const auto& record : measurements_[slot]) std::erase(on.landmarks_of_pose[record.pose], slot);
  if (last != slot) {
    for (const auto& record : measurements_[last])
      std::replace(on.landmarks_of_pose[record.pose].begin(), on.landmarks_of_pose[record.pose].end(), last, slot);
    on.landmarks[slot] = std::move(on.landmarks[last]);
    on.theta_landmarks.template segment<M>(M * static_cast<Eigen::Index>(slot)) = on.theta_landmarks.template tail<M>();
    on.delta_landmarks.template segment<M>(M * static_cast<Eigen::Index>(slot)) = on.delta_landmarks.template tail<M>();
  }
  on.landmarks.pop_back();
  on.theta_landmarks.conservativeResize(M * static_cast<Eigen::Index>(last));
  on.delta_landmarks.conservativeResize(M * static_cast<Eigen::Index>(last));
}

/// One online step after update() recorded the frame: plan the linearization points and the
/// factors to linearize again, stage them in S, refactorize S from its first changed row, solve,
/// commit. A throw before the commit leaves the estimator as it was.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::step_online(const std::vector<std::size_t>& touched) {
  OnlinePlan plan;
  plan.summary.poses = poses_.size();
  plan_linearization_points(plan);
  for (std::size_t j : touched) plan.landmark_redo[j] = 1;
  plan_pose_factors(plan);
  try {
    stage_online_factors(plan);
    plan.summary.first_row = online_.S.first_changed();
    online_.S.factorize();
    plan.summary.sparse = online_.S.factorized_sparse();
    plan_estimate(plan, online_.S.solve(plan.g));
  } catch (...) {
    online_.S.discard();
    throw;
  }
  commit_online_step(plan);
}

}  // namespace sextant
