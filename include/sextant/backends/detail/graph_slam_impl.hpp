#pragma once
// Bodies of GraphSlam (see ../graph_slam.hpp).

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <string>
#include <utility>

#include "sextant/core/landmark_init.hpp"
#include "sextant/core/block_columns.hpp"
#include "sextant/core/block_sum.hpp"
#include "sextant/core/factor_information.hpp"
#include "sextant/core/linearized_observation.hpp"
#include "sextant/core/sparse_cholesky.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

/// The Gauss-Newton system at the current estimate, by blocks: Omega delta = b, b = -gradient
/// (thesis eqs. 58-64, Appendix B), over poses 0 .. pose_count - 1 and the landmarks they saw.
template <class Motion, class Sensor>
struct GraphSlam<Motion, Sensor>::Linearization {
  struct PoseLink {
    std::size_t a, b;  ///< a < b
    Eigen::Matrix<double, X, X> block;  ///< Omega_ab
  };
  struct LandmarkTerms {
    std::size_t slot;
    Eigen::Matrix<double, M, M> diagonal = Eigen::Matrix<double, M, M>::Zero();
    Eigen::Matrix<double, M, 1> rhs = Eigen::Matrix<double, M, 1>::Zero();
    std::vector<std::pair<std::size_t, Eigen::Matrix<double, X, M>>> poses;  ///< Omega_pj per observing pose
  };
  std::size_t pose_count = 0;
  std::vector<Eigen::Matrix<double, X, X>> pose_diagonal;
  std::vector<PoseLink> pose_links;
  Eigen::VectorXd pose_rhs;
  std::vector<LandmarkTerms> landmarks;
  double cost = 0.0;
  std::size_t unobservable = 0;  ///< measurement factors the model cannot evaluate here, left out

  Eigen::Index dim() const { return X * static_cast<Eigen::Index>(pose_count) + M * static_cast<Eigen::Index>(landmarks.size()); }

  /// The information matrix (poses, then landmarks in this system's order), written block column by
  /// block column (core/block_columns.hpp). `Triangle::both`: every block, as information_matrix()
  /// and the marginals need; `Triangle::lower`: the blocks on and below the diagonal, all a sparse
  /// Cholesky of the lower triangle reads (half the pose-landmark blocks, which are most of it).
  enum class Triangle { both, lower };
  Eigen::SparseMatrix<double> assemble(Triangle triangle = Triangle::both) const {
    const bool both = triangle == Triangle::both;
    const PoseColumns columns = pose_columns(both);
    std::vector<ColumnBlock> landmark_column;
    Eigen::Index nonzeros = 0;
    for (std::size_t p = 0; p < pose_count; ++p) nonzeros += BlockColumnWriter::entries(X, columns.of(p));
    for (const auto& terms : landmarks) nonzeros += BlockColumnWriter::entries(M, landmark_blocks(terms, both, landmark_column));
    BlockColumnWriter out(dim(), dim(), nonzeros);
    for (std::size_t p = 0; p < pose_count; ++p) out.write(X, columns.of(p));
    for (const auto& terms : landmarks) out.write(M, landmark_blocks(terms, both, landmark_column));
    return out.finish();
  }

 private:
  /// Each pose's block column: its pose rows (its diagonal block, its links; those at one pair in the
  /// order of pose_links) and below them the landmarks it saw, in this system's order.
  struct PoseColumns {
    std::vector<std::size_t> start;  ///< pose p's blocks are blocks[start[p], start[p + 1])
    std::vector<ColumnBlock> blocks;
    std::span<const ColumnBlock> of(std::size_t p) const { return {blocks.data() + start[p], blocks.data() + start[p + 1]}; }
  };
  PoseColumns pose_columns(bool both) const {
    PoseColumns out;
    std::vector<std::size_t> count(pose_count + 1, 0);  // blocks of pose p's column counted at p + 1
    for (std::size_t p = 0; p < pose_count; ++p) ++count[p + 1];
    for (const auto& link : pose_links) {
      ++count[link.a + 1];  // (b, a): below the diagonal
      if (both) ++count[link.b + 1];
    }
    for (const auto& terms : landmarks)
      for (const auto& pose_block : terms.poses) ++count[pose_block.first + 1];
    for (std::size_t p = 0; p < pose_count; ++p) count[p + 1] += count[p];
    out.start = count;
    out.blocks.resize(count[pose_count]);
    std::vector<std::size_t> next(count.begin(), count.end() - 1);
    const Eigen::Index base = X * static_cast<Eigen::Index>(pose_count);
    for (std::size_t p = 0; p < pose_count; ++p) out.blocks[next[p]++] = {X * static_cast<Eigen::Index>(p), X, pose_diagonal[p].data()};
    for (const auto& link : pose_links) {
      out.blocks[next[link.a]++] = {X * static_cast<Eigen::Index>(link.b), X, link.block.data(), true};
      if (both) out.blocks[next[link.b]++] = {X * static_cast<Eigen::Index>(link.a), X, link.block.data()};
    }
    for (std::size_t p = 0; p < pose_count; ++p)  // the pose rows by row, one pair's blocks in order
      std::stable_sort(out.blocks.begin() + out.start[p], out.blocks.begin() + next[p],
                       [](const ColumnBlock& l, const ColumnBlock& r) { return l.row < r.row; });
    for (std::size_t j = 0; j < landmarks.size(); ++j)
      for (const auto& [p, block] : landmarks[j].poses)
        out.blocks[next[p]++] = {base + M * static_cast<Eigen::Index>(j), M, block.data(), true};
    return out;
  }
  /// Landmark j's block column: the poses that saw it (by pose, one pose's blocks in order), then its
  /// diagonal block; only the diagonal block for the lower triangle.
  std::span<const ColumnBlock> landmark_blocks(const LandmarkTerms& terms, bool both, std::vector<ColumnBlock>& out) const {
    out.clear();
    if (both) {
      for (const auto& [p, block] : terms.poses) out.push_back({X * static_cast<Eigen::Index>(p), X, block.data()});
      std::stable_sort(out.begin(), out.end(), [](const ColumnBlock& l, const ColumnBlock& r) { return l.row < r.row; });
    }
    const Eigen::Index row = X * static_cast<Eigen::Index>(pose_count) + M * static_cast<Eigen::Index>(&terms - landmarks.data());
    out.push_back({row, M, terms.diagonal.data()});
    return out;
  }
};

