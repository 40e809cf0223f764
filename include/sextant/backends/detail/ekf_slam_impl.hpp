#pragma once
// Bodies of EkfSlam (see ../ekf_slam.hpp).

#include <algorithm>
#include <limits>
#include <string>
#include <utility>

#include "sextant/core/iterate_settled.hpp"
#include "sextant/core/landmark_init.hpp"
#include "sextant/core/symmetric_rank_update.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

template <class Motion, class Sensor>
EkfSlam<Motion, Sensor>::EkfSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, EkfOptions options)
    : motion_(std::move(motion)), sensor_(std::move(sensor)), options_(options), x_(prior.mean), propagated_(prior.mean),
      cov_(X) {
  if (!Space::is_finite(prior.mean)) throw invalid_input_error("prior mean contains NaN or Inf");
  require_constrainable<Space, Landmark>(options_.observability_constraints);
  cholesky_or_throw(prior.cov, "prior covariance");
  if (options_.iterations < 1)
    throw invalid_input_error("EkfOptions::iterations must be at least 1 (got " + std::to_string(options_.iterations) + ")");
  gate_ = InnovationGate(Z, options_.gate_probability);
  if (options_.reacquisition.min_landmarks != 0)  // checks the options; needs the gate
    recovery_ = Recovery(options_.reacquisition, options_.gate_probability);
  cov_.view() = symmetrized(prior.cov);
}

/// Thesis eqs. (10)-(13): mu' = g(u, mu); P_xx' = G P_xx G^T + R; P_xm' = G P_xm. O(n).
/// The new blocks are computed and checked first, then written.
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::predict(const Control& u, double dt) {
  require_finite(u, "control");
  require_positive_time_step(dt);
  const auto prediction = checked_motion_prediction(motion_, x_, u, dt);
  auto P = cov_.view();
  const Eigen::Matrix<double, X, X> G =
      robot_transition<Space, X>(options_.observability_constraints, prediction.J_x_x, propagated_, prediction.x);
  const Eigen::Index rest = P.rows() - X;
  const Eigen::Matrix<double, X, X> P_xx = symmetrized(G * symmetric_diagonal_block<X>(P, 0) * G.transpose() + prediction.R);
  const Eigen::MatrixXd P_mx = P.bottomLeftCorner(rest, X) * G.transpose();
  if (!P_xx.allFinite() || !P_mx.allFinite()) throw numerical_error("EKF motion update overflowed (NaN or Inf)");
  const auto drift = recovery_.drift_after(G, prediction.R);
  P.template topLeftCorner<X, X>() = P_xx;
  P.bottomLeftCorner(rest, X) = P_mx;
  x_ = prediction.x;
  propagated_ = prediction.x;
  recovery_.set_drift(drift);
  recovery_.follow([&](EkfSlam& candidate) { candidate.predict(u, dt); });
}


/// The correction, then (when on) the re-acquisition's bookkeeping, which cannot throw.
template <class Motion, class Sensor>
UpdateResult EkfSlam<Motion, Sensor>::update(std::span<const ObservationType> observations) {
  UpdateResult result = correct_and_augment(observations);
  Recovery::after_update(*this, observations, result);
  return result;
}

/// Batch mode: one joint correction, planned in full before anything changes. Sequential mode:
/// one correction per observation on a snapshot that is restored if any step throws.
template <class Motion, class Sensor>
UpdateResult EkfSlam<Motion, Sensor>::correct_and_augment(std::span<const ObservationType> observations) {
  require_valid_observations(observations);
  const auto [known, fresh] = split_known_and_new(landmarks_.pool(), observations);
  UpdateResult result;
  if (options_.batch_update || known.size() <= 1) {
    commit(plan(known, fresh, result));
    return result;
  }
  RollbackGuard guard(x_, landmarks_, cov_);
  const std::span<const ObservationType> all_known(known);
  for (std::size_t i = 0; i < known.size(); ++i) commit(plan(all_known.subspan(i, 1), {}, result));
  commit(plan({}, fresh, result));
  guard.commit();
  return result;
}

