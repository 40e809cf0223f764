#pragma once
// Bodies of FastSlam (see ../fast_slam.hpp).

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "sextant/core/gaussian_mixture.hpp"
#include "sextant/core/iterate_settled.hpp"
#include "sextant/core/landmark_init.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

template <class Motion, class Sensor, template <class> class Map>
FastSlam<Motion, Sensor, Map>::FastSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, FastSlamOptions options)
    : motion_(std::move(motion)),
      sensor_(std::move(sensor)),
      options_(options),
      next_unassociated_id_(options.first_unassociated_id),
      rng_(options.seed) {
  if (options_.particles == 0) throw invalid_input_error("FastSlamOptions: particles must be > 0");
  if (options_.iterations < 1)
    throw invalid_input_error("FastSlamOptions: iterations must be at least 1 (got " + std::to_string(options_.iterations) + ")");
  if (!(options_.resample_threshold >= 0.0 && options_.resample_threshold <= 1.0))
    throw invalid_input_error("FastSlamOptions: resample_threshold must be in [0, 1]");
  if (!Space::is_finite(prior.mean)) throw invalid_input_error("prior mean contains NaN or Inf");
  cholesky_or_throw(prior.cov, "prior covariance");
  if (options_.new_landmark_nis == 0.0) options_.new_landmark_nis = chi_square_quantile(Z, 0.9999);
  if (!(options_.new_landmark_nis > 0.0) || !std::isfinite(options_.new_landmark_nis))
    throw invalid_input_error("FastSlamOptions: new_landmark_nis must be positive and finite (0: the default)");
  gate_ = InnovationGate(Z, options_.gate_probability);
  noise_tails_ = StudentTNoise{options_.student_t_dof};
  noise_tails_.validate("FastSlamOptions: student_t_dof");
  particles_.resize(options_.particles);
  const PoseMatrix tail = kept_tail(prior.cov);
  for (std::size_t n = 0; n < particles_.size(); ++n) {
    particles_[n].x = prior.mean;  // see predict_without_map
    particles_[n].cov = tail;
    particles_[n].forget_proposal();
    particles_[n].ancestor = n;
    if (options_.keep_paths) particles_[n].path.push_back({prior.mean, tail});
  }
  frame_cov_ = prior.cov - tail;
}

/// The sampled entries from the Gaussian, the tail at its conditional mean with its conditional
/// covariance (core/conditionally_linear.hpp; without a tail a plain draw, callers having checked
/// that the covariance is positive semi-definite up to rounding).
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::draw_into(Particle& particle, const PoseEstimate& gaussian,
                                              std::mt19937_64& rng) const {
  auto draw = keeps_tail() ? draw_lead_keep_tail<Space, T>(gaussian.mean, gaussian.cov, rng)
                           : draw_lead_keep_tail<Space, 0>(gaussian.mean, gaussian.cov, rng);
  particle.x = std::move(draw.x);
  particle.cov = std::move(draw.cov);
}

template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::kept_tail(const PoseMatrix& cov) const -> PoseMatrix {
  return keeps_tail() ? conditional_tail_covariance<T>(cov) : PoseMatrix::Zero().eval();
}

/// The motion of a particle whose tail is Gaussian: exact, since g is linear in the tail once the
/// sampled entries are fixed and R does not depend on it (Schoen et al. 2005, eqs. 9-10).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::motion_gaussian(const State& x, const PoseMatrix& cov, const Control& u,
                                                    double dt) const -> PoseEstimate {
  auto p = checked_motion_prediction(motion_, x, u, dt);
  if (!keeps_tail()) return {std::move(p.x), std::move(p.R)};  // cov is zero
  return {std::move(p.x), symmetrized((p.J_x_x * cov * p.J_x_x.transpose() + p.R).eval())};
}


template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::commit(Transaction&& t) {
  particles_ = std::move(t.particles);
  rng_ = t.rng;
  estimate_ = std::move(t.estimate);
  support_ = t.support;
  pending_ = std::move(t.pending);
  next_unassociated_id_ = t.next_unassociated_id;
  if (t.resampled) ++resamplings_;
  frame_cov_ = t.frame_cov;
  frame_fixed_ = t.frame_fixed;
  best_ = t.best;
}

template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::extend_paths(Transaction& t, const std::vector<PoseEstimate>& components) const {
  if (!options_.keep_paths) return;
  for (std::size_t i = 0; i < t.particles.size(); ++i) t.particles[i].path.push_back(components[i]);
}

template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::settle_paths(Transaction& t) const {
  if (!options_.keep_paths) return;
  for (auto& particle : t.particles) particle.path.replace_back({particle.drawn_from, particle.drawn_cov});
}

/// Dead reckoning of the common pose and of its covariance, Sigma <- G Sigma G^T + R, split into the
/// frame's part and the particles' conditionally linear tail (which stays theirs: no rigid motion).
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::predict_without_map(const Control& u, double dt) {
  Transaction t = begin();
  const Particle& common = t.particles.front();
  const auto p = checked_motion_prediction(motion_, common.x, u, dt);
  const PoseMatrix total = symmetrized(p.J_x_x * (t.frame_cov + common.cov) * p.J_x_x.transpose() + p.R);
  if (!total.allFinite()) throw numerical_error("FastSLAM dead-reckoned frame covariance is not finite");
  const PoseMatrix tail = kept_tail(total);
  t.frame_cov = total - tail;
  for (auto& particle : t.particles) {
    particle.x = p.x;
    particle.cov = tail;
    particle.forget_proposal();
  }
  t.estimate = PoseEstimate{p.x, total};
  t.support = std::numeric_limits<double>::infinity();
  if (options_.keep_paths) extend_paths(t, pose_components(t.particles, t.pending));
  commit(std::move(t));
}

/// The frame is fixed by the first landmark any particle maps.
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::fix_frame_if_mapped(Transaction& t) const {
  for (const auto& particle : t.particles)
    if (particle.landmarks.size() > 0 || particle.unassociated.size() > 0) t.frame_fixed = true;
}