/// The lowest-cost iterate of one gauss_newton() so far, by the cost Levenberg-Marquardt accepts its
/// steps by. (Ranking first by the factors an iterate leaves out, behind the camera, sent the
/// visual-inertial runs back to their start, where fewer points are behind the camera.) Its estimate
/// is copied only when it is offered and wins; a tie goes to the later iterate, so that under
/// Levenberg-Marquardt, which never moves to a higher cost, it is the iterate a rejected step returns to.
template <class Motion, class Sensor>
struct GraphSlam<Motion, Sensor>::BestIterate {
  int iteration = -1;
  double cost = 0.0;
  std::vector<State> poses;
  Eigen::VectorXd means;

  /// Whether the kept iterate is better than the one linearized in `sys` by more than `tolerance` of
  /// its cost (a rise within the tolerance that ends the iterations is rounding, not worth the
  /// linearization a restore costs: on the linear ship the second iteration's cost differs from the
  /// first's in its last bits).
  bool beats(const Linearization& sys, double tolerance) const {
    return iteration >= 0 && cost < sys.cost && sys.cost - cost > tolerance * cost;
  }
  void restore(std::vector<State>& estimate_poses, Eigen::VectorXd& estimate_means) const {
    estimate_poses = poses;
    estimate_means = means;
  }
  void offer(int at, const Linearization& sys, const std::vector<State>& estimate_poses, const Eigen::VectorXd& estimate_means) {
    if (iteration >= 0 && !(sys.cost <= cost)) return;
    iteration = at;
    cost = sys.cost;
    poses = estimate_poses;
    means = estimate_means;
  }
};

template <class Motion, class Sensor>
GraphSlam<Motion, Sensor>::GraphSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, GraphOptions options)
    : motion_(std::move(motion)), sensor_(std::move(sensor)), options_(options), prior_(prior), newest_cov_(prior.cov) {
  if (!Space::is_finite(prior.mean)) throw invalid_input_error("prior mean contains NaN or Inf");
  prior_information_ = inverse_of_spd_or_throw(prior.cov, "prior covariance");
  if (options_.max_iterations < 1 || options_.window_iterations < 1)
    throw invalid_input_error("GraphOptions: max_iterations and window_iterations must be >= 1");
  if (!(options_.relinearize_threshold > 0.0) || !std::isfinite(options_.relinearize_threshold))
    throw invalid_input_error("GraphOptions: relinearize_threshold must be positive and finite");
  options_.measurement_loss.validate();
  if (options_.lag > 0) options_.incremental = true;
  poses_.push_back(prior.mean);
  entry_sigma_.push_back(prior.cov.diagonal().cwiseSqrt());
}

template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::predict(const Control& u, double dt) {
  require_finite(u, "control");
  require_positive_time_step(dt);
  const auto prediction = checked_motion_prediction(motion_, poses_.back(), u, dt);
  if constexpr (!HasBetweenFactor<Motion>)  // the motion factor is weighted by R^-1
    cholesky_or_throw(prediction.R, "process noise R of step " + std::to_string(motions_.size()) +
                                        " (GraphSLAM weights the motion factor by R^-1)");
  const Eigen::Matrix<double, X, X> newest_cov =
      symmetrized(prediction.J_x_x * newest_cov_ * prediction.J_x_x.transpose() + prediction.R);
  if (!newest_cov.allFinite()) throw numerical_error("GraphSLAM: covariance of the new pose overflowed");
  require_factorizable_extension<X>(prior_.cov, prediction.J_x_x, prediction.R, "GraphSLAM: the new pose");
  motions_.push_back({u, dt});
  poses_.push_back(prediction.x);
  entry_sigma_.push_back(newest_cov.diagonal().cwiseMax(0.0).cwiseSqrt());
  newest_cov_ = newest_cov;
  touch();
}

