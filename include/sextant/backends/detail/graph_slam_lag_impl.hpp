#pragma once
// GraphSLAM's fixed-lag mode (see ../graph_slam.hpp, GraphOptions::lag): one Gauss-Newton step a
// frame over the newest `lag` poses and the landmarks they see, with everything older marginalized
// into one dense prior (docs/derivations/fixed_lag_graph_slam.md).

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace sextant {

/// The poses and stacked landmark means a fixed-lag system is linearized at.
template <class Motion, class Sensor>
struct GraphSlam<Motion, Sensor>::LagEstimate {
  const std::vector<State>* poses;
  const Eigen::VectorXd* means;
  const State& pose(std::size_t p) const { return (*poses)[p]; }
  Landmark landmark(std::size_t slot) const { return means->template segment<M>(M * static_cast<Eigen::Index>(slot)); }
};

/// What one fixed-lag step changes, computed before anything is kept.
template <class Motion, class Sensor>
struct GraphSlam<Motion, Sensor>::LagPlan {
  std::vector<State> poses;
  Eigen::VectorXd means;
  Lag window;
  Eigen::Matrix<double, X, X> newest_cov;
};

/// Whether the landmark in `slot` is one of the prior's variables.
template <class Motion, class Sensor>
bool GraphSlam<Motion, Sensor>::in_lag_prior(std::size_t slot) const {
  const LandmarkId id = landmarks_.id_at(slot);
  return std::find(lag_.prior.landmarks.begin(), lag_.prior.landmarks.end(), id) != lag_.prior.landmarks.end();
}

/// The landmark slots the window's poses (first .. newest) measured, in slot order; `touched` are the
/// newest frame's.
template <class Motion, class Sensor>
std::vector<std::size_t> GraphSlam<Motion, Sensor>::lag_slots(const std::vector<std::size_t>& touched) const {
  std::vector<std::size_t> slots = touched;
  for (std::size_t p = lag_.first; p < lag_.seen_from.size(); ++p)
    for (LandmarkId id : lag_.seen_from[p])
      if (landmarks_.contains(id) && measurements_[landmarks_.slot(id)].back().pose >= lag_.first)
        slots.push_back(landmarks_.slot(id));
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  return slots;
}

/// The marginalized variables' prior at estimate `at`: g = eta - Lambda d, d = (m_j - theta_j,
/// x_p ⊖ theta_p), read in each pose's tangent through D = d minus / d x (block-diagonal, the identity
/// on landmarks and in an additive chart: applied block by block), added over its variables in sys.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_lag_prior(LagSys& sys, const LagEstimate& at, const typename Lag::Prior& prior) const {
  const std::size_t count = prior.landmarks.size() + prior.poses.size();
  if (count == 0) return;
  std::vector<Eigen::Index> offset, in_sys;
  Eigen::VectorXd d(prior.Lambda.rows());
  Eigen::Index o = 0;
  for (std::size_t i = 0; i < prior.landmarks.size(); ++i, o += M) {
    const std::size_t slot = landmarks_.slot(prior.landmarks[i]);
    d.template segment<M>(o) = at.landmark(slot) - prior.landmark_theta[i];
    offset.push_back(o);
    in_sys.push_back(sys.landmark_at.at(slot));
  }
  for (std::size_t i = 0; i < prior.poses.size(); ++i, o += X) {
    d.template segment<X>(o) = Space::minus(at.pose(prior.poses[i]), prior.pose_theta[i]);
    offset.push_back(o);
    in_sys.push_back(sys.pose_at.at(prior.poses[i]));
  }
  Eigen::MatrixXd Lambda = prior.Lambda;
  Eigen::VectorXd g = prior.eta - prior.Lambda * d;
  if constexpr (has_minus_jacobians_v<Space, State>)
    for (std::size_t i = 0; i < prior.poses.size(); ++i) {
      const Eigen::Index at_i = offset[prior.landmarks.size() + i];
      const Eigen::Matrix<double, X, X> D = minus_jacobian_first<Space>(at.pose(prior.poses[i]), prior.pose_theta[i]);
      Lambda.middleRows(at_i, X) = (D.transpose() * Lambda.middleRows(at_i, X)).eval();
      Lambda.middleCols(at_i, X) = (Lambda.middleCols(at_i, X) * D).eval();
      g.template segment<X>(at_i) = (D.transpose() * g.template segment<X>(at_i)).eval();
    }
  auto dim = [&](std::size_t i) { return i < prior.landmarks.size() ? Eigen::Index{M} : Eigen::Index{X}; };
  for (std::size_t i = 0; i < count; ++i) {
    sys.b.segment(in_sys[i], dim(i)) += g.segment(offset[i], dim(i));
    for (std::size_t k = 0; k < count; ++k)
      sys.H.block(in_sys[i], in_sys[k], dim(i), dim(k)) += Lambda.block(offset[i], offset[k], dim(i), dim(k));
  }
}