/// FastSLAM 1.0 samples now; 2.0 keeps the motion pending for update()'s proposal (a second predict
/// in a row samples the first one plainly). Either way every particle's motion is checked here
/// (pose_components), and so is the cloud's pose estimate (it overflows when the particles spread
/// over 1e154).
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::predict(const Control& u, double dt) {
  require_finite(u, "control");
  require_positive_time_step(dt);
  if (!frame_fixed_) return predict_without_map(u, dt);
  Transaction t = begin();
  t.estimate.reset();
  apply_pending_motion_v1(t);
  t.pending.push_back({u, dt});
  if (options_.version == FastSlamVersion::v1) apply_pending_motion_v1(t);
  const auto components = pose_components(t.particles, t.pending);
  t.estimate = cloud_estimate(t.particles, components);  // pose() after an accepted predict cannot throw
  t.support = point_support(t.particles, t.pending, t.frame_fixed);
  extend_paths(t, components);
  commit(std::move(t));
}

/// FastSLAM 1.0 (eq. 74): every particle samples x ~ N(g(x, u), R) for each pending motion (its
/// sampled entries; the tail given them).
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::apply_pending_motion_v1(Transaction& t) const {
  for (const auto& motion : t.pending)
    for (auto& particle : t.particles) {
      draw_into(particle, motion_gaussian(particle.x, particle.cov, motion.u, motion.dt), t.rng);
      particle.forget_proposal();
    }
  t.pending.clear();
}

/// The innovation's NIS against S, and with heavy-tailed noise (core/student_t.hpp) the factor c on
/// Q and the factor of S + (c - 1) Q; the log likelihood log t_nu(nu; 0, S), or log N(nu; 0, S)
/// (eqs. 79-81, 93) with S itself for Gaussian noise.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::weigh_innovation(const Eigen::Matrix<double, Z, Z>& S,
                                                     const Eigen::Matrix<double, Z, 1>& nu,
                                                     const Eigen::Matrix<double, Z, Z>& Q, const char* what) const
    -> WeighedInnovation {
  auto llt = cholesky_or_throw(S, what);
  const double nis = mahalanobis_squared(llt, nu);
  const double log_likelihood = noise_tails_.log_density_at_nis(llt, nis);
  const double c = noise_tails_.noise_factor(nis, Z);
  if (c != 1.0) llt = cholesky_or_throw(symmetrized((S + (c - 1.0) * Q).eval()), what);
  return {nis, c, std::move(llt), log_likelihood};
}

/// One landmark EKF update with the particle's pose (eqs. 75-78, Joseph form, the noise c Q of
/// weigh_innovation); returns the log likelihood, S = H_m Sigma_m H_m^T + Q (eqs. 79-81).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::update_landmark(Particle& particle, std::size_t index, const Measurement& z,
                                                    double noise_scale, bool unassociated) const -> LandmarkUpdate {
  auto& map = unassociated ? particle.unassociated : particle.landmarks;
  const LandmarkGaussian<M>& L = map[index];
  const auto prediction = predict_if_observable(particle.x, L.mean, noise_scale);
  if (!prediction) return {0.0, Outcome::unusable};
  const auto& pred = *prediction;
  const Eigen::Matrix<double, Z, 1> nu = sensor_.residual(z, pred.z);
  const Eigen::Matrix<double, Z, Z> S = symmetrized(pred.J_z_m * L.cov * pred.J_z_m.transpose() + pred.Q);
  const auto w = weigh_innovation(S, nu, pred.Q, "landmark innovation covariance");
  const Eigen::Matrix<double, M, Z> K = w.llt.solve(pred.J_z_m * L.cov).transpose();
  const Eigen::Matrix<double, M, M> I_KH = Eigen::Matrix<double, M, M>::Identity() - K * pred.J_z_m;
  LandmarkGaussian<M> updated{
      L.mean + K * nu,
      symmetrized(I_KH * L.cov * I_KH.transpose() + w.noise_factor * (K * pred.Q * K.transpose())), true, L.id};
  const double log_likelihood = w.log_likelihood;
  if (!updated.mean.allFinite() || !updated.cov.allFinite() || !std::isfinite(log_likelihood))
    throw numerical_error("landmark update is not finite");
  map.set(index, std::move(updated));
  return {log_likelihood, Outcome::used};
}

/// The model's prediction, or nothing where it cannot predict (unobservable_error: in this
/// particle the landmark is behind the camera). Such an observation neither shapes the particle
/// nor weighs on it: a Gaussian likelihood is not defined there.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::predict_if_observable(const State& x, const Landmark& m, double noise_scale) const
    -> std::optional<Prediction> {
  try {
    return with_noise_scale(sensor_.predict(x, m), noise_scale);
  } catch (const unobservable_error&) {
    return std::nullopt;
  }
}

/// FastSLAM 2.0 proposal (eqs. 82-92), in Kalman form so that R may be singular: starting from
/// N(g(x, u), R), each observation of a known landmark corrects the pose Gaussian with
/// S = H_x Sigma H_x^T + H_m Sigma_m H_m^T + Q; the weight gains log N(nu; 0, S) (eq. 93, chained
/// over the observations); the pose is then sampled from the result. An observation that fails the
/// gate does not shape the proposal and weighs as on the gate's edge; the result flags it. The
/// innovation is residual(z, h) - offset (offset: an iterated pass's relinearization, fold_proposal).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::proposal_innovation(Prediction prediction, const PoseMatrix& cov,
                                                        const LandmarkGaussian<M>& landmark, const Measurement& z,
                                                        const Eigen::Matrix<double, Z, 1>& offset) const
    -> ProposalInnovation {
  Eigen::Matrix<double, Z, 1> nu = sensor_.residual(z, prediction.z) - offset;
  auto weighed = weigh_innovation(proposal_covariance(prediction, cov, landmark), nu, prediction.Q, kProposalS);
  return {std::move(prediction), std::move(nu), std::move(weighed)};
}

/// S = H_x Sigma H_x^T + H_m Sigma_m H_m^T + Q of a measurement against the pose Gaussian (Sigma).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::proposal_covariance(const Prediction& prediction, const PoseMatrix& cov,
                                                        const LandmarkGaussian<M>& landmark) -> Eigen::Matrix<double, Z, Z> {
  return symmetrized(prediction.J_z_x * cov * prediction.J_z_x.transpose() +
                     prediction.J_z_m * landmark.cov * prediction.J_z_m.transpose() + prediction.Q);
}

/// One measurement folded into the Gaussian proposal of the pose (thesis eqs. 91-92): K = Sigma H_x^T S^-1,
/// mu = mu (+) K nu, Sigma = (I - K H_x) Sigma (S with the noise c Q, weigh_innovation). Returns its
/// factor of the weight (eq. 93).
template <class Motion, class Sensor, template <class> class Map>
double FastSlam<Motion, Sensor, Map>::fold_into_proposal(State& mean, PoseMatrix& cov, const ProposalInnovation& in) {
  const Eigen::Matrix<double, X, Z> K = in.weighed.llt.solve(in.prediction.J_z_x * cov).transpose();
  mean = Space::plus(mean, K * in.nu);
  cov = symmetrized((PoseMatrix::Identity() - K * in.prediction.J_z_x) * cov);
  return in.weighed.log_likelihood;
}