template <class Motion, class Sensor>
UpdateResult GraphSlam<Motion, Sensor>::update(std::span<const ObservationType> observations) {
  require_valid_observations(observations);
  const auto [known, fresh] = split_known_and_new(landmarks_.pool(), observations);
  const std::size_t pose = poses_.size() - 1;
  // Linearize every new factor at the current estimate now, so that a factor no later
  // linearization could use (bad noise, an overflowing residual) is rejected where it enters
  // instead of making every later optimize(), map() and landmark() throw.
  // An observation the model cannot use at the current estimate (unobservable_error) is left out.
  UpdateResult result;
  std::vector<const ObservationType*> used;
  for (const auto& observation : known)
    if (linearize_if_observable(sensor_, poses_[pose], landmark_mean(landmarks_.slot(observation.landmark_id)),
                                observation.z, observation.landmark_id, 0, observation.noise_scale, result.unusable))
      used.push_back(&observation);
  std::vector<std::pair<const ObservationType*, LandmarkInit<M, X, Z>>> inits;
  for (const auto& observation : fresh) {
    auto init = initialize_if_observable(sensor_, poses_[pose], observation.z, observation.landmark_id,
                                         observation.noise_scale, result.unusable);
    if (!init || !linearize_if_observable(sensor_, poses_[pose], init->m, observation.z, observation.landmark_id, 0,
                                          observation.noise_scale, result.unusable))
      continue;
    require_factorizable_extension<M>(prior_.cov, init->J_m_x, symmetrized(init->J_m_z * init->Q * init->J_m_z.transpose()),
                                      "GraphSLAM: new landmark " + std::to_string(observation.landmark_id));
    inits.emplace_back(&observation, std::move(*init));
  }
  record_measurements(pose, used, inits);
  touch();
  result.corrected = used.size();
  result.initialized = inits.size();
  return result;
}

/// Records the frame's measurements (new landmarks at their inverse-model means); in online mode
/// also takes the online step, and forgets the records again if that throws.
template <class Motion, class Sensor>
template <class Inits>
void GraphSlam<Motion, Sensor>::record_measurements(std::size_t pose, const std::vector<const ObservationType*>& used,
                                                    const Inits& inits) {
  const std::size_t old_slots = landmarks_.size();
  std::vector<std::size_t> touched;
  for (const ObservationType* observation : used) {
    touched.push_back(landmarks_.slot(observation->landmark_id));
    measurements_[touched.back()].push_back({pose, observation->z, observation->noise_scale});
  }
  for (const auto& [observation, init] : inits) {
    touched.push_back(landmarks_.add(observation->landmark_id, init.m));
    measurements_.push_back({{pose, observation->z, observation->noise_scale}});
  }
  if (!options_.incremental) return;
  try {
    if (options_.lag > 0)
      step_lag(touched);
    else
      step_online(touched);
  } catch (...) {
    for (std::size_t i = 0; i < used.size(); ++i) measurements_[touched[i]].pop_back();
    measurements_.resize(old_slots);
    landmarks_.truncate(old_slots);
    touch();
    throw;
  }
}

/// The model's prediction, or nothing where it cannot predict (unobservable_error).
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::predict_if_observable(const State& x, const Landmark& m) const
    -> std::optional<decltype(std::declval<const Sensor&>().predict(x, m))> {
  try {
    return sensor_.predict(x, m);
  } catch (const unobservable_error&) {
    return std::nullopt;
  }
}

/// A new variable y = J x + v, v ~ N(0, C), tied to the newest pose x (a pose by a motion factor,
/// a landmark by its first measurement). The graph's only absolute information is the prior
/// N(mu_0, P) (a relative factor cannot lift the gauge), so x is never known better than P
/// carried along, and the system map() and optimize() factorize is at least as ill-conditioned as
/// the joint covariance [P, P J^T; J P, J P J^T + C] of x and y. If that is numerically singular
/// (sigma 1e-100 against a 1e-2 prior, a landmark at 1e150 m, a step of 1e100) so is the system:
/// the variable is rejected here instead of making every later map() and optimize() throw. The
/// joint's Schur complement of P is C, so a singular C (exact odometry) makes it singular: the
/// message then names C, which a factor weighs by its inverse.
template <class Motion, class Sensor>
template <int D>
void GraphSlam<Motion, Sensor>::require_factorizable_extension(const Eigen::Matrix<double, X, X>& P,
                                                               const Eigen::Matrix<double, D, X>& J,
                                                               const Eigen::Matrix<double, D, D>& C,
                                                               const std::string& what) {
  Eigen::Matrix<double, X + D, X + D> joint;
  joint.template topLeftCorner<X, X>() = P;
  joint.template bottomLeftCorner<D, X>() = J * P;
  joint.template topRightCorner<X, D>() = joint.template bottomLeftCorner<D, X>().transpose();
  joint.template bottomRightCorner<D, D>() = symmetrized(J * P * J.transpose() + C);
  try {
    require_well_conditioned(joint, what + ": its joint covariance with the newest pose");
  } catch (const numerical_error&) {
    require_well_conditioned(C, what + ": its noise covariance, whose inverse weighs its factor (exact motion or "
                                       "measurements need a small positive noise here)");
    throw;
  }
}

/// The motion factor between poses k and k + 1 at `from` and `to`: the model's own between() when
/// it has one, else r = minus(to, g(from, u)) with covariance R (thesis eqs. 60-61) and the Jacobians
/// of minus: J_to = D1, J_from = D2 G (D1 = I, D2 = -I in an additive chart; core/state_space.hpp).
template <class Motion, class Sensor>
BetweenFactor<GraphSlam<Motion, Sensor>::X> GraphSlam<Motion, Sensor>::motion_factor(std::size_t k, const State& from,
                                                                                      const State& to) const {
  if constexpr (HasBetweenFactor<Motion>) {
    return motion_.between(from, to, motions_[k].u, motions_[k].dt);
  } else {
    const auto prediction = motion_.predict(from, motions_[k].u, motions_[k].dt);
    return {Space::minus(to, prediction.x), minus_jacobian_second<Space>(to, prediction.x) * prediction.J_x_x,
            minus_jacobian_first<Space>(to, prediction.x), prediction.R};
  }
}

