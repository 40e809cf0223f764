#pragma once
// Bodies of SeifSlam (see ../seif_slam.hpp).

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <unordered_set>
#include <utility>

#include "sextant/core/factor_information.hpp"
#include "sextant/core/iterate_settled.hpp"
#include "sextant/core/landmark_init.hpp"
#include "sextant/core/seif_sparsification.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

template <class Motion, class Sensor>
SeifSlam<Motion, Sensor>::SeifSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, SeifOptions options)
    : motion_(std::move(motion)), sensor_(std::move(sensor)), options_(options), x_(prior.mean), propagated_(prior.mean) {
  require_constrainable<Space, Landmark>(options_.observability_constraints);
  if (!Space::is_finite(prior.mean)) throw invalid_input_error("prior mean contains NaN or Inf");
  info_.robot() = inverse_of_spd_or_throw(prior.cov, "prior covariance");
  if (!(options_.relocalization_min_information >= 0.0) || !std::isfinite(options_.relocalization_min_information))
    throw invalid_input_error("SeifOptions: relocalization_min_information must be finite and >= 0");
  if (options_.relocalization_active_bound != 0 && options_.relocalization_active_bound < options_.max_active)
    throw invalid_input_error("SeifOptions: relocalization_active_bound must be 0 (no bound) or at least max_active");
  if (options_.mean_recovery_sweeps < 0 || options_.exact_recovery_period < 0)
    throw invalid_input_error("SeifOptions: mean_recovery_sweeps and exact_recovery_period must be >= 0");
  if (options_.iterations < 1)
    throw invalid_input_error("SeifOptions: iterations must be >= 1 (1 = one linearization, the thesis's SEIF)");
  gate_ = InnovationGate(Z, options_.gate_probability);
  if (!(options_.stale_mean_probability >= 0.0 && options_.stale_mean_probability < 1.0))
    throw invalid_input_error("SeifOptions: stale_mean_probability must be in [0, 1) (0 = off)");
  if (options_.stale_mean_probability > 0.0) stale_gate_ = chi_square_quantile(M, options_.stale_mean_probability);
  if (options_.sparsification == SeifSparsification::relocalization) tail_information_ = relocalized_tail_information(prior);
  if (options_.reacquisition.min_landmarks != 0)  // checks the options; needs the gate
    recovery_ = Recovery(options_.reacquisition, options_.gate_probability);
}

/// The information of the relocalized tail: SeifOptions::relocalization_tail_covariance inverted, or
/// the prior's tail covariance; nothing when no tail is unseen. Throws invalid_input_error on a
/// covariance of the wrong size or one that is not positive definite.
template <class Motion, class Sensor>
Eigen::MatrixXd SeifSlam<Motion, Sensor>::relocalized_tail_information(const PoseEstimate& prior) const {
  constexpr int T = kUnseenTail;
  const Eigen::MatrixXd& given = options_.relocalization_tail_covariance;
  if (given.size() > 0 && (given.rows() != T || given.cols() != T))
    throw invalid_input_error("SeifOptions: relocalization_tail_covariance must be " + std::to_string(T) + " x " +
                              std::to_string(T) + " (the entries of the state no measurement sees), got " +
                              std::to_string(given.rows()) + " x " + std::to_string(given.cols()));
  if (T == 0) return {};
  const Eigen::MatrixXd cov = given.size() > 0 ? given : Eigen::MatrixXd(prior.cov.bottomRightCorner(T, T));
  if (!cov.allFinite()) throw invalid_input_error("SeifOptions: relocalization_tail_covariance contains NaN or Inf");
  const Eigen::LLT<Eigen::MatrixXd> llt(symmetrized(cov));
  if (llt.info() != Eigen::Success)
    throw invalid_input_error("SeifOptions: relocalization tail covariance is not positive definite");
  return inverse_from_cholesky(llt);
}

/// Thesis eqs. (20)-(26) in error-state form, with Phi = G^-T Omega G^-1 and
/// T = (R^-1 + Phi_xx)^-1 = (I + R Phi_xx)^-1 R (no R^-1 needed):
///   Omega_xx' = A Phi_xx,  Omega_xj' = A Phi_xj,  Omega_ij' = Omega_ij - Phi_xi^T T Phi_xj,
///   r_x' = A G^-T r_x,     r_j' = r_j - Phi_xj^T T G^-T r_x,
/// for the active landmarks i, j only; everything else is untouched. A = I - Phi_xx T is computed
/// as (I + Phi_xx R)^-1, the same matrix without the cancellation that makes I - Phi_xx T garbage
/// (and Omega indefinite) when R is large against Phi_xx^-1, e.g. after a long dt.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::predict(const Control& u, double dt) {
  require_finite(u, "control");
  require_positive_time_step(dt);
  const auto prediction = checked_motion_prediction(motion_, x_, u, dt);
  const Eigen::Matrix<double, X, X> G =
      robot_transition<Space, X>(options_.observability_constraints, prediction.J_x_x, propagated_, prediction.x);
  const auto drift = recovery_.drift_after(G, prediction.R);
  apply_motion(prediction.x, G, prediction.R);
  propagated_ = prediction.x;
  recovery_.set_drift(drift);
  recovery_.follow([&](SeifSlam& candidate) { candidate.predict(u, dt); });
}