/// FastSLAM 2.0's Gaussian proposal of one particle's pose, folded from its motion prior and the
/// accepted observations of known landmarks (kept as Particle::drawn_from, drawn_cov); its weight
/// factor (eq. 93) is added to the particle. Nothing is drawn: the weight depends on the particle
/// before the draw, which is what lets update() resample first (draw_from_proposal). With
/// options().iterations > 1 the proposal is iterated as the iterated EKF's update is (Gauss-Newton
/// on the prior, the landmarks' priors and the measurements, the landmarks marginalized): each
/// further pass linearizes every measurement at the last pass's pose and at its landmark's mean given
/// that pose, until the pose moves by less than 1e-9 of the step; the weight is the last pass's.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::propose_v2(Particle& particle, const PoseEstimate& prior,
                                               std::span<const ObservationType> known,
                                               const std::vector<bool>& accepted) const -> std::vector<Outcome> {
  std::vector<Outcome> outcomes(known.size(), Outcome::used);
  std::vector<const LandmarkGaussian<M>*> landmarks;
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (!accepted[i]) outcomes[i] = Outcome::gated;
    landmarks.push_back(&particle.landmarks[index_.at(known[i].landmark_id)]);
  }
  const FoldedProposal proposal = iterated_proposal(particle.log_weight, prior, known, landmarks, outcomes);
  if (!std::isfinite(proposal.log_weight)) throw numerical_error("FastSLAM 2.0 proposal weight is not finite");
  particle.log_weight = proposal.log_weight;
  particle.drawn_from = proposal.mean;
  particle.drawn_cov = proposal.cov;
  return outcomes;
}

/// The proposal's first pass (fold_proposal), then options().iterations - 1 passes at most, each
/// linearized where the last one ended, until the pose moves by less than 1e-9 of the step.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::iterated_proposal(double log_weight, const PoseEstimate& prior,
                                                      std::span<const ObservationType> observations,
                                                      std::span<const LandmarkGaussian<M>* const> landmarks,
                                                      std::vector<Outcome>& outcomes) const -> FoldedProposal {
  FoldedProposal proposal = *fold_proposal(log_weight, prior, observations, landmarks, outcomes, nullptr);
  for (int pass = 1; pass < options_.iterations; ++pass) {
    auto next = fold_proposal(log_weight, prior, observations, landmarks, outcomes, &proposal.next);
    if (!next) break;  // a measurement the model cannot predict from the iterate ends the iterations
    const double moved = Space::minus(next->mean, proposal.mean).template lpNorm<Eigen::Infinity>();
    const double step = Space::minus(next->mean, prior.mean).template lpNorm<Eigen::Infinity>();
    proposal = std::move(*next);
    if (iterate_settled(moved, step)) break;
  }
  return proposal;
}

/// One pass of the proposal: the measurements whose outcome is `used` folded one by one into the
/// motion prior. The first pass (`at` null) is the textbook proposal: each measurement linearized at
/// the running mean and its landmark's mean (and marked unusable where the model cannot predict it).
/// A further pass linearizes measurement i at (at->x, at->m[i]) and refers its residual back to the
/// running mean mu and the landmark's mean m: nu = z - h(x_i, m_i) - H_x (mu - x_i) - H_m (m - m_i)
/// (nothing where the model cannot predict one). The weight starts from the particle's and gains each
/// one's log likelihood (weigh_innovation). With iterations asked for, the pass also gives the next
/// one's linearization.
/// Measurement i is known[i] of the landmark landmarks[i].
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::fold_proposal(double log_weight, const PoseEstimate& prior,
                                                  std::span<const ObservationType> known,
                                                  std::span<const LandmarkGaussian<M>* const> landmarks,
                                                  std::vector<Outcome>& outcomes,
                                                  const ProposalLinearization* at) const -> std::optional<FoldedProposal> {
  FoldedProposal out{prior.mean, prior.cov, log_weight, {}};
  std::vector<FoldedMeasurement> folded;  // kept for the next linearization
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (outcomes[i] != Outcome::used) continue;
    const LandmarkGaussian<M>& L = *landmarks[i];
    const State x_i = at ? at->x : out.mean;
    auto prediction = predict_if_observable(x_i, at ? at->m[i] : Landmark(L.mean), known[i].noise_scale);
    if (!prediction) {
      if (at) return std::nullopt;
      outcomes[i] = Outcome::unusable;
      continue;
    }
    const Eigen::Matrix<double, Z, 1> offset =
        at ? (prediction->J_z_x * Space::minus(out.mean, x_i) + prediction->J_z_m * (L.mean - at->m[i])).eval()
           : Eigen::Matrix<double, Z, 1>::Zero().eval();
    auto innovation = proposal_innovation(std::move(*prediction), out.cov, L, known[i].z, offset);
    out.log_weight += fold_into_proposal(out.mean, out.cov, innovation);
    if (options_.iterations > 1) folded.push_back({i, x_i, std::move(innovation)});
  }
  if (options_.iterations > 1) out.next = next_linearization(known, landmarks, out.mean, folded, at);
  return out;
}

/// Where the next pass linearizes: the pass's pose x, and each landmark at its mean given x under the
/// pass's linearization (in the linear-Gaussian joint of pose and landmarks, the landmark's posterior
/// mean is its conditional mean at the pose's): m + Sigma_m H_m^T R^-1 (nu - H_x (x - x_i)), with
/// R = H_m Sigma_m H_m^T + Q and nu the measurement's residual in the pass.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::next_linearization(std::span<const ObservationType> known,
                                                       std::span<const LandmarkGaussian<M>* const> landmarks,
                                                       const State& x, const std::vector<FoldedMeasurement>& folded,
                                                       const ProposalLinearization* at) const -> ProposalLinearization {
  ProposalLinearization next{x, std::vector<Landmark>(known.size())};
  for (const auto& [i, x_i, innovation] : folded) {
    const LandmarkGaussian<M>& L = *landmarks[i];
    const auto& p = innovation.prediction;
    Eigen::Matrix<double, Z, 1> nu = sensor_.residual(known[i].z, p.z) - p.J_z_x * Space::minus(x, x_i);
    if (at) nu -= p.J_z_m * (L.mean - at->m[i]);
    const auto R = cholesky_or_throw(
        symmetrized(p.J_z_m * L.cov * p.J_z_m.transpose() + innovation.weighed.noise_factor * p.Q),
        "landmark innovation covariance");
    next.m[i] = Landmark(L.mean + L.cov * p.J_z_m.transpose() * R.solve(nu));
  }
  return next;
}