/// The motion factor's information over (from, to) (eqs. 60-61).
template <class Motion, class Sensor>
FactorInformation<GraphSlam<Motion, Sensor>::X, GraphSlam<Motion, Sensor>::X> GraphSlam<Motion, Sensor>::motion_information(
    std::size_t k, const State& from, const State& to) const {
  const BetweenFactor<X> factor = motion_factor(k, from, to);
  const GaussianNoise<X> noise(factor.cov, "process noise of step " + std::to_string(k));
  return noise.information(factor.J_from, factor.J_to, (-factor.r).eval());
}

/// The normal equations at the current estimate, factor by factor (core/factor_information.hpp):
/// Omega += J^T W J, b += J^T W nu, cost += rho(nu^T C^-1 nu) for the prior (eq. 64), the motion
/// factors (eqs. 60-61), the factors of marginalized landmarks and the measurements (eqs. 62-63).
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::linearize(std::size_t pose_count) const -> Linearization {
  Linearization sys;
  sys.pose_count = pose_count;
  sys.pose_diagonal.assign(pose_count, Eigen::Matrix<double, X, X>::Zero());
  sys.pose_rhs = Eigen::VectorXd::Zero(X * static_cast<Eigen::Index>(pose_count));
  add_prior_factor(sys);
  add_motion_factors(sys);
  add_marginal_factors(sys);
  add_measurement_factors(sys);
  if (!std::isfinite(sys.cost) || !sys.pose_rhs.allFinite()) throw numerical_error("GraphSLAM linearization is not finite");
  return sys;
}

/// The prior on the first pose at x0, r = minus(x0, mu_0) (eq. 64), its Jacobian D = d minus / d x0
/// (the identity in an additive chart, where the product below is skipped to keep every bit).
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::prior_information_at(const State& x0) const -> PriorInformation {
  const Eigen::Matrix<double, X, 1> r0 = Space::minus(x0, prior_.mean);
  const double cost = r0.dot(prior_information_ * r0);
  if constexpr (has_minus_jacobians_v<Space, State>) {
    const Eigen::Matrix<double, X, X> D = minus_jacobian_first<Space>(x0, prior_.mean);
    return {D.transpose() * prior_information_ * D, -(D.transpose() * (prior_information_ * r0)), cost};
  } else {
    return {prior_information_, -(prior_information_ * r0), cost};
  }
}

template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_prior_factor(Linearization& sys) const {
  const PriorInformation prior = prior_information_at(poses_[0]);
  sys.pose_diagonal[0] += prior.Lambda;
  sys.pose_rhs.template head<X>() += prior.g;
  sys.cost += prior.cost;
}

/// Each motion factor between poses k and k + 1: residual r, Jacobians J_from, J_to (eqs. 60-61).
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_motion_factors(Linearization& sys) const {
  for (std::size_t k = 0; k + 1 < sys.pose_count; ++k) {
    const auto info = motion_information(k, poses_[k], poses_[k + 1]);
    sys.pose_diagonal[k] += info.aa;
    sys.pose_diagonal[k + 1] += info.bb;
    sys.pose_links.push_back({k, k + 1, info.ab});
    sys.pose_rhs.template segment<X>(X * k) += info.a;
    sys.pose_rhs.template segment<X>(X * (k + 1)) += info.b;
    sys.cost += info.squared_norm;
  }
}

/// A linear factor that a marginalized landmark left on its poses (remove_landmark), relinearized by
/// the poses' moves since: g = eta - Lambda d, d = minus(x, linearization point), read in each
/// pose's tangent through D = d minus / d x (block-diagonal; the identity in an additive chart).
/// pose_at(p) gives the state of pose p to evaluate at.
template <class Motion, class Sensor>
template <class PoseAt>
auto GraphSlam<Motion, Sensor>::marginal_information(const LinearFactor& factor, PoseAt&& pose_at) const ->
    typename Online::PoseFactor {
  const std::size_t count = factor.poses.size();
  Eigen::VectorXd d(X * static_cast<Eigen::Index>(count));
  for (std::size_t i = 0; i < count; ++i)
    d.template segment<X>(X * i) = Space::minus(pose_at(factor.poses[i]), factor.linearization[i]);
  typename Online::PoseFactor out{Online::Source::marginal, 0, factor.poses, factor.Lambda, factor.eta - factor.Lambda * d,
                                  d.dot(factor.Lambda * d) - 2.0 * factor.eta.dot(d)};
  if constexpr (has_minus_jacobians_v<Space, State>) {
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(d.size(), d.size());
    for (std::size_t i = 0; i < count; ++i)
      D.template block<X, X>(X * i, X * i) = minus_jacobian_first<Space>(pose_at(factor.poses[i]), factor.linearization[i]);
    out.g = (D.transpose() * out.g).eval();
    out.Lambda = D.transpose() * factor.Lambda * D;
  }
  return out;
}

template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_marginal_factors(Linearization& sys) const {
  for (const auto& factor : linear_factors_) {
    if (*std::max_element(factor.poses.begin(), factor.poses.end()) >= sys.pose_count) continue;
    const auto info = marginal_information(factor, [&](std::size_t p) -> const State& { return poses_[p]; });
    const std::size_t count = factor.poses.size();
    for (std::size_t i = 0; i < count; ++i) {
      sys.pose_rhs.template segment<X>(X * factor.poses[i]) += info.g.template segment<X>(X * i);
      for (std::size_t k = 0; k < count; ++k) {
        const Eigen::Matrix<double, X, X> block = info.Lambda.template block<X, X>(X * i, X * k);
        if (factor.poses[i] == factor.poses[k])
          sys.pose_diagonal[factor.poses[i]] += block;
        else if (factor.poses[i] < factor.poses[k])
          sys.pose_links.push_back({factor.poses[i], factor.poses[k], block});
      }
    }
    sys.cost += info.cost;
  }
}