/// As EkfSlam::reacquire_pose: Sigma_xx += d d^T with the mean moved by d, the motion update with
/// G = I and R = d d^T (its T needs no R^-1).
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::reacquire_pose(const Eigen::Matrix<double, X, 1>& d) {
  if (!d.allFinite()) throw invalid_input_error("reacquire_pose: the offset contains NaN or Inf");
  const State moved = Space::plus(x_, d);
  if (!Space::is_finite(moved)) throw numerical_error("reacquire_pose: the moved pose is not finite");
  apply_motion(moved, Eigen::Matrix<double, X, X>::Identity(), d * d.transpose());
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::apply_motion(const State& moved, const Eigen::Matrix<double, X, X>& G,
                                            const Eigen::Matrix<double, X, X>& R) {
  using MatrixX = Eigen::Matrix<double, X, X>;
  const auto singular_values = Eigen::JacobiSVD<MatrixX>(G).singularValues();
  if (!(singular_values(X - 1) > 1e-12 * singular_values(0)))
    throw numerical_error("motion Jacobian G is singular; the SEIF motion update needs G^-1");
  const MatrixX G_inv_T = G.partialPivLu().solve(MatrixX::Identity()).transpose();  // conditioning checked above
  const MatrixX Phi_xx = symmetrized(G_inv_T * info_.robot() * G_inv_T.transpose());
  const MatrixX T = symmetrized((MatrixX::Identity() + R * Phi_xx).partialPivLu().solve(R));
  const MatrixX A = (MatrixX::Identity() + Phi_xx * R).partialPivLu().solve(MatrixX::Identity());
  std::vector<std::size_t> active;  // the active landmarks, in the order of Phi_xA's columns
  Eigen::MatrixXd Phi_xA(X, M * static_cast<Eigen::Index>(info_.robot_links().size()));
  for (const auto& [slot, block] : info_.robot_links()) {
    Phi_xA.template middleCols<M>(M * static_cast<Eigen::Index>(active.size())) = G_inv_T * block;
    active.push_back(slot);
  }
  const Eigen::Matrix<double, X, 1> r_x = G_inv_T * info_.robot_residual();
  auto change = factor_workspace_.view(Phi_xA.cols());  // -Phi_Ax T Phi_xA on the active pairs: its upper triangle
  if (!active.empty())  // Eigen's triangular product binds a reference to the data of an empty matrix
    change.template triangularView<Eigen::Upper>() = -Phi_xA.transpose() * (T * Phi_xA);
  auto at = [](std::size_t a) { return M * static_cast<Eigen::Index>(a); };

  atomically([&] {
    info_.robot() = symmetrized(A * Phi_xx);
    info_.robot_residual() = A * r_x;
    const Eigen::Matrix<double, X, 1> T_r_x = T * r_x;
    for (std::size_t a = 0; a < active.size(); ++a) {
      const std::size_t i = active[a];
      const auto Phi_xi = Phi_xA.template middleCols<M>(at(a));
      info_.set_robot_link(i, A * Phi_xi);
      const Eigen::Matrix<double, M, M> change_ii = change.template block<M, M>(at(a), at(a)).template selfadjointView<Eigen::Upper>();
      info_.diagonal(i) = symmetrized(info_.diagonal(i) + change_ii);
      info_.landmark_residual(i) -= Phi_xi.transpose() * T_r_x;
    }
    auto D = block_workspace_.view(X + at(active.size()));  // the (x, active) block after the update, for its check
    info_.add_to_links(
        active, [&](std::size_t a, std::size_t b) { return change.template block<M, M>(at(a), at(b)); },
        [&](std::size_t a, std::size_t b, const Eigen::Matrix<double, M, M>& block) {
          D.template block<M, M>(X + at(a), X + at(b)) = block;
        });
    x_ = moved;
    require_finite_robot_and_active("SEIF motion update");
    fill_robot_and_diagonal_blocks(active, D);
    require_factorizable_block(D, "SEIF motion update");
  });
}

/// One observation linearized at the current estimate (H at the first estimate if so configured).
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::linearize(const ObservationType& observation, std::vector<LandmarkId>& unusable) const
    -> std::optional<Linearized> {
  const std::size_t slot = landmarks_.slot(observation.landmark_id);
  return linearize_for_filter<Space>(sensor_, x_, landmark_mean(slot), Landmark(landmarks_.first_mean(slot)),
                                     observation, offset_of(slot), propagated_,
                                     {options_.first_estimate_jacobians, options_.observability_constraints}, unusable);
}

/// H^T Q^-1 H and H^T Q^-1 nu of one observation, by blocks (thesis eqs. 29-30).
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::measurement_information(const Linearized& lin) const -> MeasurementInformation {
  const GaussianNoise<Z> noise(lin.Q, "measurement noise Q of landmark " + std::to_string(lin.id));
  const auto info = noise.information(lin.J_z_x, lin.J_z_m, lin.residual);
  const std::size_t slot = landmarks_.slot(lin.id);
  return {slot, symmetrized(info.aa), info.ab, symmetrized(info.bb), info.a, info.b, lin.id, x_, landmark_mean(slot)};
}

/// A new landmark in information form: the conditional m = init.m + J_m_x dx + v, v ~ N(0, C),
/// C = J_m_z Q J_m_z^T, adds [J_m_x^T W J_m_x, -J_m_x^T W; -W J_m_x, W] with W = C^-1 and no residual.
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::new_landmark(const ObservationType& observation, std::vector<LandmarkId>& unusable) const
    -> std::optional<NewLandmark> {
  const auto initialized = initialize_if_observable(sensor_, x_, observation.z, observation.landmark_id,
                                                     observation.noise_scale, unusable);
  if (!initialized) return std::nullopt;
  const Init& init = *initialized;
  const Eigen::Matrix<double, M, M> C = symmetrized(init.J_m_z * init.Q * init.J_m_z.transpose());
  const Eigen::Matrix<double, M, M> W = inverse_of_spd_or_throw(
      C, "covariance J_m_z Q J_m_z^T of new landmark " + std::to_string(observation.landmark_id));
  return NewLandmark{observation.landmark_id, init.m, symmetrized(init.J_m_x.transpose() * W * init.J_m_x),
                     -init.J_m_x.transpose() * W, W};
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::add(const MeasurementInformation& info) {
  add_factor(info, 1.0, info.r_x, info.r_m);
}

/// The factor's gradient at the current mean is r - Omega_f delta, delta the move from where it was
/// linearized; that is what the factor contributes to the residual now, and what leaves with it.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::take_out(const MeasurementInformation& info) {
  const Eigen::Matrix<double, X, 1> dx = Space::minus(x_, info.at_x);
  const Eigen::Matrix<double, M, 1> dm = landmark_mean(info.slot) - info.at_m;
  add_factor(info, -1.0, info.r_x - info.xx * dx - info.xm * dm, info.r_m - info.xm.transpose() * dx - info.mm * dm);
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::add_factor(const MeasurementInformation& info, double sign,
                                          const Eigen::Matrix<double, X, 1>& r_x,
                                          const Eigen::Matrix<double, M, 1>& r_m) {
  info_.robot() += sign * info.xx;
  info_.add_to_robot_link(info.slot, sign * info.xm);
  info_.diagonal(info.slot) += sign * info.mm;
  info_.robot_residual() += sign * r_x;
  info_.landmark_residual(info.slot) += sign * r_m;
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::augment(const NewLandmark& landmark) {
  const std::size_t slot = landmarks_.add(landmark.id, landmark.mean);
  info_.append_landmark();
  info_.robot() += landmark.xx;
  info_.add_to_robot_link(slot, landmark.xm);
  info_.diagonal(slot) = landmark.mm;
}

/// The step's measurements and new landmarks added (thesis eqs. 27-30); their slots, in that order.
template <class Motion, class Sensor>
std::vector<std::size_t> SeifSlam<Motion, Sensor>::add_step(const std::vector<MeasurementInformation>& measurements,
                                                            const std::vector<NewLandmark>& landmarks) {
  std::vector<std::size_t> observed;
  for (const auto& info : measurements) {
    add(info);
    observed.push_back(info.slot);
  }
  for (const auto& landmark : landmarks) {
    augment(landmark);
    observed.push_back(landmarks_.size() - 1);
  }
  return observed;
}

/// The update, then (when on) the re-acquisition's bookkeeping, which cannot throw.
template <class Motion, class Sensor>
UpdateResult SeifSlam<Motion, Sensor>::update(std::span<const ObservationType> observations) {
  UpdateResult result = update_information(observations);
  Recovery::after_update(*this, observations, result);
  return result;
}

template <class Motion, class Sensor>
UpdateResult SeifSlam<Motion, Sensor>::update_information(std::span<const ObservationType> observations) {
  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  auto stage_start = Clock::now();
  SeifUpdateTimes times;
  require_valid_observations(observations);
  const auto split = split_known_and_new(landmarks_.pool(), observations);
  const auto& known = split.known;  // a reference, not a structured binding: the transaction's lambda uses it
  const auto& fresh = split.fresh;
  // Linearize everything first; the rest runs as one transaction, undone if any step throws.
  std::vector<Linearized> linearized;
  linearized.reserve(known.size());
  UpdateResult result;
  for (const auto& observation : known)
    if (auto lin = linearize(observation, result.unusable)) linearized.push_back(std::move(*lin));
  gate(linearized, result);
  result.corrected = linearized.size();
  std::vector<MeasurementInformation> measurements;
  measurements.reserve(linearized.size());
  for (const auto& lin : linearized) measurements.push_back(measurement_information(lin));
  std::vector<NewLandmark> landmarks;
  landmarks.reserve(fresh.size());
  for (const auto& observation : fresh)
    if (auto landmark = new_landmark(observation, result.unusable)) landmarks.push_back(std::move(*landmark));
  result.initialized = landmarks.size();
  auto relocalization = hold_back_for_relocalization(measurements, fresh.size());
  recovered_stale_mean_ = false;
  changed_residuals_.clear();

  atomically([&] {
    const State prior = x_;
    std::vector<std::size_t> observed = add_step(measurements, landmarks);
    times.measurement_s = seconds_since(stage_start);
    stage_start = Clock::now();
    ++updates_;
    if (!relocalization.empty()) {
      if (options_.iterations > 1) iterate_before_relocalizing(known, measurements, relocalization, observed, prior);
      relocalize(relocalization, std::move(observed));
      times.mean_recovery_s = seconds_since(stage_start);
      return;
    }
    update_active_queue(observed);  // first: mean recovery orders the active block by it
    auto squared_pivots = recover_step_mean();
    if (options_.iterations > 1) relinearize_at_iterates(known, measurements, prior, squared_pivots);
    times.mean_recovery_s = seconds_since(stage_start);
    stage_start = Clock::now();
    const auto robot_squared_pivots = sparsify(squared_pivots.has_value());
    require_factorizable_after_update(squared_pivots, robot_squared_pivots);
    times.sparsification_s = seconds_since(stage_start);
  });
  last_update_times_ = times;
  if (!relocalization.empty()) ++relocalizations_;
  if (recovered_stale_mean_) ++stale_recoveries_;
  return result;
}

template <class Motion, class Sensor>
std::optional<Eigen::VectorXd> SeifSlam<Motion, Sensor>::recover_step_mean() {
  if (exact_recovery_due()) {
    recover_mean_exactly_in_transaction();
    return std::nullopt;
  }
  auto squared_pivots = recover_mean_locally();  // Omega is unchanged by what follows: the pivots hold
  recover_exactly_if_stale();
  return squared_pivots;
}

/// The iterated SEIF update: Gauss-Newton on the prior and the step's measurements, as the iterated
/// EKF (Bell and Cathey 1993), in information form. Each iterate takes the step's factors out at the
/// recovered mean (their gradient moved there), adds them again linearized there, and recovers the
/// mean; stops when it moves by < 1e-9 of the step's move, or where an observation cannot be used.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::relinearize_at_iterates(std::span<const ObservationType> known,
                                                       std::vector<MeasurementInformation>& step, const State& prior,
                                                       std::optional<Eigen::VectorXd>& squared_pivots) {
  for (int i = 1; i < options_.iterations; ++i) {
    auto relinearized = relinearize(known, step);
    if (!relinearized) break;
    for (const auto& info : step) take_out(info);
    for (const auto& info : *relinearized) add(info);
    step = std::move(*relinearized);
    squared_pivots = recover_step_mean();
    double moved = 0.0;  // since the linearization, robot and the step's landmarks
    for (const auto& info : step)
      moved = std::max({moved, Space::minus(x_, info.at_x).template lpNorm<Eigen::Infinity>(),
                        (landmark_mean(info.slot) - info.at_m).template lpNorm<Eigen::Infinity>()});
    if (iterate_settled(moved, Space::minus(x_, prior).template lpNorm<Eigen::Infinity>())) break;
  }
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::relinearize(std::span<const ObservationType> known,
                                           const std::vector<MeasurementInformation>& step) const
    -> std::optional<std::vector<MeasurementInformation>> {
  std::vector<MeasurementInformation> out;
  out.reserve(step.size());
  std::vector<LandmarkId> unusable;
  for (const auto& info : step) {
    const auto observation = std::find_if(known.begin(), known.end(),
                                          [&](const ObservationType& o) { return o.landmark_id == info.id; });
    auto lin = linearize(*observation, unusable);
    if (!lin) return std::nullopt;
    out.push_back(measurement_information(*lin));
  }
  return out;
}

/// The held-back measurements join the others, the step is iterated to its mean over the robot and
/// every landmark linked to it, and they leave again linearized there: ESEIF then relocalizes the
/// robot from measurements linearized at the step's mean instead of at the prediction.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::iterate_before_relocalizing(std::span<const ObservationType> known,
                                                           const std::vector<MeasurementInformation>& applied,
                                                           std::vector<MeasurementInformation>& held_back,
                                                           std::vector<std::size_t> observed, const State& prior) {
  std::vector<MeasurementInformation> step = applied;
  for (const auto& info : held_back) {
    add(info);
    observed.push_back(info.slot);
  }
  step.insert(step.end(), held_back.begin(), held_back.end());
  update_active_queue(observed);
  auto squared_pivots = recover_step_mean();  // relocalize() recovers again; these are not needed
  relinearize_at_iterates(known, step, prior, squared_pivots);
  held_back.assign(step.end() - static_cast<std::ptrdiff_t>(held_back.size()), step.end());
  for (const auto& info : held_back) take_out(info);
}

/// Removes the observations whose innovation fails the chi-square test, with S = H Sigma H^T + Q and
/// Sigma the joint marginal of the robot and the landmark: one multi-column solve with the factor of Omega.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::gate(std::vector<Linearized>& observations, UpdateResult& result) const {
  if (!gate_.on() || observations.empty()) return;
  std::vector<Eigen::Index> offsets;
  for (const Linearized& lin : observations) offsets.push_back(lin.offset);
  const Eigen::MatrixXd joint = joint_covariance(offsets);
  std::vector<Linearized> kept;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const Linearized& lin = observations[i];
    const Eigen::Index at = X + M * static_cast<Eigen::Index>(i);
    const Eigen::Matrix<double, Z, Z> S =
        symmetrized(innovation_cross_block(joint, lin.J_z_x, lin.J_z_m, at, lin.J_z_x, lin.J_z_m, at) + lin.Q);
    const auto llt = cholesky_or_throw(S, "innovation covariance of landmark " + std::to_string(lin.id));
    const double nis = mahalanobis_squared(llt, lin.residual);
    result.log_likelihood += gated_log_likelihood(gate_, llt, nis);
    if (gate_.rejects(nis))
      result.rejected.push_back(lin.id);
    else
      kept.push_back(lin);
  }
  observations = std::move(kept);
}