/// A particle's pose drawn from its proposal, then each landmark its proposal used updated from the
/// drawn pose (eqs. 75-78); one that is behind the camera from there becomes unusable.
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::draw_from_proposal(Particle& particle, std::span<const ObservationType> known,
                                                       std::vector<Outcome>& outcomes, std::mt19937_64& rng) const {
  draw_into(particle, {particle.drawn_from, particle.drawn_cov}, rng);
  for (std::size_t i = 0; i < known.size(); ++i)
    if (outcomes[i] == Outcome::used &&
        update_landmark(particle, index_.at(known[i].landmark_id), known[i].z, known[i].noise_scale, false).outcome == Outcome::unusable)
      outcomes[i] = Outcome::unusable;
}

/// Each particle's pose before this step's measurements: its motion prior when a FastSLAM 2.0 motion
/// is pending (the proposal's start, computed once for the gate and the proposal), else its pose.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::pose_priors(const std::vector<Particle>& particles, const PendingMotion* motion) const
    -> std::vector<PoseEstimate> {
  std::vector<PoseEstimate> poses;
  poses.reserve(particles.size());
  for (const auto& particle : particles)
    poses.push_back(motion ? motion_gaussian(particle.x, particle.cov, motion->u, motion->dt)
                           : PoseEstimate{particle.x, particle.cov});
  return poses;
}

/// The gate on the cloud (docs/results/mrclam.md, "FastSLAM's gate on the cloud"): an observation
/// of a known landmark is an outlier when it is one for the filter's predictive distribution, the
/// weighted mixture over particles of N(h(x_n, m_n), S_n) with S_n = H_x C_n H_x^T + H_m Sigma_m H_m^T
/// + Q (C_n: the particle's pending motion, FastSLAM 2.0, or its tail), moment-matched: its NIS is
/// nu^T S^-1 nu with nu = sum w_n nu_n and S = sum w_n (S_n + (nu_n - nu)(nu_n - nu)^T). Every
/// particle then uses it or none does: a per-particle gate would let each particle ignore the
/// sightings that refute it, and a cloud that has drifted (a long gap) would never come back.
/// Particles that cannot predict it are left out; all true with the gate off.
template <class Motion, class Sensor, template <class> class Map>
std::vector<bool> FastSlam<Motion, Sensor, Map>::accepted_by_cloud(const std::vector<Particle>& particles,
                                                                   const std::vector<PoseEstimate>& poses,
                                                                   std::span<const ObservationType> known) const {
  std::vector<bool> accepted(known.size(), true);
  if (!gate_.on() || known.empty()) return accepted;
  const auto w = normalized_weights(particles);
  std::vector<Eigen::Matrix<double, Z, 1>> nus(particles.size());
  std::vector<Eigen::Matrix<double, Z, Z>> covs(particles.size());
  for (std::size_t i = 0; i < known.size(); ++i) {
    const std::size_t index = index_.at(known[i].landmark_id);
    std::vector<double> predicted_w(w.size(), 0.0);  // the weights of the particles that can predict it
    double total = 0.0;
    for (std::size_t n = 0; n < particles.size(); ++n) {
      const LandmarkGaussian<M>& L = particles[n].landmarks[index];
      const auto p = predict_if_observable(poses[n].mean, L.mean, known[i].noise_scale);
      if (!p) continue;
      nus[n] = sensor_.residual(known[i].z, p->z);
      covs[n] = p->J_z_x * poses[n].cov * p->J_z_x.transpose() + p->J_z_m * L.cov * p->J_z_m.transpose() + p->Q;
      predicted_w[n] = w[n];
      total += w[n];
    }
    if (!(total > 0.0)) continue;  // no particle can predict it: each says so itself
    for (double& v : predicted_w) v /= total;
    const auto innovation = mixture_moments<Z>(predicted_w, [&](std::size_t n) { return nus[n]; },
                                               [&](std::size_t n) { return covs[n]; });
    if (!innovation.mean.allFinite() || !innovation.cov.allFinite())
      throw numerical_error("FastSLAM: the cloud's innovation is not finite");
    accepted[i] = !gate_.rejects(cholesky_or_throw(symmetrized(innovation.cov), "the cloud's innovation covariance"),
                                 innovation.mean);
  }
  return accepted;
}

/// One particle's known landmarks without a proposal (FastSLAM 1.0, or 2.0 with no motion pending):
/// each landmark updated from the particle's pose and weighed (eq. 85).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::update_known_landmarks(Particle& particle, std::span<const ObservationType> known,
                                                           const std::vector<bool>& accepted) const
    -> std::vector<Outcome> {
  std::vector<Outcome> outcomes;
  particle.forget_proposal();
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (!accepted[i]) {
      outcomes.push_back(Outcome::gated);
      continue;
    }
    const auto result = update_landmark(particle, index_.at(known[i].landmark_id), known[i].z, known[i].noise_scale, false);
    particle.log_weight += result.log_likelihood;
    outcomes.push_back(result.outcome);
  }
  return outcomes;
}