template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::linearize(std::span<const ObservationType> known, UpdateResult& result) const
    -> std::vector<Linearized> {
  std::vector<Linearized> out;
  out.reserve(known.size());
  for (const auto& observation : known) {
    const std::size_t slot = landmarks_.slot(observation.landmark_id);
    if (auto lin = linearize_at(observation, slot, x_, landmark_mean(slot), result.unusable)) out.push_back(std::move(*lin));
  }
  return out;
}

/// One observation linearized at robot state x and landmark mean m, with the Jacobians the options
/// ask for (first estimates, observability constraints); none when the model cannot use it there.
template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::linearize_at(const ObservationType& observation, std::size_t slot, const State& x,
                                           const Landmark& m, std::vector<LandmarkId>& unusable) const
    -> std::optional<Linearized> {
  return linearize_for_filter<Space>(sensor_, x, m, Landmark(landmarks_.first_mean(slot)), observation, offset_of(slot),
                                     propagated_, {options_.first_estimate_jacobians, options_.observability_constraints},
                                     unusable);
}

/// Iterated EKF: x_{i+1} = x_0 + P H_i^T S_i^-1 (z - h(x_i) + H_i (x_i - x_0)), the Gauss-Newton step
/// on ||x - x_0||^2_P^-1 + sum ||z - h(x)||^2_Q^-1 from the iterate x_i (Bell and Cathey 1993), until
/// the correction moves by less than 1e-9 of itself. Leaves `observations` linearized at the last
/// iterate (an observation the model cannot use at the next one ends the iterations there); plan()
/// then corrects with them once. A correction that fails at an iterate throws, as at the first.
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::relinearize_at_iterates(std::span<const ObservationType> known,
                                                      std::vector<Linearized>& observations) const {
  Correction correction = compute_correction(observations, false);
  for (int i = 1; i < options_.iterations; ++i) {
    auto relinearized = relinearize(known, observations, correction);
    if (!relinearized) return;
    Correction next = compute_correction(*relinearized, false);
    const double moved = (next.delta - correction.delta).template lpNorm<Eigen::Infinity>();
    observations = std::move(*relinearized);
    correction = std::move(next);
    if (iterate_settled(moved, correction.delta.template lpNorm<Eigen::Infinity>())) return;
  }
}

template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::relinearize(std::span<const ObservationType> known,
                                          const std::vector<Linearized>& observations,
                                          const Correction& correction) const -> std::optional<std::vector<Linearized>> {
  std::vector<Linearized> out;
  out.reserve(observations.size());
  std::vector<LandmarkId> unusable;
  auto observation = known.begin();  // observations keep known's order (some left out)
  const Eigen::Matrix<double, X, 1> dx = correction.delta.template head<X>();
  for (const auto& previous : observations) {
    while (observation->landmark_id != previous.id) ++observation;
    const std::size_t slot = landmarks_.slot(previous.id);
    const Eigen::Matrix<double, M, 1> dm = correction.delta.template segment<M>(previous.offset);
    auto lin = linearize_at(*observation, slot, correction.x, Landmark(landmark_mean(slot) + dm), unusable);
    if (!lin) return std::nullopt;
    lin->residual += lin->J_z_x * dx + lin->J_z_m * dm;
    out.push_back(std::move(*lin));
  }
  return out;
}

/// P H_i^T for one observation, from the robot and landmark column blocks only: O(n).
template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::cross_covariance(const Linearized& obs) const -> Eigen::Matrix<double, Eigen::Dynamic, Z> {
  const auto P = cov_.view();
  return symmetric_column_block<X>(P, 0) * obs.J_z_x.transpose() +
         symmetric_column_block<M>(P, obs.offset) * obs.J_z_m.transpose();
}

/// Removes observations whose innovation fails the chi-square test (core/innovation_gate.hpp).
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::gate(std::vector<Linearized>& observations, UpdateResult& result) const {
  if (!gate_.on()) return;
  std::vector<Linearized> kept;
  for (auto& obs : observations) {
    const Eigen::Matrix<double, Z, Z> S = symmetrized(jacobian_times(obs, cross_covariance(obs)) + obs.Q);
    const auto llt = cholesky_or_throw(S, "innovation covariance of landmark " + std::to_string(obs.id));
    const double nis = mahalanobis_squared(llt, obs.residual);
    result.log_likelihood += gated_log_likelihood(gate_, llt, nis);
    if (gate_.rejects(nis))
      result.rejected.push_back(obs.id);
    else
      kept.push_back(std::move(obs));
  }
  observations = std::move(kept);
}