/// Runs `step` so that it either completes or, if it throws, leaves the filter exactly as before:
/// the information form is journaled block by block, the means that move are saved first.
template <class Motion, class Sensor>
template <class Step>
void SeifSlam<Motion, Sensor>::atomically(Step step) {
  Undo undo{x_, {}, {}, active_queue_, updates_, landmarks_.size()};
  undo_ = &undo;
  info_.begin_transaction();
  try {
    step();
    info_.commit();
    undo_ = nullptr;
    touch();
  } catch (...) {
    info_.rollback();
    undo_ = nullptr;
    if (undo.all_means) landmarks_.means().stacked() = std::move(*undo.all_means);
    landmarks_.truncate(undo.landmarks);
    for (auto it = undo.means.rbegin(); it != undo.means.rend(); ++it)  // oldest saved value last
      landmarks_.means().slot(it->first) = it->second;
    x_ = undo.x;
    active_queue_ = std::move(undo.active_queue);
    updates_ = undo.updates;
    touch();  // a new version, never an old one: caches may not mistake anything for the old state
    throw;
  }
}

/// mu_m += dm, remembering the old mean inside a transaction.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::move_landmark_mean(std::size_t slot, const Eigen::Matrix<double, M, 1>& dm) {
  if (undo_ && slot < undo_->landmarks && !undo_->all_means) undo_->means.emplace_back(slot, landmark_mean(slot));
  landmarks_.means().slot(slot) += dm;
}