/// Every step works on a copy of the particles (O(N) with shared maps) and of the random engine,
/// and commits at its very end: the strong guarantee, resampling included.
template <class Motion, class Sensor, template <class> class Map>
UpdateResult FastSlam<Motion, Sensor, Map>::update(std::span<const ObservationType> observations) {
  require_valid_observations(observations);
  const auto [known, fresh] = split_known_and_new(index_, observations);
  Transaction t = begin();
  const bool proposal = options_.version == FastSlamVersion::v2 && !t.pending.empty();
  // The priors feed the proposal and the gate on the cloud; FastSLAM 1.0 ungated needs neither.
  const std::vector<PoseEstimate> priors = proposal || gate_.on()
                                               ? pose_priors(t.particles, proposal ? &t.pending.back() : nullptr)
                                               : std::vector<PoseEstimate>{};
  const std::vector<bool> accepted = accepted_by_cloud(t.particles, priors, known);
  std::vector<std::vector<Outcome>> outcomes(t.particles.size());
  for (std::size_t n = 0; n < t.particles.size(); ++n)
    outcomes[n] = proposal ? propose_v2(t.particles[n], priors[n], known, accepted)
                           : update_known_landmarks(t.particles[n], known, accepted);
  t.pending.clear();
  const auto parents = normalize_and_resample(t);  // with the frame as the particles were drawn in (point_support)
  std::vector<Outcome> reported = outcomes[parents[t.best]];
  // FastSLAM 2.0's weight does not depend on the draw, so the cloud was resampled first and each
  // copy of a particle draws its own pose (the fully adapted order; Pitt and Shephard, JASA 1999).
  for (std::size_t n = 0; proposal && n < t.particles.size(); ++n) {
    std::vector<Outcome> drawn = outcomes[parents[n]];
    draw_from_proposal(t.particles[n], known, drawn, t.rng);
    if (n == t.best) reported = std::move(drawn);
  }
  UpdateResult result;
  const auto added = add_new_landmarks(t.particles, fresh, result.unusable);
  std::size_t known_unusable = 0;
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (reported[i] == Outcome::gated) result.rejected.push_back(known[i].landmark_id);
    if (reported[i] == Outcome::unusable) {
      result.unusable.push_back(known[i].landmark_id);
      ++known_unusable;
    }
  }
  result.corrected = known.size() - result.rejected.size() - known_unusable;
  result.initialized = added.size();
  fix_frame_if_mapped(t);
  auto index = index_;
  auto id_of_index = id_of_index_;
  for (const auto& observation : added) {
    index[observation.landmark_id] = id_of_index.size();
    id_of_index.push_back(observation.landmark_id);
  }
  settle_paths(t);
  commit(std::move(t));
  index_.swap(index);
  id_of_index_.swap(id_of_index);
  return result;
}

/// New landmarks from every particle's pose by the inverse model. One that the model cannot place
/// from some particle's pose (unobservable_error) is left out of every particle, so that all
/// particles hold the same ids; its id goes to `unusable`. Returns the observations added.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::add_new_landmarks(std::vector<Particle>& particles,
                                                      std::span<const ObservationType> fresh,
                                                      std::vector<LandmarkId>& unusable) const
    -> std::vector<ObservationType> {
  std::vector<ObservationType> added;
  std::vector<LandmarkGaussian<M>> per_particle;
  for (const auto& observation : fresh) {
    per_particle.clear();
    std::vector<LandmarkId> failed;
    for (const auto& particle : particles) {
      const auto init = initialize_if_observable(sensor_, particle.x, observation.z, observation.landmark_id,
                                                 observation.noise_scale, failed);
      if (!init) break;
      per_particle.push_back(
          {init->m, symmetrized(init->J_m_z * init->Q * init->J_m_z.transpose()), true, observation.landmark_id});
    }
    if (!failed.empty()) {
      unusable.push_back(observation.landmark_id);
      continue;
    }
    for (std::size_t n = 0; n < particles.size(); ++n) particles[n].landmarks.push_back(std::move(per_particle[n]));
    added.push_back(observation);
  }
  return added;
}

/// Thesis §7.2: per particle, each measurement goes to the landmark of that particle with the
/// largest likelihood, or starts a new one when even the best is beyond the new-landmark gate. With
/// FastSLAM 2.0 the association is decided inside the proposal, so the innovation covariance
/// includes the pose's motion uncertainty (S = H_x Sigma_x H_x^T + H_m Sigma_m H_m^T + Q), and the
/// pose is sampled after the associated measurements have shaped it. A landmark started from the
/// i-th measurement gets the id next_unassociated_id + i in every particle that starts it.
template <class Motion, class Sensor, template <class> class Map>
UpdateResult FastSlam<Motion, Sensor, Map>::update_unassociated(std::span<const Measurement> measurements,
                                                                std::vector<LandmarkId>* most_likely) {
  for (const auto& z : measurements) require_finite(z, "unassociated measurement");
  Transaction t = begin();
  const bool proposal = options_.version == FastSlamVersion::v2 && !t.pending.empty();
  std::vector<std::vector<std::size_t>> match(t.particles.size());
  for (std::size_t n = 0; n < t.particles.size(); ++n)
    match[n] = associate_and_propose(t.particles[n], measurements, proposal, t.pending);
  t.pending.clear();
  for (std::size_t n = 0; !proposal && n < t.particles.size(); ++n)  // weighed by the updates themselves
    map_unassociated(t.particles[n], measurements, match[n], false, t);
  const auto parents = normalize_and_resample(t);  // with the frame as the particles were drawn in (point_support)
  // The most likely particle given this step's measurements: each particle's weight held them
  // (FastSLAM 2.0's proposal factor, 1.0's updates), and new landmarks go to the end of its list.
  const auto& chosen = match[parents[t.best]];
  const auto initialized = static_cast<std::size_t>(std::count(chosen.begin(), chosen.end(), kNewLandmark));
  std::vector<LandmarkId> chosen_ids;  // only for a caller that asked
  for (std::size_t i = 0; most_likely && i < measurements.size(); ++i)
    chosen_ids.push_back(chosen[i] == kNewLandmark ? t.next_unassociated_id + i
                                                   : t.particles[t.best].unassociated[chosen[i]].id);
  for (std::size_t n = 0; proposal && n < t.particles.size(); ++n)  // each copy draws its own pose, as in update()
    map_unassociated(t.particles[n], measurements, match[parents[n]], true, t);
  t.next_unassociated_id += measurements.size();
  fix_frame_if_mapped(t);
  settle_paths(t);
  commit(std::move(t));
  if (most_likely) *most_likely = std::move(chosen_ids);
  return {measurements.size() - initialized, initialized, {}, {}};
}