/// Thesis eqs. (14)-(16) for k observations at once: C = P H^T, S = H C + Q, delta = C S^-1 nu;
/// and the factors of the covariance correction, checked for overflow before anything changes.
template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::compute_correction(const std::vector<Linearized>& observations,
                                                 bool with_covariance) const -> Correction {
  const Eigen::Index n = state_dim(), k = static_cast<Eigen::Index>(observations.size());
  Eigen::MatrixXd C(n, Z * k);
  Eigen::VectorXd nu(Z * k);
  for (Eigen::Index i = 0; i < k; ++i) {
    C.template middleCols<Z>(Z * i) = cross_covariance(observations[i]);
    nu.template segment<Z>(Z * i) = observations[i].residual;
  }
  Eigen::MatrixXd S(Z * k, Z * k);
  for (Eigen::Index i = 0; i < k; ++i) {
    const auto& obs = observations[i];
    S.template middleRows<Z>(Z * i) = jacobian_times(obs, C);
    S.template block<Z, Z>(Z * i, Z * i) += obs.Q;
  }
  const auto llt = cholesky_or_throw(symmetrized(S), "innovation covariance S");
  Correction out;
  out.delta = C * llt.solve(nu);
  if (!out.delta.allFinite()) throw numerical_error("EKF correction is not finite");
  out.x = Space::plus(x_, out.delta.template head<X>());
  if (!Space::is_finite(out.x)) throw numerical_error("EKF correction of the robot state is not finite");
  if (!with_covariance) return out;
  if constexpr (has_plus_jacobian_v<Space, State>) {
    if (options_.tangent_reset)
      out.reset = plus_jacobian<Space>(x_, Eigen::Matrix<double, X, 1>(out.delta.template head<X>()));
    if (out.reset && !out.reset->allFinite()) throw numerical_error("EKF covariance reset is not finite");
  }
  if (options_.covariance_update == CovarianceUpdate::symmetric) {
    out.Wt = std::move(C);
    right_solve_lower_transposed(llt.matrixLLT(), out.Wt);  // W^T = (L^-1 C^T)^T, in C's memory
    // |(W^T W)_ij| <= max_i |W_i|^2: with that and |P| below half the double range, P - W^T W is finite.
    const double largest = out.Wt.size() ? out.Wt.rowwise().squaredNorm().maxCoeff() : 0.0;
    if (!out.Wt.allFinite() || !(largest < 0.25 * std::numeric_limits<double>::max()))
      throw numerical_error("EKF covariance correction would overflow");
  } else {
    const Eigen::MatrixXd K = llt.solve(C.transpose()).transpose();
    out.P_joseph = joseph_covariance(observations, K);
    if (!out.P_joseph.allFinite()) throw numerical_error("EKF covariance correction (Joseph form) is not finite");
  }
  return out;
}