/// Overflow shows up first in the blocks a step touched: the robot's and the active landmarks'.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::require_finite_robot_and_active(const char* what) const {
  bool finite = info_.robot().allFinite() && info_.robot_residual().allFinite() && Space::is_finite(x_);
  for (const auto& [slot, block] : info_.robot_links())
    finite = finite && block.allFinite() && info_.diagonal(slot).allFinite() && info_.landmark_residual(slot).allFinite() &&
             landmark_mean(slot).allFinite();
  if (!finite) throw numerical_error(std::string(what) + ": the information form overflowed (NaN or Inf)");
}

/// A step leaves Omega positive definite in exact arithmetic; in floating point it may not, when
/// it adds information far beyond what Omega holds (sigma 1e-100) or moves the robot by 1e100.
/// The robot-and-active block is a principal block of Omega that every step touches: if it is
/// numerically singular, so is Omega (require_well_conditioned), and pose() could not factorize it.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::require_factorizable_robot_and_active(const char* what) {
  require_finite_robot_and_active(what);
  std::vector<std::size_t> slots;
  for (const auto& [slot, block] : info_.robot_links()) slots.push_back(slot);
  auto D = block_workspace_.view(X + M * static_cast<Eigen::Index>(slots.size()));
  robot_and_landmarks_block(slots, D);
  require_factorizable_block(D, what);
}

/// require_factorizable_robot_and_active's test on D, the (robot, active) block as
/// robot_and_landmarks_block writes it; D is factorized (overwritten).
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::require_factorizable_block(Eigen::Ref<Eigen::MatrixXd> D, const char* what) {
  require_well_conditioned_in_place(D, std::string(what) + ": the information of the robot and the active landmarks");
}

/// The update's check of the block it leaves (require_factorizable_robot_and_active) without a
/// second factorization when mean recovery factorized the block before sparsification: with the
/// robot first, the block after sparsification has the squared pivots of S_xx for the robot and
/// those of the block before for m+ (core/seif_sparsification.hpp), scaled by its new diagonal.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::require_factorizable_after_update(
    const std::optional<Eigen::VectorXd>& squared_pivots,
    const std::optional<Eigen::Matrix<double, X, 1>>& robot_squared_pivots) {
  constexpr const char* what = "SEIF update";
  if (!squared_pivots) return require_factorizable_robot_and_active(what);
  require_finite_robot_and_active(what);
  Eigen::VectorXd pivots = squared_pivots->head(X + M * static_cast<Eigen::Index>(active_queue_.size()));
  if (robot_squared_pivots) pivots.template head<X>() = *robot_squared_pivots;
  pivots.template head<X>().array() /= info_.robot().diagonal().array();
  for (std::size_t a = 0; a < active_queue_.size(); ++a)
    pivots.template segment<M>(X + M * a).array() /= info_.diagonal(active_queue_[a]).diagonal().array();
  require_well_conditioned_pivots(pivots, std::string(what) + ": the information of the robot and the active landmarks");
}

template <class Motion, class Sensor>
std::optional<Eigen::VectorXd> SeifSlam<Motion, Sensor>::recover_mean_locally() {
  std::optional<Eigen::VectorXd> squared_pivots;
  for (int sweep = 0; sweep < options_.mean_recovery_sweeps; ++sweep) {
    if (options_.mean_recovery == MeanRecovery::active_block)
      squared_pivots = recover_mean_of_active_block();
    else
      recover_mean_by_coordinate_descent();
  }
  return squared_pivots;
}

/// Omega restricted to (robot, slots...) as a dense matrix, written into the lower triangle of D
/// (X + M |slots| square; the diagonal blocks whole, the rest of the strict upper triangle
/// unspecified: the factorization and the products that read D read only the lower triangle),
/// down its columns, one landmark's links at a time.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::robot_and_landmarks_block(const std::vector<std::size_t>& slots,
                                                         Eigen::Ref<Eigen::MatrixXd> D) const {
  for (std::size_t a = 0; a < slots.size(); ++a) gather_links_below(slots, a, D, a + 1);
  fill_robot_and_diagonal_blocks(slots, D);
}

/// The links of slots[a] to slots[first], slots[first + 1], ... (first > a), into D's column of
/// slots[a] below its diagonal block.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::gather_links_below(const std::vector<std::size_t>& slots, std::size_t a,
                                                  Eigen::Ref<Eigen::MatrixXd> D, std::size_t first) const {
  auto at = [](std::size_t k) { return X + M * static_cast<Eigen::Index>(k); };
  const auto below = std::span(slots).subspan(first);  // one look-up per pair
  info_.for_each_block_in_row(slots[a], below, [&](std::size_t b, const Eigen::Matrix<double, M, M>& block) {
    D.template block<M, M>(at(first + b), at(a)) = block.transpose();
  });
}

/// D's robot block, the robot's links (its first X columns) and the landmarks' diagonal blocks.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::fill_robot_and_diagonal_blocks(const std::vector<std::size_t>& slots,
                                                              Eigen::Ref<Eigen::MatrixXd> D) const {
  auto at = [](std::size_t k) { return X + M * static_cast<Eigen::Index>(k); };
  D.template topLeftCorner<X, X>() = info_.robot();
  for (std::size_t a = 0; a < slots.size(); ++a) {
    D.template block<M, X>(at(a), 0) = info_.robot_link(slots[a]).transpose();
    D.template block<M, M>(at(a), at(a)) = info_.diagonal(slots[a]);
  }
}