/// Normalizes the log weights (log-sum-exp), keeps the weighted cloud as the pose estimate, and
/// resamples by the low-variance sampler (§3.7.4) when the effective sample size falls below the
/// threshold; t.best becomes the most likely particle (the first copy of it after a resampling).
/// Returns each particle's parent in the cloud before (itself when none was resampled).
template <class Motion, class Sensor, template <class> class Map>
std::vector<std::size_t> FastSlam<Motion, Sensor, Map>::normalize_and_resample(Transaction& t) const {
  auto& particles = t.particles;
  t.best = heaviest_particle(particles);
  const double max_log = particles[t.best].log_weight;
  if (!std::isfinite(max_log)) throw numerical_error("FastSLAM particle weights are not finite");
  double sum = 0.0;
  for (const auto& p : particles) sum += std::exp(p.log_weight - max_log);
  const double log_total = max_log + std::log(sum);
  for (auto& p : particles) p.log_weight -= log_total;
  t.estimate = cloud_estimate(particles, pose_components(particles, t.pending));
  t.support = point_support(particles, t.pending, t.frame_fixed);
  const double n = static_cast<double>(particles.size());
  const auto w = normalized_weights(particles);
  std::vector<std::size_t> parents(particles.size());
  std::iota(parents.begin(), parents.end(), std::size_t{0});
  if (effective_sample_size_of(w) >= options_.resample_threshold * n) return parents;
  std::vector<Particle> resampled;
  resampled.reserve(particles.size());
  const double step = 1.0 / n;
  double u = std::uniform_real_distribution<double>(0.0, step)(t.rng), cumulative = w[0];
  std::size_t i = 0;
  for (std::size_t m = 0; m < particles.size(); ++m, u += step) {
    while (u > cumulative && i + 1 < w.size()) cumulative += w[++i];
    resampled.push_back(particles[i]);  // O(1) map copy with PersistentArray
    resampled.back().log_weight = -std::log(n);
    parents[m] = i;
  }
  particles = std::move(resampled);
  t.resampled = true;
  // A particle of weight >= 1/n, as the largest is, keeps a copy under the low-variance sampler.
  t.best = static_cast<std::size_t>(std::find(parents.begin(), parents.end(), t.best) - parents.begin());
  return parents;
}

template <class Motion, class Sensor, template <class> class Map>
std::vector<double> FastSlam<Motion, Sensor, Map>::normalized_weights(const std::vector<Particle>& particles) {
  std::vector<double> w;
  w.reserve(particles.size());
  for (const auto& p : particles) w.push_back(std::exp(p.log_weight));
  const double sum = std::accumulate(w.begin(), w.end(), 0.0);
  for (double& v : w) v /= sum;
  return w;
}

template <class Motion, class Sensor, template <class> class Map>
std::vector<double> FastSlam<Motion, Sensor, Map>::weights() const {
  return normalized_weights(particles_);
}

template <class Motion, class Sensor, template <class> class Map>
double FastSlam<Motion, Sensor, Map>::effective_sample_size() const {
  return effective_sample_size_of(weights());
}

template <class Motion, class Sensor, template <class> class Map>
std::size_t FastSlam<Motion, Sensor, Map>::distinct_ancestors() const {
  std::vector<std::size_t> ancestors;
  for (const auto& particle : particles_) ancestors.push_back(particle.ancestor);
  std::sort(ancestors.begin(), ancestors.end());
  return static_cast<std::size_t>(std::unique(ancestors.begin(), ancestors.end()) - ancestors.begin());
}

/// N_eff = 1 / sum w_i^2 of normalized weights (§3.7.4).
template <class Motion, class Sensor, template <class> class Map>
double FastSlam<Motion, Sensor, Map>::effective_sample_size_of(const std::vector<double>& normalized) {
  double sum_sq = 0.0;
  for (double v : normalized) sum_sq += v * v;
  return 1.0 / sum_sq;
}

template <class Motion, class Sensor, template <class> class Map>
std::size_t FastSlam<Motion, Sensor, Map>::heaviest_particle(const std::vector<Particle>& particles) {
  return static_cast<std::size_t>(std::max_element(particles.begin(), particles.end(),
                                                   [](const auto& a, const auto& b) { return a.log_weight < b.log_weight; }) -
                                  particles.begin());
}

/// The weighted mixture of the particles' pose Gaussians, in the tangent space at the best particle,
/// given in the space's canonical coordinates (in_canonical_coordinates).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::pose() const -> PoseEstimate {
  if (estimate_) return in_canonical_coordinates<Space>(*estimate_);
  return in_canonical_coordinates<Space>(cloud_estimate(particles_, pose_components(particles_, pending_)));
}

template <class Motion, class Sensor, template <class> class Map>
double FastSlam<Motion, Sensor, Map>::pose_sample_support() const {
  return estimate_ ? support_ : point_support(particles_, pending_, frame_fixed_);
}

/// 1 / sum W_g^2 over the groups g of particles at one pose (W_g their summed weight), where every
/// pose component is a point in the sampled entries; otherwise +inf (see pose_sample_support()).
template <class Motion, class Sensor, template <class> class Map>
double FastSlam<Motion, Sensor, Map>::point_support(const std::vector<Particle>& cloud,
                                                    const std::vector<PendingMotion>& pending, bool frame_fixed) const {
  constexpr double kGaussians = std::numeric_limits<double>::infinity();
  const int sampled = keeps_tail() ? X - T : X;
  if (!frame_fixed || !pending.empty()) return kGaussians;
  for (const auto& particle : cloud)
    if (!particle.drawn_cov.topLeftCorner(sampled, sampled).isZero(0.0)) return kGaussians;
  const auto w = normalized_weights(cloud);
  std::vector<Eigen::Matrix<double, X, 1>> d;
  for (const auto& particle : cloud) d.push_back(Space::minus(particle.drawn_from, cloud.front().drawn_from));
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto before = [&](std::size_t a, std::size_t b) {
    return std::lexicographical_compare(d[a].data(), d[a].data() + X, d[b].data(), d[b].data() + X);
  };
  std::sort(order.begin(), order.end(), before);
  double sum_sq = 0.0, group = 0.0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    group += w[order[i]];
    if (i + 1 == order.size() || d[order[i + 1]] != d[order[i]]) {
      sum_sq += group * group;
      group = 0.0;
    }
  }
  return 1.0 / sum_sq;
}

/// One particle's pose Gaussian: after a predict of FastSLAM 2.0 (pending motions), its draw carried
/// through them, N(g(x, u), G Sigma G^T + R); otherwise the Gaussian it was drawn from.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::pose_component(const Particle& particle, const std::vector<PendingMotion>& pending) const
    -> PoseEstimate {
  if (pending.empty()) return {particle.drawn_from, particle.drawn_cov};
  PoseEstimate out{particle.x, particle.cov};
  for (const auto& motion : pending) {
    const auto p = checked_motion_prediction(motion_, out.mean, motion.u, motion.dt);
    out = {p.x, symmetrized(p.J_x_x * out.cov * p.J_x_x.transpose() + p.R)};
  }
  return out;
}

template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::pose_components(const std::vector<Particle>& cloud,
                                                    const std::vector<PendingMotion>& pending) const
    -> std::vector<PoseEstimate> {
  std::vector<PoseEstimate> components;
  components.reserve(cloud.size());
  for (const auto& particle : cloud) components.push_back(pose_component(particle, pending));
  return components;
}