/// The prior on pose 0 (eq. 64) and motion factor k (pose k -> k + 1, eqs. 60-61) at `at`.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_lag_pose_prior(LagSys& sys, const LagEstimate& at) const {
  const PriorInformation prior = prior_information_at(at.pose(0));
  const Eigen::Index i = sys.pose_at.at(0);
  sys.H.template block<X, X>(i, i) += prior.Lambda;
  sys.b.template segment<X>(i) += prior.g;
}

template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_lag_motion(LagSys& sys, const LagEstimate& at, std::size_t k) const {
  const auto info = motion_information(k, at.pose(k), at.pose(k + 1));
  sys.add_factor(sys.pose_at.at(k), sys.pose_at.at(k + 1), info);
}

/// The landmark's measurements from poses from .. to (eqs. 62-63); one the model cannot evaluate
/// sits this one out, as in the batch.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_lag_measurements(LagSys& sys, const LagEstimate& at, std::size_t slot,
                                                        std::size_t from, std::size_t to) const {
  const auto& records = measurements_[slot];
  const Eigen::Index j = sys.landmark_at.at(slot);
  for (auto record = records.rbegin(); record != records.rend() && record->pose >= from; ++record) {
    if (record->pose > to) continue;
    const auto info = measurement_information(slot, *record, at.pose(record->pose), at.landmark(slot));
    if (!info) continue;
    sys.add_factor(sys.pose_at.at(record->pose), j, *info);
  }
}

/// A landmark seen again after it left the window: its marginal when it left, as a prior.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_retired_prior(LagSys& sys, const LagEstimate& at, std::size_t slot,
                                                  const Lag& window) const {
  const auto it = window.retired.find(landmarks_.id_at(slot));
  if (it == window.retired.end()) return;
  const Eigen::Index j = sys.landmark_at.at(slot);
  sys.H.template block<M, M>(j, j) += it->second.information;
  sys.b.template segment<M>(j) -= it->second.information * (at.landmark(slot) - it->second.mean);
}

/// The window's normal equations at `at`: the landmarks `slots` (those without a factor on another
/// landmark first: the prior's last), then the poses first .. newest (the newest last, so that its
/// marginal is the factor's last block), with every factor on them.
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::lag_system(const std::vector<std::size_t>& slots, const LagEstimate& at,
                                           MatrixWorkspace& memory) const -> LagSys {
  const std::size_t first = lag_.first, last = poses_.size() - 1;
  LagSys sys;
  for (std::size_t slot : slots)
    if (!in_lag_prior(slot)) sys.add_landmark(slot);
  for (std::size_t slot : slots) sys.add_landmark(slot);
  for (std::size_t p = first; p <= last; ++p) sys.add_pose(p);
  sys.allocate(memory);
  add_lag_prior(sys, at, lag_.prior);
  if (first == 0) add_lag_pose_prior(sys, at);
  for (std::size_t k = first; k < last; ++k) add_lag_motion(sys, at, k);
  for (std::size_t slot : slots) {
    add_lag_measurements(sys, at, slot, first, last);
    add_retired_prior(sys, at, slot, lag_);
  }
  if (!sys.H.allFinite() || !sys.b.allFinite()) {
    throw numerical_error("GraphSLAM (fixed lag): the window's system is not finite at " + lag_variable_at(sys, first_non_finite(sys)));
  }
  return sys;
}