/// Joseph form (I - K H) P (I - K H)^T + K Q K^T as written, with X = I - K H formed explicitly on
/// the columns S that H touches (robot and observed landmarks) and equal to I elsewhere:
///   A = X P:    rows S of A = X_SS P_S,   other rows = P_i + X_iS P_S   (P_S: rows S of P);
///   B = A X^T:  columns S of B = A_:S X_SS^T,  other columns = A_:j + A_:S X_jS^T;
///   P' = B + K Q K^T.
/// Rows and columns in S come out as products with the small entries of X_SS instead of as the
/// difference of two large numbers (the cancellation of eq. 17). O(n^2 |S|) with three products.
template <class Motion, class Sensor>
Eigen::MatrixXd EkfSlam<Motion, Sensor>::joseph_covariance(const std::vector<Linearized>& observations,
                                                           const Eigen::MatrixXd& K) const {
  const Eigen::Index zk = K.cols();
  std::vector<Eigen::Index> support;  // S: robot, then each observed landmark's block (distinct ids)
  for (Eigen::Index i = 0; i < X; ++i) support.push_back(i);
  for (const auto& obs : observations)
    for (Eigen::Index i = 0; i < M; ++i) support.push_back(obs.offset + i);
  const Eigen::Index s = static_cast<Eigen::Index>(support.size());
  Eigen::MatrixXd H_S = Eigen::MatrixXd::Zero(zk, s);
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const Eigen::Index row = Z * static_cast<Eigen::Index>(i);
    H_S.block(row, 0, Z, X) = observations[i].J_z_x;
    H_S.block(row, X + M * static_cast<Eigen::Index>(i), Z, M) = observations[i].J_z_m;
  }
  Eigen::MatrixXd X_S = -K * H_S;  // X restricted to the columns S
  for (Eigen::Index j = 0; j < s; ++j) X_S(support[j], j) += 1.0;
  const Eigen::MatrixXd P = covariance();
  const Eigen::MatrixXd P_S = P(support, Eigen::all);
  Eigen::MatrixXd A = P;
  A(support, Eigen::all).setZero();
  A.noalias() += X_S * P_S;
  Eigen::MatrixXd A_S = A(Eigen::all, support);
  A(Eigen::all, support).setZero();
  A.noalias() += A_S * X_S.transpose();
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(zk, zk);
  for (std::size_t i = 0; i < observations.size(); ++i)
    Q.block(Z * static_cast<Eigen::Index>(i), Z * static_cast<Eigen::Index>(i), Z, Z) = observations[i].Q;
  const Eigen::MatrixXd KQ = K * Q;
  A.noalias() += KQ * K.transpose();
  return symmetrized(A);
}

/// P's robot rows and columns (lower triangle) read in the tangent at the corrected robot state:
/// P_xx -> G P_xx G^T, P_mx -> P_mx G^T. O(n X^2).
template <class Motion, class Sensor>
template <class Lower>
void EkfSlam<Motion, Sensor>::reset_robot_tangent(Lower& P, const Eigen::Matrix<double, X, X>& G) {
  const Eigen::Index below = P.rows() - X;
  const Eigen::Matrix<double, X, X> P_xx = symmetric_diagonal_block<X>(P, 0);
  P.template topLeftCorner<X, X>().template triangularView<Eigen::Lower>() = symmetrized(G * P_xx * G.transpose());
  if (below > 0) P.bottomLeftCorner(below, X) = (P.bottomLeftCorner(below, X) * G.transpose()).eval();
}

/// Commits a planned correction: nothing here can fail.
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::apply(const Correction& correction) {
  auto P = cov_.view();
  if (options_.covariance_update == CovarianceUpdate::symmetric)
    symmetric_rank_update<Eigen::Lower, RankUpdateOf::columns>(P, correction.Wt, -1.0, 1.0);  // P - W^T W (eq. 17)
  else
    P.template triangularView<Eigen::Lower>() = correction.P_joseph;
  if (correction.reset) reset_robot_tangent(P, *correction.reset);
  x_ = correction.x;
  landmarks_.means().stacked() += correction.delta.tail(correction.delta.size() - X);
}

template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::plan(std::span<const ObservationType> known, std::span<const ObservationType> fresh,
                                   UpdateResult& result) const -> Plan {
  Plan out;
  std::vector<Linearized> observations = linearize(known, result);
  gate(observations, result);
  State x_after = x_;
  if (!observations.empty()) {
    if (options_.iterations > 1) relinearize_at_iterates(known, observations);
    out.correction = compute_correction(observations);
    x_after = out.correction->x;
    result.corrected += observations.size();
  }
  // The corrected P_xx is below the current one, so P_mm = J_m_x P_xx J_m_x^T + J_m_z Q J_m_z^T finite
  // with the current P_xx means finite after the correction too, and so are the cross terms
  // (|P_m,j| <= sqrt(P_mm P_jj)): augment() in commit() cannot overflow.
  const Eigen::Matrix<double, X, X> P_xx = symmetric_diagonal_block<X>(cov_.view(), 0);
  for (const auto& observation : fresh) {
    auto initialized = initialize_if_observable(sensor_, x_after, observation.z, observation.landmark_id,
                                                observation.noise_scale, result.unusable);
    if (!initialized) continue;
    auto& init = *initialized;
    if (!(init.J_m_x * P_xx * init.J_m_x.transpose()).allFinite())
      throw numerical_error("covariance of new landmark " + std::to_string(observation.landmark_id) + " overflows");
    out.new_landmarks.emplace_back(observation.landmark_id, std::move(init));
  }
  result.initialized += out.new_landmarks.size();
  return out;
}