template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::cloud_estimate(const std::vector<Particle>& cloud,
                                                   const std::vector<PoseEstimate>& components) const -> PoseEstimate {
  const auto w = normalized_weights(cloud);
  PoseEstimate out = mixture_in_frame(w, heaviest_particle(cloud), [&](std::size_t i) -> const PoseEstimate& {
    return components[i];
  });
  if (!Space::is_finite(out.mean) || !out.cov.allFinite()) throw numerical_error("FastSLAM cloud pose estimate is not finite");
  return out;
}

/// The mixture of the pose Gaussians component(i) weighed by w[i] (within plus between), moment-
/// matched in the tangent space at component(reference)'s mean, plus the frame's uncertainty.
template <class Motion, class Sensor, template <class> class Map>
template <class Component>
auto FastSlam<Motion, Sensor, Map>::mixture_in_frame(const std::vector<double>& w, std::size_t reference,
                                                     Component&& component) const -> PoseEstimate {
  const State at = component(reference).mean;
  std::vector<Eigen::Matrix<double, X, 1>> d;
  d.reserve(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) d.push_back(Space::minus(component(i).mean, at));
  const auto moments = mixture_moments<X>(w, [&](std::size_t i) { return d[i]; },
                                          [&](std::size_t i) { return component(i).cov; });
  return {Space::plus(at, moments.mean), symmetrized(moments.cov + frame_cov_)};
}

template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::path_posterior() const -> PathPosterior {
  if (!options_.keep_paths)
    throw invalid_input_error("FastSlam::path_posterior: the paths were not kept (FastSlamOptions::keep_paths)");
  using Path = ParticlePath<PoseEstimate>;
  std::vector<const Path*> paths;
  for (const auto& particle : particles_) paths.push_back(&particle.path);
  PathPosterior out;
  out.poses.resize(particles_.front().path.size());
  out.support.resize(out.poses.size());
  std::vector<double> w;
  const auto visit = [&](std::size_t j, std::span<const typename Path::WeightedPose> poses) {
    w.clear();
    std::size_t heaviest = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      w.push_back(poses[i].weight);
      if (poses[i].weight > poses[heaviest].weight) heaviest = i;
    }
    out.poses[j] = in_canonical_coordinates<Space>(
        mixture_in_frame(w, heaviest, [&](std::size_t i) -> const PoseEstimate& { return *poses[i].pose; }));
    out.support[j] = 1.0 / std::inner_product(w.begin(), w.end(), w.begin(), 0.0);
  };
  Path::walk_back(paths, normalized_weights(particles_), visit);
  return out;
}

/// A landmark that the most likely particle created by its own association, if it has `id`.
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::unassociated_landmark(LandmarkId id) const -> std::optional<LandmarkEstimate<M>> {
  const auto& map = particles_[best_particle()].unassociated;
  for (std::size_t j = 0; j < map.size(); ++j)
    if (map[j].alive && map[j].id == id) return LandmarkEstimate<M>{id, map[j].mean, in_world_frame(map[j].cov)};
  return std::nullopt;
}

template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::landmark(LandmarkId id) const -> LandmarkEstimate<M> {
  const auto it = index_.find(id);
  if (it == index_.end()) {
    if (auto found = unassociated_landmark(id)) return *found;
    throw unknown_landmark_error("unknown landmark id " + std::to_string(id));
  }
  if (options_.map_estimate == FastSlamMap::best_particle) {
    const auto& L = particles_[best_particle()].landmarks[it->second];
    return {id, L.mean, in_world_frame(L.cov)};
  }
  const auto moments = mixture_moments<M>(weights(), [&](std::size_t i) { return particles_[i].landmarks[it->second].mean; },
                                          [&](std::size_t i) { return particles_[i].landmarks[it->second].cov; });
  return {id, moments.mean, in_world_frame(symmetrized(moments.cov))};
}

/// The known landmarks (per options().map_estimate), then those the most likely particle created
/// by its own association (their correspondence differs between particles, so they are not averaged).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::map() const -> MapEstimate {
  MapEstimate out;
  for (std::size_t index = 0; index < id_of_index_.size(); ++index)
    if (is_current(index)) out.push_back(landmark(id_of_index_[index]));
  const auto& own = particles_[best_particle()].unassociated;
  for (std::size_t j = 0; j < own.size(); ++j)
    if (own[j].alive) out.push_back({own[j].id, own[j].mean, in_world_frame(own[j].cov)});
  return out;
}

template <class Motion, class Sensor, template <class> class Map>
bool FastSlam<Motion, Sensor, Map>::has_landmark(LandmarkId id) const {
  return index_.contains(id) || unassociated_landmark(id).has_value();
}

template <class Motion, class Sensor, template <class> class Map>
std::size_t FastSlam<Motion, Sensor, Map>::num_landmarks() const {
  const auto& own = particles_[best_particle()].unassociated;
  std::size_t alive = 0;
  for (std::size_t j = 0; j < own.size(); ++j) alive += own[j].alive;
  return index_.size() + alive;
}

template <class Motion, class Sensor, template <class> class Map>
std::vector<LandmarkId> FastSlam<Motion, Sensor, Map>::landmark_ids() const {
  std::vector<LandmarkId> out;
  for (std::size_t index = 0; index < id_of_index_.size(); ++index)
    if (is_current(index)) out.push_back(id_of_index_[index]);
  const auto& own = particles_[best_particle()].unassociated;
  for (std::size_t j = 0; j < own.size(); ++j)
    if (own[j].alive) out.push_back(own[j].id);
  return out;
}

/// Forgets a landmark in every particle. A known id's index is not reused: observed again, the id
/// starts afresh at a new index.
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::remove_landmark(LandmarkId id) {
  if (const auto it = index_.find(id); it != index_.end()) {
    auto particles = particles_;
    for (auto& particle : particles) particle.landmarks.mutate(it->second).alive = false;
    particles_.swap(particles);
    index_.erase(it);
    return;
  }
  auto particles = particles_;
  bool found = false;
  for (auto& particle : particles)
    for (std::size_t j = 0; j < particle.unassociated.size(); ++j)
      if (particle.unassociated[j].id == id && particle.unassociated[j].alive) {
        particle.unassociated.mutate(j).alive = false;
        found = true;
      }
  if (!found) throw unknown_landmark_error("unknown landmark id " + std::to_string(id));
  particles_.swap(particles);
  estimate_.reset();
}