/// Solves Omega_BB delta_B = r_B for B = robot + `slots` (in that order; the active landmarks in the
/// queue's order), moves their means, and passes the change on to the residuals of their neighbours
/// outside B: r_b -= Omega_bB delta_B. Landmarks among the first `leading` of `slots` that are linked
/// to the robot alone (the ones this update added) are eliminated first, in closed form: their rows
/// hold only their diagonal block W_u and their robot link, so eliminating them changes only the
/// robot's block, to Omega_xx - sum_u Omega_xu W_u^-1 Omega_ux, and the dense factorization works on
/// the rest (at the thesis's scale ~670 of ~760 dimensions: a third fewer flops). Returns squared
/// pivots, one per dimension of B in B's order, of a factorization of the block that
/// require_factorizable_after_update checks, (robot, the first `leading` slots) after this update:
/// ordered (closed-form landmarks, robot, the rest) as computed when no sparsification follows;
/// when one does, ordered (robot, closed-form landmarks, the rest) with the robot's pivots left for
/// sparsification to give (core/seif_sparsification.hpp) and the closed-form landmarks' from the
/// Schur complement of the robot over them, which sparsification leaves as it is.
template <class Motion, class Sensor>
Eigen::VectorXd SeifSlam<Motion, Sensor>::recover_mean_of_block(const std::vector<std::size_t>& slots,
                                                                std::size_t leading, bool sparsification_follows) {
  const Eigen::Index d = X + M * static_cast<Eigen::Index>(slots.size());
  auto D = block_workspace_.view(d);
  robot_and_landmarks_block(slots, D);
  Eigen::VectorXd r(d);
  r.template head<X>() = info_.robot_residual();
  for (std::size_t a = 0; a < slots.size(); ++a) r.template segment<M>(X + M * a) = info_.landmark_residual(slots[a]);
  constexpr const char* what = "information of the robot and the active landmarks";
  const ClosedFormLandmarks<X, M> closed(D, r, unlinked_positions(slots, leading), what);
  const std::vector<Eigen::Index> dense = closed.dense_dimensions(d);
  auto factor = factor_workspace_.view(static_cast<Eigen::Index>(dense.size()));
  closed.copy_dense_lower_triangle(D, factor);
  factor.template topLeftCorner<X, X>() = closed.robot_information();
  const auto L = cholesky_in_place_or_throw(factor, what);
  Eigen::VectorXd r_dense = r(dense);
  r_dense.template head<X>() = closed.robot_residual();
  Eigen::VectorXd delta(d);
  delta(dense) = L.solve(r_dense);
  closed.back_substitute(delta);
  Eigen::VectorXd pivots(d);
  pivots(dense) = L.squared_pivots();
  if (sparsification_follows)
    closed.squared_pivots_after_robot(D, pivots);
  else
    closed.squared_pivots_first(pivots);
  apply_mean_recovery(slots, delta, r - D.template selfadjointView<Eigen::Lower>() * delta);
  return pivots;
}

/// The positions in B of the landmarks among the first `leading` of `slots` without landmark links.
template <class Motion, class Sensor>
std::vector<Eigen::Index> SeifSlam<Motion, Sensor>::unlinked_positions(const std::vector<std::size_t>& slots,
                                                                      std::size_t leading) const {
  std::vector<Eigen::Index> out;
  for (std::size_t a = 0; a < std::min(leading, slots.size()); ++a)
    if (info_.links(slots[a]).empty()) out.push_back(X + M * static_cast<Eigen::Index>(a));
  return out;
}

/// The new means of the robot and the block's landmarks (delta) and their residuals after it.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::apply_mean_recovery(const std::vector<std::size_t>& slots, const Eigen::VectorXd& delta,
                                                   const Eigen::VectorXd& r_after) {
  x_ = Space::plus(x_, delta.template head<X>());
  info_.robot_residual() = r_after.template head<X>();
  const auto in_block = mark_slots(slots);
  for (std::size_t a = 0; a < slots.size(); ++a) {
    const Eigen::Matrix<double, M, 1> dm = delta.template segment<M>(X + M * a);
    move_landmark_mean(slots[a], dm);
    info_.landmark_residual(slots[a]) = r_after.template segment<M>(X + M * a);
    for (const auto& [neighbour, block] : info_.links(slots[a]))
      if (!in_block(neighbour)) {
        info_.landmark_residual(neighbour) -= block.transpose() * dm;
        if (stale_gate_ > 0.0) changed_residuals_.insert(neighbour);
      }
  }
}

/// A landmark p outside the block would move by delta_p = Omega_pp^-1 r_p given its neighbours
/// (block coordinate descent's step, thesis eq. 34); delta_p^T Omega_pp delta_p = r_p^T Omega_pp^-1 r_p
/// is that move in its conditional information.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::recover_exactly_if_stale() {
  const auto& changed = changed_residuals_.members();
  const bool stale = std::any_of(changed.begin(), changed.end(), [&](std::size_t slot) {
    if (slot >= landmarks_.size()) return false;  // noted before a removal (a step that threw)
    const Eigen::Matrix<double, M, 1> r = info_.landmark_residual(slot);
    return r.dot(info_.diagonal(slot).llt().solve(r)) > stale_gate_;
  });
  changed_residuals_.clear();
  if (!stale) return;
  recover_mean_exactly_in_transaction();
  recovered_stale_mean_ = true;
}

/// A test of membership in `slots` in O(1) without hashing (core/slot_set.hpp).
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::mark_slots(const std::vector<std::size_t>& slots) {
  marked_slots_.clear();
  for (std::size_t slot : slots) marked_slots_.insert(slot);
  return [this](std::size_t slot) { return marked_slots_.contains(slot); };
}