/// One measurement z of the landmark in `slot` at pose x and landmark m: innovation
/// nu = residual(z, h(x, m)), Jacobians J_z_x, J_z_m (eqs. 62-63), down-weighted by the measurement
/// loss; nothing where the model cannot predict it (e.g. an iterate put the landmark behind the camera).
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::measurement_information(std::size_t slot, const MeasurementRecord& record, const State& x,
                                                        const Landmark& m) const -> std::optional<FactorInformation<X, M>> {
  const auto prediction = predict_if_observable(x, m);
  if (!prediction) return std::nullopt;
  const GaussianNoise<Z> noise(with_noise_scale(*prediction, record.noise_scale).Q,
                               "measurement noise Q of landmark " + std::to_string(landmarks_.id_at(slot)));
  return noise.information(prediction->J_z_x, prediction->J_z_m, sensor_.residual(record.z, prediction->z),
                           options_.measurement_loss);
}

/// Each measurement of each landmark (eqs. 62-63); one the model cannot evaluate sits this one out.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::add_measurement_factors(Linearization& sys) const {
  sys.landmarks.reserve(measurements_.size());  // grown by doubling, both were fresh pages of every solve
  for (std::size_t slot = 0; slot < measurements_.size(); ++slot) {
    typename Linearization::LandmarkTerms terms;
    terms.slot = slot;
    terms.poses.reserve(measurements_[slot].size());
    for (const auto& record : measurements_[slot]) {
      if (record.pose >= sys.pose_count) continue;
      const auto info = measurement_information(slot, record, poses_[record.pose], landmark_mean(slot));
      if (!info) {
        ++sys.unobservable;
        continue;
      }
      sys.pose_diagonal[record.pose] += info->aa;
      sys.pose_rhs.template segment<X>(X * record.pose) += info->a;
      terms.diagonal += info->bb;
      terms.rhs += info->b;
      terms.poses.emplace_back(record.pose, info->ab);
      sys.cost += options_.measurement_loss.cost(info->squared_norm);
    }
    if (!terms.poses.empty()) sys.landmarks.push_back(std::move(terms));
  }
}

/// Thesis eqs. (66)-(69), (72)-(73): S = Omega_pp - sum_j Omega_pj Omega_jj^-1 Omega_jp,
/// b_S = b_p - sum_j Omega_pj Omega_jj^-1 b_j; S delta_p = b_S; delta_j = Omega_jj^-1 (b_j - Omega_jp delta_p).
template <class Motion, class Sensor>
Eigen::VectorXd GraphSlam<Motion, Sensor>::solve_by_landmark_schur(const Linearization& sys,
                                                                    OptimizationSummary& summary) const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  BlockSum<X> reduced;  // S, pose blocks (a, b)
  for (std::size_t p = 0; p < sys.pose_count; ++p) reduced.add(p, p, sys.pose_diagonal[p]);
  for (const auto& link : sys.pose_links) reduced.add_symmetric(link.a, link.b, link.block);
  Eigen::VectorXd b = sys.pose_rhs;
  std::vector<Eigen::LLT<Eigen::Matrix<double, M, M>>> factors;
  factors.reserve(sys.landmarks.size());
  for (const auto& terms : sys.landmarks) {
    factors.push_back(cholesky_or_throw(terms.diagonal, "information of landmark " + std::to_string(landmarks_.id_at(terms.slot))));
    const auto& llt = factors.back();
    std::vector<Eigen::Matrix<double, M, X>> solved;  // Omega_jj^-1 Omega_jp
    for (const auto& [p, block] : terms.poses) solved.push_back(llt.solve(block.transpose()));
    const Eigen::Matrix<double, M, 1> solved_rhs = llt.solve(terms.rhs);
    for (std::size_t a = 0; a < terms.poses.size(); ++a) {
      const auto& [p, block] = terms.poses[a];
      b.template segment<X>(X * p) -= block * solved_rhs;
      for (std::size_t c = 0; c < terms.poses.size(); ++c)
        reduced.add(p, terms.poses[c].first, Eigen::Matrix<double, X, X>(-(block * solved[c])));
    }
  }
  const Eigen::SparseMatrix<double> S = reduced.to_sparse(X * sys.pose_count, X * sys.pose_count);
  const auto eliminated = Clock::now();
  summary.seconds_eliminate += std::chrono::duration<double>(eliminated - start).count();

  solver_.factorize(S);
  const Eigen::VectorXd delta_poses = solver_.solve(b);
  const auto solved_at = Clock::now();
  summary.seconds_solve += std::chrono::duration<double>(solved_at - eliminated).count();

  Eigen::VectorXd delta(sys.dim());
  delta.head(delta_poses.size()) = delta_poses;
  for (std::size_t j = 0; j < sys.landmarks.size(); ++j) {
    Eigen::Matrix<double, M, 1> r = sys.landmarks[j].rhs;
    for (const auto& [p, block] : sys.landmarks[j].poses) r -= block.transpose() * delta_poses.template segment<X>(X * p);
    delta.template segment<M>(delta_poses.size() + M * j) = factors[j].solve(r);
  }
  summary.seconds_recover += std::chrono::duration<double>(Clock::now() - solved_at).count();
  return delta;
}