template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::commit(const Plan& plan) {
  if (plan.correction) apply(*plan.correction);
  if (plan.new_landmarks.size() > 1)  // one allocation for a batch of new landmarks
    cov_.reserve(cov_.dim() + M * static_cast<Eigen::Index>(plan.new_landmarks.size()));
  for (const auto& [id, init] : plan.new_landmarks) augment(id, init);
}

/// State augmentation with the inverse model: P_mm = J_m_x P_xx J_m_x^T + J_m_z Q J_m_z^T,
/// P_m,rest = J_m_x P_x,rest (the cross-covariance that makes new landmarks correlated with the robot).
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::augment(LandmarkId id, const Init& init) {
  const Eigen::Index offset = cov_.dim();
  landmarks_.add(id, init.m);
  cov_.grow(M);
  auto P = cov_.view();
  const Eigen::Matrix<double, X, X> P_xx = symmetric_diagonal_block<X>(P, 0);
  P.block(offset, 0, M, X) = init.J_m_x * P_xx;
  P.block(offset, X, M, offset - X) = init.J_m_x * P.block(X, 0, offset - X, X).transpose();
  P.template block<M, M>(offset, offset) =
      symmetrized(init.J_m_x * P_xx * init.J_m_x.transpose() + init.J_m_z * init.Q * init.J_m_z.transpose());
}

template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::add_landmark(const LandmarkEstimate<M>& known) {
  require_valid_known_landmark(known, landmarks_.contains(known.id));
  recovery_.follow([&](EkfSlam& candidate) { candidate.add_landmark(known); });  // checked above
  const Eigen::Index offset = cov_.dim();
  landmarks_.add(known.id, Landmark(known.mean));
  cov_.grow(M);  // zero cross-covariance with the robot and the map
  cov_.view().template block<M, M>(offset, offset) = symmetrized(known.cov);
}

/// Marginalization in moment form: drop the landmark's rows and columns (thesis §4.2.2).
template <class Motion, class Sensor>
void EkfSlam<Motion, Sensor>::remove_landmark(LandmarkId id) {
  const auto removal = landmarks_.remove(id);
  auto P = cov_.view();
  mirror_lower_to_upper(P);  // the move below reads whole rows and columns
  cov_.remove_block_by_moving_last(offset_of(removal.freed_slot), M);
  recovery_.follow([&](EkfSlam& candidate) { candidate.remove_landmark(id); });
}

template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::landmark_at(std::size_t slot) const -> LandmarkEstimate<M> {
  return {landmarks_.id_at(slot), landmark_mean(slot), symmetric_diagonal_block<M>(cov_.view(), offset_of(slot))};
}

template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::map() const -> MapEstimate {
  MapEstimate out;
  out.reserve(landmarks_.size());
  for (std::size_t slot = 0; slot < landmarks_.size(); ++slot) out.push_back(landmark_at(slot));
  return out;
}

template <class Motion, class Sensor>
auto EkfSlam<Motion, Sensor>::joint_marginal(std::span<const LandmarkId> ids) const -> JointMarginal<State, M> {
  JointMarginal<State, M> out{x_, {ids.begin(), ids.end()}, {}, {}};
  const auto rows = joint_rows<X, M>(landmarks_.template gather<X>(ids, out.landmarks));
  const auto lower = cov_.view();
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  out.cov.resize(n, n);
  for (Eigen::Index c = 0; c < n; ++c)
    for (Eigen::Index r = c; r < n; ++r)
      out.cov(r, c) = out.cov(c, r) = lower(std::max(rows[r], rows[c]), std::min(rows[r], rows[c]));
  return out;
}

}  // namespace sextant