/// Block coordinate descent on Omega delta = r over the robot and the active landmarks
/// (thesis eqs. 31-36): delta_a = Omega_aa^-1 r_a, mu_a <- mu_a + delta_a, r_b -= Omega_ba delta_a.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::recover_mean_by_coordinate_descent() {
  const auto robot_llt = cholesky_or_throw(info_.robot(), "robot block of the information matrix");
  std::vector<std::pair<std::size_t, Eigen::LLT<Eigen::Matrix<double, M, M>>>> active;
  for (const auto& [slot, block] : info_.robot_links())
    active.emplace_back(slot, cholesky_or_throw(info_.diagonal(slot), "information block of an active landmark"));
  {
    const Eigen::Matrix<double, X, 1> dx = robot_llt.solve(info_.robot_residual());
    x_ = Space::plus(x_, dx);
    info_.robot_residual() -= info_.robot() * dx;
    for (const auto& [slot, block] : info_.robot_links()) info_.landmark_residual(slot) -= block.transpose() * dx;
    for (const auto& [slot, llt] : active) {
      const Eigen::Matrix<double, M, 1> dm = llt.solve(info_.landmark_residual(slot));
      move_landmark_mean(slot, dm);
      info_.landmark_residual(slot) -= info_.diagonal(slot) * dm;
      info_.robot_residual() -= info_.robot_link(slot) * dm;
      for (const auto& [neighbour, block] : info_.links(slot)) {
        info_.landmark_residual(neighbour) -= block.transpose() * dm;
        if (stale_gate_ > 0.0) changed_residuals_.insert(neighbour);
      }
    }
  }
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::recover_mean_exactly() {
  atomically([&] { recover_mean_exactly_in_transaction(); });
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::recover_mean_exactly_in_transaction() {
  const Eigen::SparseMatrix<double> omega = info_.to_sparse();
  Factor factor;
  factor.factorize(omega);  // throws numerical_error when Omega is not PD
  const Eigen::VectorXd r = info_.residual();
  const Eigen::VectorXd delta = factor.solve(r);
  if (!delta.allFinite()) throw numerical_error("exact mean recovery is not finite");
  if (undo_ && !undo_->all_means) undo_->all_means = landmarks_.means().stacked();
  x_ = Space::plus(x_, delta.template head<X>());
  landmarks_.means().stacked() += delta.tail(delta.size() - X);
  info_.set_residual(r - omega * delta);
}

/// Which observed landmarks relocalize the robot (ESEIF): max_active of them (the new active set),
/// chosen greedily for the most information about the robot (largest log det of Lambda, the sum of
/// information_about_robot, D-optimal), and more, the next most informative, until Lambda holds at
/// least relocalization_min_information of the robot's information Omega_xx in every direction (the
/// robot state is determined by them alone, well enough to stay where linearization holds); none
/// when all of the step's measurements do not. As
/// many as the active set holds, the most informative first: a relocalized pose from the fewest
/// that determine it (two range-bearing landmarks) tracked at 6x the EKF's error on kf-slam_demo,
/// from eight in the order observed at 1.7x, from the eight most informative at 1.3x, and 1.16x
/// once a landmark's own uncertainty counts (docs/results/seif_relocalization.md).
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::hold_back_for_relocalization(std::vector<MeasurementInformation>& observations,
                                                           std::size_t new_landmarks) const
    -> std::vector<MeasurementInformation> {
  using MatrixX = Eigen::Matrix<double, X, X>;
  if (options_.sparsification != SeifSparsification::relocalization || options_.max_active == 0) return {};
  std::unordered_set<std::size_t> active;
  for (const auto& [slot, block] : info_.robot_links()) active.insert(slot);
  for (const auto& info : observations) active.insert(info.slot);
  const std::size_t linked = active.size() + new_landmarks;
  if (linked <= options_.max_active || observations.empty()) return {};
  // Past the bound, a set that determines the pose at all will do.
  const double share = linked > relocalization_active_bound() ? kAnyShare : options_.relocalization_min_information;
  std::vector<MatrixX> about_robot = information_about_robot(observations);
  MatrixX total = MatrixX::Zero();
  for (const auto& lambda : about_robot) total += lambda;
  // Lambda_beta v = lambda Omega_ss v on the entries measurements see (s): the share of the robot's
  // information given the map that the held-back measurements carry, where they carry least.
  const auto reference = seen_information_given_map();
  if (!reference) return {};
  const MatrixX regularizer = 1e-12 * total.trace() / X * MatrixX::Identity();  // log det defined from the first pick
  if (!carries_enough(total + regularizer, *reference, share)) return {};  // then no subset does: information only adds
  MatrixX chosen = regularizer;
  std::size_t count = 0;
  for (; count < observations.size(); ++count) {
    if (count >= options_.max_active && carries_enough(chosen, *reference, share)) break;
    pick_most_informative(observations, about_robot, count, chosen);
  }
  if (!carries_enough(chosen, *reference, share)) return {};  // all of them, summed in another order
  const auto held_end = observations.begin() + static_cast<std::ptrdiff_t>(count);
  std::vector<MeasurementInformation> held(std::make_move_iterator(observations.begin()), std::make_move_iterator(held_end));
  observations.erase(observations.begin(), held_end);
  return held;
}

/// Moves the observation (from position k on) whose information about the robot adds most to
/// log det(chosen) to position k, and adds its information to chosen.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::pick_most_informative(std::vector<MeasurementInformation>& observations,
                                                     std::vector<Eigen::Matrix<double, X, X>>& about_robot, std::size_t k,
                                                     Eigen::Matrix<double, X, X>& chosen) {
  std::size_t best = k;
  double best_log_det = -std::numeric_limits<double>::infinity();
  for (std::size_t j = k; j < observations.size(); ++j) {
    const double log_det = (chosen + about_robot[j]).ldlt().vectorD().array().log().sum();
    if (log_det > best_log_det) best_log_det = log_det, best = j;
  }
  std::swap(observations[k], observations[best]);
  std::swap(about_robot[k], about_robot[best]);
  chosen += about_robot[k];
}

/// Whether the information `chosen` about the robot holds `share` of `reference` (the robot's seen
/// entries given the map) in every direction, and is well conditioned (with kAnyShare, only that).
template <class Motion, class Sensor>
bool SeifSlam<Motion, Sensor>::carries_enough(const Eigen::Matrix<double, X, X>& chosen,
                                              const Eigen::Matrix<double, X - kUnseenTail, X - kUnseenTail>& reference,
                                              double share) const {
  constexpr int P = X - kUnseenTail;
  using MatrixP = Eigen::Matrix<double, P, P>;
  const MatrixP seen = chosen.template topLeftCorner<P, P>();
  if (share != kAnyShare) {
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixP> relative(seen, reference, Eigen::EigenvaluesOnly);
    if (!(relative.eigenvalues()(0) >= share)) return false;
  }
  const Eigen::SelfAdjointEigenSolver<MatrixP> eigen(seen, Eigen::EigenvaluesOnly);
  return eigen.eigenvalues()(0) > 1e-9 * eigen.eigenvalues()(P - 1);
}

/// What each observation tells about the robot once its landmark's uncertainty is counted: the
/// measurement's information on (x, m) with the landmark's information W (given the other landmarks,
/// marginal over the robot) added, the landmark then marginalized, xx - xm (mm + W)^-1 mx
/// = H_x^T (Q + H_m W^-1 H_m^T)^-1 H_x. A landmark seen once tells next to nothing about where
/// the robot is, however precise the measurement.
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::information_about_robot(const std::vector<MeasurementInformation>& observations) const
    -> std::vector<Eigen::Matrix<double, X, X>> {
  std::vector<Eigen::Matrix<double, X, X>> out;
  out.reserve(observations.size());
  const Eigen::LLT<Eigen::Matrix<double, X, X>> robot(info_.robot());
  for (const auto& info : observations) {
    Eigen::Matrix<double, M, M> W = info_.diagonal(info.slot);
    if (robot.info() == Eigen::Success && info_.is_linked_to_robot(info.slot)) {
      const Eigen::Matrix<double, X, M> link = info_.robot_link(info.slot);
      W -= link.transpose() * robot.solve(link);
    }
    const Eigen::LLT<Eigen::Matrix<double, M, M>> landmark(symmetrized((W + info.mm).eval()));
    if (landmark.info() != Eigen::Success) {
      out.push_back(info.xx);
      continue;
    }
    out.push_back(symmetrized((info.xx - info.xm * landmark.solve(info.xm.transpose())).eval()));
  }
  return out;
}