template <class Motion, class Sensor>
Eigen::VectorXd GraphSlam<Motion, Sensor>::solve_full(const Linearization& sys, OptimizationSummary& summary) const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const Eigen::SparseMatrix<double> A = sys.assemble(Linearization::Triangle::lower);
  Eigen::VectorXd b(sys.dim());
  b.head(sys.pose_rhs.size()) = sys.pose_rhs;
  for (std::size_t j = 0; j < sys.landmarks.size(); ++j) b.template segment<M>(sys.pose_rhs.size() + M * j) = sys.landmarks[j].rhs;
  const auto assembled = Clock::now();
  summary.seconds_eliminate += std::chrono::duration<double>(assembled - start).count();
  solver_.factorize(A);
  const Eigen::VectorXd delta = solver_.solve(b);
  summary.seconds_solve += std::chrono::duration<double>(Clock::now() - assembled).count();
  return delta;
}

template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::apply(const Linearization& sys, const Eigen::VectorXd& delta) {
  for (std::size_t p = 0; p < sys.pose_count; ++p) poses_[p] = Space::plus(poses_[p], delta.template segment<X>(X * p));
  const Eigen::Index base = X * static_cast<Eigen::Index>(sys.pose_count);
  for (std::size_t j = 0; j < sys.landmarks.size(); ++j)
    landmarks_.means().slot(sys.landmarks[j].slot) += delta.template segment<M>(base + M * j);
}

/// One step of the (damped) normal equations: lambda > 0 adds lambda diag(Omega) (Marquardt).
template <class Motion, class Sensor>
Eigen::VectorXd GraphSlam<Motion, Sensor>::solve(const Linearization& sys, double lambda,
                                                 OptimizationSummary& summary) const {
  const Linearization* system = &sys;
  Linearization damped;
  if (lambda > 0.0) {
    damped = sys;
    for (auto& block : damped.pose_diagonal) block.diagonal() *= 1.0 + lambda;
    for (auto& terms : damped.landmarks) terms.diagonal.diagonal() *= 1.0 + lambda;
    system = &damped;
  }
  return uses_landmark_schur(*system) ? solve_by_landmark_schur(*system, summary) : solve_full(*system, summary);
}

template <class Motion, class Sensor>
bool GraphSlam<Motion, Sensor>::uses_landmark_schur(const Linearization& sys) const {
  if (options_.solver == GraphSolver::automatic) return M * sys.landmarks.size() > X * sys.pose_count;
  return options_.solver == GraphSolver::landmark_schur;
}

/// The marginal covariance of the newest pose at the linearization `sys`: X solves with the
/// Cholesky factor of the information matrix (or of its Schur complement on the poses, whose
/// inverse is the poses' marginal covariance). One numeric factorization, no selected inversion.
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::newest_pose_marginal(const Linearization& sys) -> Eigen::Matrix<double, X, X> {
  OptimizationSummary ignored;
  solve(sys, 0.0, ignored);  // factorizes the undamped system
  const Eigen::Index dim = uses_landmark_schur(sys) ? X * static_cast<Eigen::Index>(sys.pose_count) : sys.dim();
  const Eigen::Index at = X * static_cast<Eigen::Index>(sys.pose_count - 1);
  Eigen::Matrix<double, X, X> out;
  for (int i = 0; i < X; ++i) {
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(dim);
    unit(at + i) = 1.0;
    out.col(i) = solver_.solve(unit).template segment<X>(at);
  }
  out = symmetrized(out);
  if (!out.allFinite()) throw numerical_error("GraphSLAM: marginal covariance of the newest pose is not finite");
  return out;
}

/// Gauss-Newton (or Levenberg-Marquardt) until the step or the relative change of chi2 is small.
/// Plain Gauss-Newton does not descend monotonically (a far start, a robust kernel's reweighting):
/// with `damp_after_rise` the first iteration that ends on a higher cost is undone and the steps go on
/// damped from the iterate before it, the lowest so far; without it, where an iteration ends on a
/// higher cost than an earlier one, the estimate returned is the best iterate's, not the last one's
/// (`BestIterate`).
template <class Motion, class Sensor>
OptimizationSummary GraphSlam<Motion, Sensor>::gauss_newton(std::size_t pose_count, int max_iterations,
                                                            Linearization* final_system, bool damp_after_rise) {
  using Clock = std::chrono::steady_clock;
  OptimizationSummary summary;
  const auto began = Clock::now();
  auto record_cost = [&](double cost) {
    summary.cost.push_back(cost);
    summary.seconds.push_back(std::chrono::duration<double>(Clock::now() - began).count());
  };
  auto timed_linearize = [&] {
    const auto start = Clock::now();
    auto sys = linearize(pose_count);
    summary.seconds_linearize += std::chrono::duration<double>(Clock::now() - start).count();
    return sys;
  };
  Linearization sys = timed_linearize();
  record_cost(sys.cost);
  BestIterate best;
  double lambda = options_.levenberg_marquardt ? options_.initial_lambda : 0.0;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const Eigen::VectorXd delta = solve(sys, lambda, summary);
    if (!delta.allFinite()) throw numerical_error("GraphSLAM step is not finite");
    best.offer(summary.iterations, sys, poses_, landmarks_.means().stacked());
    apply(sys, delta);
    Linearization next = timed_linearize();
    ++summary.iterations;
    const bool rose = next.cost > sys.cost;
    if (lambda == 0.0 && damp_after_rise && summary.damped_from < 0 && best.beats(next, options_.relative_cost_tolerance)) {
      summary.damped_from = summary.iterations;  // Gauss-Newton rose past rounding: undone below, damped from here
      lambda = options_.initial_lambda / 10.0;
    }
    if (lambda > 0.0 && rose) {  // rejected: back to where we were (the best iterate), damp more
      best.restore(poses_, landmarks_.means().stacked());
      lambda *= 10.0;
      record_cost(sys.cost);
      continue;
    }
    if (lambda > 0.0) lambda = std::max(lambda / 10.0, 1e-12);
    record_cost(next.cost);
    const double previous = sys.cost;
    sys = std::move(next);
    const double step = delta.size() ? delta.cwiseAbs().maxCoeff() : 0.0;
    if (step < options_.step_tolerance ||
        std::abs(previous - sys.cost) <= options_.relative_cost_tolerance * std::max(previous, 1e-300)) {
      summary.converged = true;
      break;
    }
  }
  summary.best_iteration = summary.iterations;
  if (best.beats(sys, options_.relative_cost_tolerance)) {
    best.restore(poses_, landmarks_.means().stacked());
    sys = timed_linearize();
    summary.best_iteration = best.iteration;
  }
  summary.unobservable_factors = sys.unobservable;
  if (final_system) *final_system = std::move(sys);
  return summary;
}