/// The index of the landmark of `particle` each measurement goes to (kNewLandmark: none is within
/// the new-landmark gate), the largest likelihood first; with the proposal (FastSLAM 2.0) each
/// associated measurement is folded into (mean, cov) before the next is associated.
template <class Motion, class Sensor, template <class> class Map>
std::vector<std::size_t> FastSlam<Motion, Sensor, Map>::associate_in_particle(Particle& particle, State& mean,
                                                                              PoseMatrix& cov,
                                                                              std::span<const Measurement> measurements,
                                                                              bool proposal) const {
  std::vector<std::size_t> match(measurements.size(), kNewLandmark);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    double best_nis = options_.new_landmark_nis;
    std::optional<Prediction> best;
    for (std::size_t j = 0; j < particle.unassociated.size(); ++j) {
      const auto& L = particle.unassociated[j];
      if (!L.alive) continue;
      auto prediction = sensor_.predict(mean, L.mean);
      const auto llt = cholesky_or_throw(proposal_covariance(prediction, cov, L), kProposalS);
      const double nis = mahalanobis_squared(llt, sensor_.residual(measurements[i], prediction.z));
      if (nis < best_nis) best_nis = nis, match[i] = j, best = std::move(prediction);
    }
    if (!proposal || !best) continue;
    // Only the chosen landmark is weighed (its likelihood, with heavy tails its noise factor).
    const auto chosen = proposal_innovation(std::move(*best), cov, particle.unassociated[match[i]], measurements[i],
                                            Eigen::Matrix<double, Z, 1>::Zero());
    particle.log_weight += fold_into_proposal(mean, cov, chosen);
  }
  return match;
}

/// One particle's association in update_unassociated: its pose over the pending motions and each
/// measurement's landmark (kNewLandmark: start one). With FastSLAM 2.0 the associated measurements
/// shape the Gaussian proposal (Particle::drawn_from, drawn_cov) and weigh on the particle, and so
/// does each new landmark, as a measurement on the new-landmark gate's edge (the p0 of Montemerlo
/// et al.); none of that depends on the pose drawn later (map_unassociated).
template <class Motion, class Sensor, template <class> class Map>
std::vector<std::size_t> FastSlam<Motion, Sensor, Map>::associate_and_propose(
    Particle& particle, std::span<const Measurement> measurements, bool proposal,
    const std::vector<PendingMotion>& pending) const {
  // Only FastSLAM 2.0 leaves motion pending (1.0 samples it in predict), so the prior is the
  // particle's point (tail Gaussian) without the proposal.
  PoseEstimate prior{particle.x, particle.cov};
  for (const auto& motion : pending) prior = motion_gaussian(prior.mean, prior.cov, motion.u, motion.dt);
  auto [mean, cov] = prior;
  const double log_weight = particle.log_weight;
  const auto match = associate_in_particle(particle, mean, cov, measurements, proposal);
  if (!proposal) {
    particle.forget_proposal();
    return match;
  }
  if (options_.iterations > 1) {  // the associated measurements' proposal iterated as update()'s
    auto folded = iterated_proposal_of_matches(particle, log_weight, prior, measurements, match);
    mean = std::move(folded.mean), cov = std::move(folded.cov), particle.log_weight = folded.log_weight;
  }
  for (std::size_t i = 0; i < measurements.size(); ++i)
    if (match[i] == kNewLandmark) particle.log_weight += new_landmark_log_weight(mean, measurements[i]);
  particle.drawn_from = std::move(mean);
  particle.drawn_cov = std::move(cov);
  return match;
}

/// The proposal of the measurements `match` pairs with landmarks of `particle`, iterated from the
/// particle's weight before them (the first pass repeats the association's folding).
template <class Motion, class Sensor, template <class> class Map>
auto FastSlam<Motion, Sensor, Map>::iterated_proposal_of_matches(const Particle& particle, double log_weight,
                                                                 const PoseEstimate& prior,
                                                                 std::span<const Measurement> measurements,
                                                                 const std::vector<std::size_t>& match) const
    -> FoldedProposal {
  std::vector<ObservationType> paired(measurements.size());
  std::vector<const LandmarkGaussian<M>*> landmarks(measurements.size(), nullptr);
  std::vector<Outcome> outcomes(measurements.size(), Outcome::gated);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    paired[i].z = measurements[i];
    if (match[i] == kNewLandmark) continue;
    landmarks[i] = &particle.unassociated[match[i]];
    outcomes[i] = Outcome::used;
  }
  return iterated_proposal(log_weight, prior, paired, landmarks, outcomes);
}

/// What a new landmark weighs: a measurement on the new-landmark gate's edge (NIS = new_landmark_nis)
/// against the measurement noise Q at pose x, log N (the Gaussian's log N(0; 0, Q) - new_landmark_nis
/// / 2) or log t with heavy-tailed noise.
template <class Motion, class Sensor, template <class> class Map>
double FastSlam<Motion, Sensor, Map>::new_landmark_log_weight(const State& x, const Measurement& z) const {
  const auto init = initialize_landmark(sensor_, x, z, LandmarkId{0}, 1.0);
  return noise_tails_.log_density_at_nis(cholesky_or_throw(init.Q, "measurement noise"), options_.new_landmark_nis);
}

/// One particle's landmarks in update_unassociated: with FastSLAM 2.0 its pose drawn from the
/// proposal first; each associated landmark updated from the pose (weighing on the particle
/// without a proposal), each other measurement starting a landmark with id next_unassociated_id + i.
template <class Motion, class Sensor, template <class> class Map>
void FastSlam<Motion, Sensor, Map>::map_unassociated(Particle& particle, std::span<const Measurement> measurements,
                                                     const std::vector<std::size_t>& match, bool proposal,
                                                     Transaction& t) const {
  if (proposal) draw_into(particle, {particle.drawn_from, particle.drawn_cov}, t.rng);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    if (match[i] != kNewLandmark) {
      const double log_likelihood = update_landmark(particle, match[i], measurements[i], 1.0, true).log_likelihood;
      if (!proposal) particle.log_weight += log_likelihood;
      continue;
    }
    const LandmarkId id = t.next_unassociated_id + i;
    const auto init = initialize_landmark(sensor_, particle.x, measurements[i], id, 1.0);
    particle.unassociated.push_back({init.m, symmetrized(init.J_m_z * init.Q * init.J_m_z.transpose()), true, id});
    if (!proposal) particle.log_weight += new_landmark_log_weight(particle.x, measurements[i]);
  }
}

}  // namespace sextant