/// The first row of sys's H or b that is not finite.
template <int X, int M>
Eigen::Index first_non_finite(const LagSystem<X, M>& sys) {
  for (Eigen::Index i = 0; i < sys.dims; ++i)
    if (!sys.H.row(i).allFinite() || !std::isfinite(sys.b(i))) return i;
  return sys.dims;
}

/// Which variable of sys holds row `row`: "landmark <id>" or "pose <index>".
template <class Motion, class Sensor>
std::string GraphSlam<Motion, Sensor>::lag_variable_at(const LagSys& sys, Eigen::Index row) const {
  for (const auto& [slot, offset] : sys.landmark_at)
    if (row >= offset && row < offset + M) return "landmark " + std::to_string(landmarks_.id_at(slot));
  for (const auto& [p, offset] : sys.pose_at)
    if (row >= offset && row < offset + X) return "pose " + std::to_string(p);
  return "no variable";
}

/// The prior left when pose `pose` (if any) and the landmarks `slots` are marginalized out of the
/// window at `at`: the old prior and every factor on them, their variables eliminated.
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::marginalized_prior(std::optional<std::size_t> pose, const std::vector<std::size_t>& slots,
                                                   const LagEstimate& at, const Lag& window,
                                                   MatrixWorkspace& memory) const ->
    typename Lag::Prior {
  const std::size_t last = poses_.size() - 1;
  auto seen_at = [&](std::size_t slot, std::size_t p) {
    return std::any_of(measurements_[slot].rbegin(), measurements_[slot].rend(), [&](const auto& r) { return r.pose == p; });
  };
  std::vector<std::size_t> seen_from_pose;  // landmarks measured from `pose`, not marginalized now
  if (pose)
    for (LandmarkId id : window.seen_from[*pose])
      if (landmarks_.contains(id) && seen_at(landmarks_.slot(id), *pose) &&
          std::find(slots.begin(), slots.end(), landmarks_.slot(id)) == slots.end())
        seen_from_pose.push_back(landmarks_.slot(id));
  LagSys sys;
  for (std::size_t slot : slots) sys.add_landmark(slot);
  if (pose) sys.add_pose(*pose);
  const Eigen::Index removed = sys.dims;
  for (LandmarkId id : window.prior.landmarks) sys.add_landmark(landmarks_.slot(id));
  for (std::size_t slot : seen_from_pose) sys.add_landmark(slot);
  for (std::size_t p : window.prior.poses) sys.add_pose(p);
  if (pose && *pose < last) sys.add_pose(*pose + 1);
  for (std::size_t slot : slots)
    for (const auto& record : measurements_[slot])
      if (record.pose >= window.first) sys.add_pose(record.pose);
  sys.allocate(memory);
  add_lag_prior(sys, at, window.prior);
  if (pose && *pose == 0) add_lag_pose_prior(sys, at);
  if (pose && *pose < last) add_lag_motion(sys, at, *pose);
  for (std::size_t slot : seen_from_pose) add_lag_measurements(sys, at, slot, *pose, *pose);
  for (std::size_t slot : slots) {
    add_lag_measurements(sys, at, slot, window.first, last);
    add_retired_prior(sys, at, slot, window);
  }
  typename Lag::Prior out;
  schur_complement(sys, removed, out.Lambda, out.eta);
  std::vector<std::pair<Eigen::Index, std::size_t>> kept_landmarks, kept_poses;  // by offset
  for (const auto& [slot, offset] : sys.landmark_at)
    if (offset >= removed) kept_landmarks.emplace_back(offset, slot);
  for (const auto& [p, offset] : sys.pose_at)
    if (offset >= removed) kept_poses.emplace_back(offset, p);
  std::sort(kept_landmarks.begin(), kept_landmarks.end());
  std::sort(kept_poses.begin(), kept_poses.end());
  for (const auto& [offset, slot] : kept_landmarks) {
    out.landmarks.push_back(landmarks_.id_at(slot));
    out.landmark_theta.push_back(at.landmark(slot));
  }
  for (const auto& [offset, p] : kept_poses) {
    out.poses.push_back(p);
    out.pose_theta.push_back(at.pose(p));
  }
  return out;
}