/// Poses after pose_count - 1 again by dead reckoning, and landmarks first seen there again by
/// the inverse model, so that the next sub-part starts from the optimized one.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::reinitialize_after(std::size_t pose_count) {
  for (std::size_t k = pose_count - 1; k + 1 < poses_.size(); ++k)
    poses_[k + 1] = motion_.predict(poses_[k], motions_[k].u, motions_[k].dt).x;
  for (std::size_t slot = 0; slot < measurements_.size(); ++slot) {
    const auto& first = measurements_[slot].front();
    if (first.pose >= pose_count)
      landmarks_.means().slot(slot) = initialize_landmark(sensor_, poses_[first.pose], first.z, landmarks_.id_at(slot), first.noise_scale).m;
  }
}

/// The thesis's initialization (§4.2.2): optimize the growing graph up to every `window`-th pose a
/// few times before the whole graph.
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::initialize_in_windows() {
  for (std::size_t end = options_.window; end + 1 < poses_.size(); end += options_.window) {
    gauss_newton(end + 1, options_.window_iterations);
    reinitialize_after(end + 1);
  }
  windows_done_ = true;
}

template <class Motion, class Sensor>
OptimizationSummary GraphSlam<Motion, Sensor>::optimize() {
  try {
    RollbackGuard guard(poses_, landmarks_.means(), windows_done_);
    if (options_.window > 0 && !windows_done_) initialize_in_windows();
    Linearization final_system;
    OptimizationSummary summary = gauss_newton(poses_.size(), options_.max_iterations, &final_system, options_.damp_after_rise);
    newest_cov_ = newest_pose_marginal(final_system);
    guard.commit();
    restart_online();  // the next update() linearizes the online system at the optimum
    touch();
    return summary;
  } catch (...) {
    touch();  // after the guard's restore: a new version, never an old one
    throw;
  }
}

template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::warm_start(std::span<const State> poses, const MapEstimate& map) {
  if (poses.size() != poses_.size())
    throw invalid_input_error("warm_start: " + std::to_string(poses.size()) + " poses given, the graph has " +
                              std::to_string(poses_.size()));
  for (const auto& pose : poses)
    if (!Space::is_finite(pose)) throw invalid_input_error("warm_start: a pose contains NaN or Inf");
  Eigen::VectorXd means = landmarks_.means().stacked();
  std::vector<bool> given(measurements_.size(), false);
  for (const auto& landmark : map) {
    const std::size_t slot = landmarks_.slot(landmark.id);
    means.template segment<M>(M * slot) = landmark.mean;
    given[slot] = true;
  }
  if (!means.allFinite()) throw invalid_input_error("warm_start: a landmark contains NaN or Inf");
  std::vector<LandmarkId> unplaceable;  // from the new pose: those keep their means
  for (std::size_t slot = 0; slot < measurements_.size(); ++slot) {
    if (given[slot]) continue;
    const auto& first = measurements_[slot].front();
    if (const auto init = initialize_if_observable(sensor_, poses[first.pose], first.z, landmarks_.id_at(slot),
                                                   first.noise_scale, unplaceable))
      means.template segment<M>(M * slot) = init->m;
  }
  poses_.assign(poses.begin(), poses.end());
  landmarks_.means().stacked() = means;
  windows_done_ = true;
  restart_online();
  touch();
}