/// The information about the robot's seen entries given the map, Omega_ss; with an unseen tail t,
/// marginal over it, Omega_ss - Omega_st Omega_tt^-1 Omega_ts: relocalization replaces the tail's
/// information by its prior, and with it the pose information that came through it (the motion
/// model's velocity). None when Omega_tt is not positive definite.
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::seen_information_given_map() const
    -> std::optional<Eigen::Matrix<double, X - kUnseenTail, X - kUnseenTail>> {
  constexpr int P = X - kUnseenTail, T = kUnseenTail;
  const auto& omega = info_.robot();
  Eigen::Matrix<double, P, P> out = omega.template topLeftCorner<P, P>();
  if constexpr (T > 0) {
    const Eigen::LLT<Eigen::Matrix<double, T, T>> tail(omega.template bottomRightCorner<T, T>());
    if (tail.info() != Eigen::Success) return std::nullopt;
    out -= omega.template topRightCorner<P, T>() * tail.solve(omega.template bottomLeftCorner<T, P>());
  }
  return symmetrized(out);
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::marginalize_robot() {
  const auto robot = cholesky_or_throw(info_.robot(), "robot block of the information matrix");
  std::vector<std::pair<std::size_t, Eigen::Matrix<double, X, M>>> links(info_.robot_links().begin(),
                                                                         info_.robot_links().end());
  std::sort(links.begin(), links.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Matrix<double, X, M>> solved;  // Omega_xx^-1 Omega_xi
  for (const auto& [slot, block] : links) solved.push_back(robot.solve(block));
  const Eigen::Matrix<double, X, 1> solved_r = robot.solve(info_.robot_residual());
  std::vector<std::size_t> slots;
  for (std::size_t a = 0; a < links.size(); ++a) {
    const auto& [i, L_i] = links[a];
    slots.push_back(i);
    info_.diagonal(i) = symmetrized((info_.diagonal(i) - L_i.transpose() * solved[a]).eval());
    info_.landmark_residual(i) -= L_i.transpose() * solved_r;
  }
  info_.add_to_links(slots, [&](std::size_t a, std::size_t b) { return -links[a].second.transpose() * solved[b]; });
  for (const auto& [slot, block] : links) info_.remove_robot_link(slot);
  info_.robot().setZero();
  info_.robot_residual().setZero();
}

/// ESEIF's sparsification (docs/derivations/seif_relocalization.md), after the other observations were
/// added: the robot marginalized out, a new one from the held-back observations alone, and the mean
/// recovered over it and every landmark the step touched (the landmarks just observed are passive
/// now: the thesis's active block would leave their means where they were).
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::relocalize(const std::vector<MeasurementInformation>& held_back,
                                          std::vector<std::size_t> observed) {
  std::vector<std::size_t> touched = active_queue_;
  touched.insert(touched.end(), observed.begin(), observed.end());
  marginalize_robot();
  if constexpr (kUnseenTail > 0)  // centred at the current mean: no residual
    info_.robot().template bottomRightCorner<kUnseenTail, kUnseenTail>() += tail_information_;
  for (const auto& info : held_back) {
    add(info);
    observed.insert(observed.begin(), info.slot);
  }
  update_active_queue(observed);
  if (exact_recovery_due()) {
    recover_mean_exactly_in_transaction();
    return require_factorizable_after_update(std::nullopt, std::nullopt);
  }
  std::vector<std::size_t> block = active_queue_;
  std::unordered_set<std::size_t> in_block(block.begin(), block.end());
  for (std::size_t slot : touched)
    if (in_block.insert(slot).second) block.push_back(slot);
  Eigen::VectorXd squared_pivots;
  for (int sweep = 0; sweep < std::max(options_.mean_recovery_sweeps, 1); ++sweep)
    squared_pivots = recover_mean_of_block(block, active_queue_.size(), false);
  recover_exactly_if_stale();
  require_factorizable_after_update(squared_pivots, std::nullopt);
}

/// The thesis's queue (§3.5.4): landmarks observed now first, then the previously active ones in
/// their previous order.
template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::update_active_queue(const std::vector<std::size_t>& observed_slots) {
  std::vector<std::size_t> queue;
  std::unordered_set<std::size_t> queued;
  auto push = [&](std::size_t slot) {
    if (info_.is_linked_to_robot(slot) && queued.insert(slot).second) queue.push_back(slot);
  };
  for (std::size_t slot : observed_slots) push(slot);
  for (std::size_t slot : active_queue_) push(slot);
  for (const auto& [slot, block] : info_.robot_links()) push(slot);
  active_queue_ = std::move(queue);
}

/// Thesis eqs. (37)-(44), Appendix A: the robot keeps its links to the first max_active landmarks of
/// the queue (m+) and loses those to the rest (m0); the change of Omega on B = (x, m+, m0) is
/// core/seif_sparsification.hpp's. The residual r is unchanged (eq. 44).
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::sparsify(bool active_block_gathered) -> std::optional<Eigen::Matrix<double, X, 1>> {
  if (options_.max_active == 0 || active_queue_.size() <= options_.max_active) return std::nullopt;
  if (options_.sparsification == SeifSparsification::relocalization) return std::nullopt;  // waits for relocalize()
  const std::vector<std::size_t>& R = active_queue_;
  const std::size_t kept = options_.max_active;
  const Eigen::Index n_R = M * static_cast<Eigen::Index>(R.size());
  const Eigen::Index n_dropped = n_R - M * static_cast<Eigen::Index>(kept);
  auto D = block_workspace_.view(X + n_R);  // Omega over (x, R), its lower triangle
  if (!active_block_gathered) {  // the rows of m0 are all it needs
    for (std::size_t a = 0; a < R.size(); ++a) gather_links_below(R, a, D, std::max(a + 1, kept));
    fill_robot_and_diagonal_blocks(R, D);
  }
  const Eigen::MatrixXd D_xR = D.block(X, 0, n_R, X).transpose();
  auto D_0R = D.block(X + n_R - n_dropped, X, n_dropped, n_R);  // rows of the landmarks to deactivate
  auto change_on_RR = factor_workspace_.view(n_R);
  const auto change = seif_sparsification_change<X>(info_.robot(), D_xR, D_0R, change_on_RR);
  info_.robot() = symmetrized(info_.robot() + change.robot);
  for (std::size_t a = 0; a < R.size(); ++a) {
    const std::size_t i = R[a];
    if (a < kept)
      info_.add_to_robot_link(i, change.robot_kept.template middleCols<M>(M * a));
    else
      info_.remove_robot_link(i);
    const Eigen::Matrix<double, M, M> change_ii =
        change_on_RR.template block<M, M>(M * a, M * a).template selfadjointView<Eigen::Upper>();
    info_.diagonal(i) = symmetrized(info_.diagonal(i) + change_ii);
  }
  info_.add_to_links(R, [&](std::size_t a, std::size_t b) {  // a < b: the upper triangle, all that is computed
    return change_on_RR.template block<M, M>(M * a, M * b);
  });
  active_queue_.resize(kept);
  return change.robot_squared_pivots;
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::add_landmark(const LandmarkEstimate<M>& known) {
  require_valid_known_landmark(known, landmarks_.contains(known.id));
  const Eigen::Matrix<double, M, M> information = inverse_from_cholesky(known.cov.llt());
  if (!information.allFinite())
    throw numerical_error("known landmark " + std::to_string(known.id) + ": its information (covariance inverse) is not finite");
  recovery_.follow([&](SeifSlam& candidate) { candidate.add_landmark(known); });  // checked above
  atomically([&] {
    const std::size_t slot = landmarks_.add(known.id, Landmark(known.mean));
    info_.append_landmark();
    info_.diagonal(slot) = information;
  });
}

template <class Motion, class Sensor>
void SeifSlam<Motion, Sensor>::remove_landmark(LandmarkId id) {
  const std::size_t slot = landmarks_.slot(id);
  info_.marginalize_landmark(slot);  // throws before changing anything
  const auto removal = landmarks_.remove(id);
  std::vector<std::size_t> queue;
  for (std::size_t s : active_queue_)
    if (s != removal.freed_slot) queue.push_back(s == removal.last_slot ? removal.freed_slot : s);
  active_queue_ = std::move(queue);
  update_active_queue({});
  touch();
  recovery_.follow([&](SeifSlam& candidate) { candidate.remove_landmark(id); });
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::factorization() const -> std::shared_ptr<const Factor> {
  return factor_.get(revision_, [&] {
    auto factor = std::make_shared<Factor>();
    factor->factorize(info_.to_sparse());  // throws numerical_error when Omega is not PD
    return std::shared_ptr<const Factor>(std::move(factor));
  });
}

template <class Motion, class Sensor>
std::shared_ptr<const Eigen::VectorXd> SeifSlam<Motion, Sensor>::estimate_correction() const {
  if (options_.estimate != SeifEstimate::exact_mean) return nullptr;
  return correction_.get(revision_, [&] {
    auto correction = std::make_shared<Eigen::VectorXd>(factorization()->solve(info_.residual()));
    if (!correction->allFinite()) throw numerical_error("SEIF exact mean is not finite");
    return std::shared_ptr<const Eigen::VectorXd>(std::move(correction));
  });
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::estimated_pose_mean() const -> State {
  const auto correction = estimate_correction();
  return correction ? Space::plus(x_, correction->template head<X>().eval()) : x_;
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::estimated_landmark_mean(std::size_t slot) const -> Landmark {
  const auto correction = estimate_correction();
  if (!correction) return landmark_mean(slot);
  return landmark_mean(slot) + correction->template segment<M>(offset_of(slot));
}

/// A diagonal block of Omega^-1 from `size` sparse solves.
template <class Motion, class Sensor>
Eigen::MatrixXd SeifSlam<Motion, Sensor>::marginal_covariance(Eigen::Index offset, Eigen::Index size) const {
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(state_dim(), size);
  unit.block(offset, 0, size, size).setIdentity();
  const Eigen::MatrixXd columns = factorization()->solve(unit);
  return symmetrized(columns.block(offset, 0, size, size));
}

/// Columns of Omega^-1 for the robot and the given landmark blocks (one multi-column solve), kept
/// at those rows: the joint marginal covariance.
template <class Motion, class Sensor>
Eigen::MatrixXd SeifSlam<Motion, Sensor>::joint_covariance(const std::vector<Eigen::Index>& offsets) const {
  const auto rows = joint_rows<X, M>(offsets);
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(state_dim(), n);
  for (Eigen::Index c = 0; c < n; ++c) unit(rows[c], c) = 1.0;
  const Eigen::MatrixXd columns = factorization()->solve(unit);
  Eigen::MatrixXd out(n, n);
  for (Eigen::Index r = 0; r < n; ++r) out.row(r) = columns.row(rows[r]);
  return symmetrized(out);
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::joint_marginal(std::span<const LandmarkId> ids) const -> JointMarginal<State, M> {
  JointMarginal<State, M> out{x_, {ids.begin(), ids.end()}, {}, {}};
  out.cov = joint_covariance(landmarks_.template gather<X>(ids, out.landmarks));
  return out;
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::conditional_joints(std::span<const LandmarkId> ids) const
    -> std::vector<Eigen::Matrix<double, X + M, X + M>> {
  using Block = Eigen::Matrix<double, X + M, X + M>;
  std::vector<Block> out;
  out.reserve(ids.size());
  for (const LandmarkId id : ids) {
    const std::size_t slot = landmarks_.slot(id);
    Block omega;
    omega.template topLeftCorner<X, X>() = info_.robot();
    omega.template topRightCorner<X, M>() = info_.robot_link(slot);
    omega.template bottomLeftCorner<M, X>() = info_.robot_link(slot).transpose();
    omega.template bottomRightCorner<M, M>() = info_.diagonal(slot);
    const Eigen::LLT<Block> llt(omega);
    if (llt.info() != Eigen::Success || !omega.allFinite())
      throw numerical_error("information block of the robot and landmark " + std::to_string(id) +
                            " is not positive definite");
    out.push_back(llt.solve(Block::Identity()));
  }
  return out;
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::pose() const -> PoseEstimate {
  return in_canonical_coordinates<Space>(PoseEstimate{estimated_pose_mean(), marginal_covariance(0, X)});
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::landmark(LandmarkId id) const -> LandmarkEstimate<M> {
  const std::size_t slot = landmarks_.slot(id);
  return {id, estimated_landmark_mean(slot), marginal_covariance(offset_of(slot), M)};
}

template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::map() const -> MapEstimate {
  MapEstimate out;
  out.reserve(landmarks_.size());
  constexpr std::size_t kChunk = 32;  // landmarks per multi-right-hand-side solve
  const auto factor = factorization();
  for (std::size_t first = 0; first < landmarks_.size(); first += kChunk) {
    const std::size_t count = std::min(kChunk, landmarks_.size() - first);
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(state_dim(), M * static_cast<Eigen::Index>(count));
    unit.block(offset_of(first), 0, unit.cols(), unit.cols()).setIdentity();
    const Eigen::MatrixXd columns = factor->solve(unit);
    for (std::size_t k = 0; k < count; ++k)
      out.push_back({landmarks_.id_at(first + k), estimated_landmark_mean(first + k),
                     symmetrized(columns.template block<M, M>(offset_of(first + k), M * k))});
  }
  return out;
}

template <class Motion, class Sensor>
std::vector<LandmarkId> SeifSlam<Motion, Sensor>::active_landmarks() const {
  std::vector<LandmarkId> out;
  for (std::size_t slot : active_queue_) out.push_back(landmarks_.id_at(slot));
  return out;
}

/// The update's rejected sightings as the re-acquisition test reads them: each with the robot's
/// mean, the landmark's and S = J_m P_m J_m^T + Q, P_m the landmark's marginal (one solve for all).
/// One the model cannot predict is left out.
template <class Motion, class Sensor>
auto SeifSlam<Motion, Sensor>::rejected_sightings(std::span<const ObservationType> observations,
                                                  const UpdateResult& result) const
    -> std::vector<typename Reacquisition::Sighting> {
  std::vector<const ObservationType*> rejected;
  std::vector<Eigen::Index> offsets;
  for (const auto& observation : observations)
    if (std::find(result.rejected.begin(), result.rejected.end(), observation.landmark_id) != result.rejected.end()) {
      rejected.push_back(&observation);
      offsets.push_back(offset_of(landmarks_.slot(observation.landmark_id)));
    }
  const Eigen::MatrixXd joint = joint_covariance(offsets);
  std::vector<typename Reacquisition::Sighting> out;
  for (std::size_t i = 0; i < rejected.size(); ++i) {
    const Eigen::Index at = X + M * static_cast<Eigen::Index>(i);
    const Eigen::Matrix<double, M, M> P_mm = symmetrized(Eigen::Matrix<double, M, M>(joint.template block<M, M>(at, at)));
    if (auto sighting = Reacquisition::sighting(sensor_, x_, landmark_mean(landmarks_.slot(rejected[i]->landmark_id)),
                                                *rejected[i], P_mm))
      out.push_back(std::move(*sighting));
  }
  return out;
}

}  // namespace sextant