/// Marginalizes the window's oldest poses until `lag` are left, each with the landmarks no later
/// pose saw (they retire, with their marginal from the step's system when GraphOptions::
/// reuse_retired_marginals asks for it), at the plan's estimate.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::slide_window(LagPlan& plan, const std::vector<std::size_t>& slots, const LagSys& sys,
                                             const LagSolve& solved, MatrixWorkspace& memory) const {
  const std::size_t last = poses_.size() - 1;
  const LagEstimate at{&plan.poses, &plan.means};
  while (last + 1 - plan.window.first > options_.lag) {
    const std::size_t p = plan.window.first;
    std::vector<std::size_t> leaving;
    for (std::size_t slot : slots)
      if (measurements_[slot].back().pose == p) leaving.push_back(slot);
    auto prior = marginalized_prior(p, leaving, at, plan.window, memory);
    if (options_.reuse_retired_marginals)  // otherwise a landmark seen again starts from its window
      for (std::size_t slot : leaving) {
        const Eigen::Matrix<double, M, M> cov = symmetrized(solved.landmark_covariance(sys, sys.landmark_at.at(slot)));
        plan.window.retired[landmarks_.id_at(slot)] = {
            at.landmark(slot), inverse_of_spd_or_throw(cov, "marginal covariance of landmark " + std::to_string(landmarks_.id_at(slot)))};
      }
    plan.window.prior = std::move(prior);
    plan.window.seen_from[p].clear();
    plan.window.first = p + 1;
  }
}

/// One fixed-lag step after update() recorded the frame: linearize the window at the current
/// estimate, take the Gauss-Newton step, marginalize what leaves the window, commit. A throw before
/// the commit leaves the estimator as it was.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::step_lag(const std::vector<std::size_t>& touched) {
  const std::size_t first = lag_.first, last = poses_.size() - 1;
  const std::vector<std::size_t> slots = lag_slots(touched);
  const LagSys sys = lag_system(slots, {&poses_, &landmarks_.means().stacked()}, lag_scratch_.window);
  Eigen::Index free_dims = sys.pose_at.at(first);  // the prior's landmarks follow the free ones
  for (LandmarkId id : lag_.prior.landmarks) free_dims = std::min(free_dims, sys.landmark_at.at(landmarks_.slot(id)));
  const LagSolve solved(sys, free_dims, sys.pose_at.at(first), lag_scratch_.factor);
  const Eigen::VectorXd& delta = solved.delta;
  LagPlan plan{poses_, landmarks_.means().stacked(), lag_, {}};
  for (std::size_t p = first; p <= last; ++p) {
    plan.poses[p] = Space::plus(poses_[p], delta.template segment<X>(sys.pose_at.at(p)));
    if (!Space::is_finite(plan.poses[p])) throw numerical_error("GraphSLAM (fixed lag): the step of pose " + std::to_string(p) + " is not finite");
  }
  for (std::size_t slot : slots)
    plan.means.template segment<M>(M * static_cast<Eigen::Index>(slot)) += delta.template segment<M>(sys.landmark_at.at(slot));
  plan.newest_cov = symmetrized(solved.newest_pose_covariance());
  plan.window.seen_from.resize(poses_.size());
  for (std::size_t slot : touched) plan.window.seen_from[last].push_back(landmarks_.id_at(slot));
  slide_window(plan, slots, sys, solved, lag_scratch_.marginalization);
  poses_ = std::move(plan.poses);
  landmarks_.means().stacked() = std::move(plan.means);
  lag_ = std::move(plan.window);
  newest_cov_ = plan.newest_cov;
  online_.last_step = {.first_row = first, .poses = poses_.size(), .linearized_landmarks = slots.size()};
}

/// Fixed-lag bookkeeping of remove_landmark: a landmark the window sees is marginalized into the
/// prior; a retired one is forgotten. Returns the window to commit.
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::lag_without(std::size_t slot, MatrixWorkspace& memory) const -> Lag {
  Lag out = lag_;
  const LandmarkId id = landmarks_.id_at(slot);
  if (measurements_[slot].back().pose >= lag_.first)
    out.prior = marginalized_prior(std::nullopt, {slot}, {&poses_, &landmarks_.means().stacked()}, lag_, memory);
  out.retired.erase(id);
  return out;
}

}  // namespace sextant