/// The linear factor a landmark leaves on its poses when it is eliminated (thesis Appendix C), from
/// its measurement terms (Omega_pp, Omega_pj, b_p per measurement), H = Omega_jj factored and b_j:
/// Lambda = A_PP - A_Pj H^-1 A_jP, eta = b_P - A_Pj H^-1 b_j over its poses in increasing order,
/// linearized at pose_at(p).
template <class Motion, class Sensor>
template <class PoseAt>
auto GraphSlam<Motion, Sensor>::eliminated_landmark_factor(const std::vector<typename Online::Term>& terms,
                                                           const Eigen::LLT<Eigen::Matrix<double, M, M>>& H,
                                                           const Landmark& b_j, PoseAt&& pose_at) const -> LinearFactor {
  LinearFactor factor;
  for (const auto& t : terms) factor.poses.push_back(t.pose);
  std::sort(factor.poses.begin(), factor.poses.end());
  factor.poses.erase(std::unique(factor.poses.begin(), factor.poses.end()), factor.poses.end());
  const Eigen::Index n = X * static_cast<Eigen::Index>(factor.poses.size());
  Eigen::MatrixXd A_PP = Eigen::MatrixXd::Zero(n, n), A_Pj = Eigen::MatrixXd::Zero(n, M);
  Eigen::VectorXd b_P = Eigen::VectorXd::Zero(n);
  for (const auto& t : terms) {
    const Eigen::Index at = X * (std::lower_bound(factor.poses.begin(), factor.poses.end(), t.pose) - factor.poses.begin());
    A_PP.template block<X, X>(at, at) += t.aa;
    A_Pj.template middleRows<X>(at) += t.ab;
    b_P.template segment<X>(at) += t.a;
  }
  for (std::size_t p : factor.poses) factor.linearization.push_back(pose_at(p));
  factor.Lambda = symmetrized(A_PP - A_Pj * H.solve(A_Pj.transpose()));
  factor.eta = b_P - A_Pj * H.solve(b_j);
  return factor;
}

/// Marginalization of a landmark at the current estimate (every measurement, no robust weight).
template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::marginal_factor(std::size_t slot) const -> LinearFactor {
  const LandmarkId id = landmarks_.id_at(slot);
  std::vector<typename Online::Term> terms;
  Eigen::Matrix<double, M, M> A_jj = Eigen::Matrix<double, M, M>::Zero();
  Eigen::Matrix<double, M, 1> b_j = Eigen::Matrix<double, M, 1>::Zero();
  for (const auto& record : measurements_[slot]) {
    const auto prediction = with_noise_scale(sensor_.predict(poses_[record.pose], landmark_mean(slot)), record.noise_scale);
    const GaussianNoise<Z> noise(prediction.Q, "measurement noise Q of landmark " + std::to_string(id));
    const auto info = noise.information(prediction.J_z_x, prediction.J_z_m, sensor_.residual(record.z, prediction.z));
    terms.push_back({record.pose, info.aa, info.ab, info.a});
    A_jj += info.bb;
    b_j += info.b;
  }
  const auto llt = cholesky_or_throw(A_jj, "information of landmark " + std::to_string(id));
  return eliminated_landmark_factor(terms, llt, b_j, [&](std::size_t p) -> const State& { return poses_[p]; });
}

/// In online mode the landmark's factor is its contribution to the reduced system at the
/// linearization points, which stays in S as a factor on its poses (no refactorization).
template <class Motion, class Sensor>
void GraphSlam<Motion, Sensor>::remove_landmark(LandmarkId id) {
  const std::size_t slot = landmarks_.slot(id);
  const bool online = options_.incremental && options_.lag == 0 && !online_.theta.empty();
  std::optional<Lag> lag;
  if (options_.lag > 0) lag = lag_without(slot, lag_scratch_.marginalization);
  std::optional<LinearFactor> factor;
  std::optional<typename Online::PoseFactor> held;  // online: the factor's blocks of S
  if (!online) {
    factor = marginal_factor(slot);
  } else if (!online_.landmarks[slot].terms.empty()) {
    const auto& lin = online_.landmarks[slot];
    factor = eliminated_landmark_factor(lin.terms, lin.H, lin.b, [&](std::size_t p) -> const State& { return online_.theta[p]; });
    held = marginal_information(*factor, [&](std::size_t p) -> const State& { return online_.theta[p]; });
    held->index = linear_factors_.size();
  }
  if (factor) linear_factors_.push_back(std::move(*factor));
  if (online) remove_landmark_online(slot, std::move(held));
  if (lag) lag_ = std::move(*lag);
  const auto removal = landmarks_.remove(id);
  measurements_[removal.freed_slot] = std::move(measurements_[removal.last_slot]);
  measurements_.pop_back();
  touch();
}

template <class Motion, class Sensor>
std::shared_ptr<const SelectedInverse> GraphSlam<Motion, Sensor>::marginals() const {
  return marginals_.get(revision_, [&] { return std::make_shared<const SelectedInverse>(linearize(poses_.size()).assemble()); });
}

template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::trajectory() const -> std::vector<PoseEstimate> {
  const auto marginals = this->marginals();
  std::vector<PoseEstimate> out;
  out.reserve(poses_.size());
  for (std::size_t p = 0; p < poses_.size(); ++p)
    out.push_back(in_canonical_coordinates<Space>(PoseEstimate{poses_[p], marginals->block(X * p, X)}));
  return out;
}

template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::landmark(LandmarkId id) const -> LandmarkEstimate<M> {
  const std::size_t slot = landmarks_.slot(id);
  const Eigen::Index at = X * static_cast<Eigen::Index>(poses_.size()) + M * static_cast<Eigen::Index>(slot);
  return {id, landmark_mean(slot), marginals()->block(at, M)};
}

template <class Motion, class Sensor>
auto GraphSlam<Motion, Sensor>::map() const -> MapEstimate {
  MapEstimate out;
  for (LandmarkId id : landmarks_.ids()) out.push_back(landmark(id));
  return out;
}

template <class Motion, class Sensor>
double GraphSlam<Motion, Sensor>::cost() const {
  return linearize(poses_.size()).cost;
}

template <class Motion, class Sensor>
Eigen::SparseMatrix<double> GraphSlam<Motion, Sensor>::information_matrix() const {
  return linearize(poses_.size()).assemble();
}

}  // namespace sextant
