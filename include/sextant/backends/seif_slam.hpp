#pragma once
/// \file SEIF-SLAM, the sparse extended information filter (thesis §3.5, Appendix A; Thrun et al.;
/// Eustice et al.), for any motion and measurement model pair.

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <span>
#include <vector>

#include "sextant/core/backend_types.hpp"
#include "sextant/core/closed_form_landmarks.hpp"
#include "sextant/core/landmark_store.hpp"
#include "sextant/core/concepts.hpp"
#include "sextant/core/conditionally_linear.hpp"
#include "sextant/core/filter_linearization.hpp"
#include "sextant/core/observability_constraints.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/innovation_gate.hpp"
#include "sextant/core/joint_marginal.hpp"
#include "sextant/core/landmark_pool.hpp"
#include "sextant/core/linearized_observation.hpp"
#include "sextant/core/lost_pose_recovery.hpp"
#include "sextant/core/sparse_cholesky.hpp"
#include "sextant/core/slot_set.hpp"
#include "sextant/core/sparse_information.hpp"
#include "sextant/core/matrix_workspace.hpp"
#include "sextant/core/update_result.hpp"
#include "sextant/core/versioned_cache.hpp"

namespace sextant {

/// How the mean of the robot and the active landmarks is recovered after each update.
enum class MeanRecovery {
  /// One joint solve of Omega_BB delta_B = r_B over B = robot + active landmarks (passive ones held
  /// fixed): one block coordinate-descent step with the whole active neighbourhood as the block.
  active_block,
  /// The thesis's coordinate descent (eqs. 33-36): the robot, then each active landmark in turn.
  coordinate_descent,
};

/// How SEIF bounds the landmarks linked to the robot (docs/derivations/seif_relocalization.md).
enum class SeifSparsification {
  /// Thesis eqs. 37-44 (Thrun et al.): the robot's links to the landmarks leaving the active set are
  /// dropped by an approximation that conditions on the passive landmarks; overconfident in the
  /// global frame (Walter, Eustice and Leonard, IJRR 2007).
  thesis,
  /// The exactly sparse filter of Walter, Eustice and Leonard (ESEIF): when the active set would
  /// overflow, the measurements of a few observed landmarks are held back, the robot is marginalized
  /// out after the others are applied, and a new robot state is relocalized from the held-back
  /// ones. Only information is discarded (conservative). The measurements must determine the robot
  /// state but a conditionally linear tail no measurement sees (the 12D camera's velocities), which
  /// is relocalized from SeifOptions::relocalization_tail_covariance.
  relocalization,
};

/// The mean that pose(), landmark() and map() report.
enum class SeifEstimate {
  /// The one the update keeps (recovered over the robot and the active landmarks; passive
  /// landmarks keep the mean they had when they left the active set): the thesis's estimate.
  recovered_mean,
  /// Omega^-1 xi, the mean of the Gaussian the information form holds: one more solve with the
  /// factor pose() and map() compute for the covariances anyway; the update stays O(1).
  exact_mean,
};

struct SeifOptions {
  std::size_t max_active = 0;     ///< landmarks kept linked to the robot by sparsification; 0 = no sparsification
  SeifSparsification sparsification = SeifSparsification::thesis;
  /// Relocalization only: the held-back measurements, their landmarks' uncertainty counted, must
  /// carry at least this share of the robot's information given the map (Omega_xx) in every
  /// direction: when max_active of them do not, the next most informative join them (the new active
  /// set is then larger than max_active); when all of the step's do not, the step does not sparsify
  /// and the active set stays over max_active until one can. A pose relocalized from two landmarks
  /// 0.2 m apart seen from 5 m has a heading the next linearizations cannot trust; the sweep that
  /// chose 0.05 (at most 20x less information, 4.5x the standard deviation) is in
  /// docs/results/seif_relocalization.md.
  double relocalization_min_information = 0.05;
  /// Relocalization only: a bound on that overflow, for a step cost that stays bounded. When the
  /// update would leave more than this many landmarks linked to the robot, the max_active most
  /// informative held-back measurements relocalize it as soon as they determine the pose at all (full
  /// rank, conditioned), however little of its information they carry. Without it, data that see a
  /// few landmarks at a time (Victoria Park's 0-3 trees a step) may never relocalize, and the robot
  /// ends linked to the whole map at an EKF's cost per step; with it, the map pays for the weak
  /// relocalizations (every log of docs/results/simul_landmarks.md measured with 2x, 4x and 8x
  /// max_active in docs/results/seif_relocalization.md, "A bound on the overflow"). 0 = no bound.
  std::size_t relocalization_active_bound = 0;
  /// Relocalization of a robot whose motion model has a tail no measurement sees
  /// (kConditionallyLinearDims = T, e.g. the 12D camera's velocities): the covariance (T x T) the
  /// relocalized tail gets, centred at its current mean and linked to nothing. Empty (the default):
  /// the prior's, the uncertainty the filter started with. The relocalized filter is then
  /// overconfident by at most the factor 1 + sum over relocalizations k of
  /// lambda_max(Sigma_tt(k) Sigma_tail^-1), Sigma_tt(k) the tail's exact marginal covariance then
  /// (docs/derivations/seif_relocalization.md): small where the data have taught the filter the
  /// tail far better than the prior knew it.
  Eigen::MatrixXd relocalization_tail_covariance{};
  SeifEstimate estimate = SeifEstimate::recovered_mean;
  MeanRecovery mean_recovery = MeanRecovery::active_block;
  int mean_recovery_sweeps = 1;   ///< sweeps per update (0 = none)
  int exact_recovery_period = 0;  ///< every K updates, an exact sparse solve of the whole mean; 0 = never
  /// In (0, 1): the local recovery moves the block's means and leaves the rest of the map where it
  /// was, so after a loop closure the landmarks next to the block lag behind and later steps linearize
  /// at them. When one of the landmarks whose residual r_p the recovery changed would move, given its
  /// neighbours, by more than the chi-square quantile at this probability of its conditional
  /// information (r_p^T Omega_pp^-1 r_p), the whole mean is recovered exactly (one sparse solve, only
  /// in such steps). 0 = never (the thesis's SEIF).
  double stale_mean_probability = 0.0;
  /// In (0, 1): reject observations whose innovation fails the chi-square test at this probability
  /// (core/innovation_gate.hpp), with S from the exact joint marginal of the robot and the landmark.
  /// That costs one sparse factorization of Omega per update: with the gate on, an update is no
  /// longer constant time. 0 = off.
  double gate_probability = 0.0;
  /// H of each landmark at its first estimate, the residual at the current one, as
  /// EkfOptions::first_estimate_jacobians: with the pose perturbed in the world frame the information
  /// added then never reaches the unobservable global pose. Off: the thesis's SEIF.
  bool first_estimate_jacobians = false;
  /// Observability constraints, as EkfOptions::observability_constraints (OC-EKF in information form:
  /// the constrained G and H enter the motion and measurement updates unchanged otherwise).
  bool observability_constraints = false;
  /// Linearizations of each update's measurements: 1 (the default) is the thesis's SEIF, linearized at
  /// the prediction; k > 1 is the iterated update, the information-form twin of
  /// EkfOptions::iterations: after the mean is recovered, the step's measurements are taken out as
  /// the linear factors they added and added again linearized at the recovered mean, up to k times
  /// (fewer once the mean moves by < 1e-9 of its step). With relocalization the whole step is
  /// iterated before the robot is marginalized, so the held-back measurements relocalize it from the
  /// step's mean. Each iteration costs one more mean recovery.
  int iterations = 1;
  /// With the gate on: re-acquisition of a lost pose, as EkfOptions::reacquisition (the same
  /// machinery, core/lost_pose_recovery.hpp); the moved copy's pose covariance grows by d d^T as a
  /// motion update with G = I and R = d d^T would grow it. min_landmarks = 0 (the default): off.
  ReacquisitionOptions reacquisition{};
};

/// Wall time of one update's stages, as the thesis times them (§5.4, Tables 15-16): measurement
/// (linearization, gate, information added, new landmarks), update of the state estimate (mean
/// recovery) and sparsification (with the active set's bookkeeping).
struct SeifUpdateTimes {
  double measurement_s = 0.0;
  double mean_recovery_s = 0.0;
  double sparsification_s = 0.0;
};

/// SEIF-SLAM in error-state information form: Omega (block-sparse) and r = xi - Omega mu at the
/// current mean mu. The motion update touches the robot and the active landmarks only (eqs. 20-26,
/// by the matrix inversion lemma); a measurement adds H^T Q^-1 H and H^T Q^-1 nu (eqs. 27-30); the
/// mean of the robot and the active landmarks is recovered by coordinate descent (eqs. 31-36);
/// sparsification keeps at most max_active landmarks linked to the robot (eqs. 37-44, Appendix A).
/// Covariances are computed on demand by sparse Cholesky solves, never by inverting Omega.
/// Threads: const methods (pose(), map(), landmark(), information_matrix(), ...) may be called from several threads
/// at once on one estimator; a non-const one (predict, update, remove_landmark, recover_mean_exactly) must not overlap any other call on it.
/// Independent estimators share nothing (tests/backends/concurrent_reads_test.cpp, under
/// ThreadSanitizer with ./run.sh test-tsan).
template <class Motion, class Sensor>
class SeifSlam {
  static_assert(ModelsFit<Motion, Sensor>::value, "SeifSlam: the models do not fit (see the message above)");

 public:
  SEXTANT_BACKEND_TYPES;

  SeifSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, SeifOptions options = {});

  /// Motion update (eqs. 20-26). Throws invalid_input_error on NaN/Inf or dt <= 0, numerical_error
  /// when the motion Jacobian is singular; the state is then unchanged.
  void predict(const Control& u, double dt);

  /// Measurement update, new landmarks, mean recovery and sparsification, then re-acquisition's
  /// bookkeeping (options().reacquisition; never throws). Bad input (NaN/Inf, repeated ids, non-PD
  /// noise) throws before anything changes.
  UpdateResult update(std::span<const ObservationType> observations);
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }

  /// Moves the robot's mean by d (Space::plus) and adds d d^T to its covariance, as
  /// EkfSlam::reacquire_pose: in information form the motion update with G = I and R = d d^T, which
  /// changes the robot's and the active landmarks' blocks only. Throws invalid_input_error on a d
  /// that is not finite; the state is then unchanged.
  void reacquire_pose(const Eigen::Matrix<double, X, 1>& d);

  /// A landmark known before it is seen (a surveyed map), with its mean and covariance, uncorrelated
  /// with the robot and the map: its information block is cov^-1 and it has no link (it is not active),
  /// as EkfSlam::add_landmark's zero cross-covariance. Throws on a non-finite mean, a covariance that
  /// is not symmetric positive definite, or an id already in the map; the filter is then unchanged.
  void add_landmark(const LandmarkEstimate<M>& known);
  /// Marginalizes a landmark out of the information form (thesis Appendix C).
  void remove_landmark(LandmarkId id);
  /// Whether remove_landmark(id) would link no two landmarks (or the robot and a landmark) that are
  /// not linked already: the pool's PoolEviction::fewest_sightings_without_fill asks it to keep Omega sparse.
  bool removal_adds_no_links(LandmarkId id) const { return info_.marginalizing_adds_no_links(landmarks_.slot(id)); }

  /// Solves Omega delta = r exactly (sparse Cholesky) and moves the whole mean to it.
  void recover_mean_exactly();

  /// Pose mean (SeifOptions::estimate) with its marginal covariance by sparse solves with the Cholesky
  /// factor of Omega, computed once per change of the filter (O(nnz of the factor)) and shared by
  /// pose(), landmark() and map().
  PoseEstimate pose() const;
  /// The recovered pose mean alone, O(1): pose() factorizes Omega, which fills in as the map grows.
  const State& pose_mean() const { return x_; }
  LandmarkEstimate<M> landmark(LandmarkId id) const;
  MapEstimate map() const;
  /// Every landmark's id and mean (SeifOptions::estimate), O(n) with the recovered mean: map()
  /// without its covariances.
  std::vector<std::pair<LandmarkId, Landmark>> landmark_means() const {
    return landmarks_.id_mean_pairs([&](std::size_t slot) { return estimated_landmark_mean(slot); });
  }
  /// The joint Gaussian of the robot and the landmarks `ids`, in that order (for data association,
  /// core/data_association.hpp): one multi-column solve with the factor of Omega, X + M k columns;
  /// the means are the recovered ones the update linearizes at.
  /// Throws unknown_landmark_error.
  JointMarginal<State, M> joint_marginal(std::span<const LandmarkId> ids) const;
  /// Per landmark of `ids`, the robot and that landmark conditioned on the rest of the state,
  /// (Omega_BB)^-1 for B = {robot, landmark}: O(1) each, no factorization of Omega (the gate of
  /// Probabilistic Robotics §12.7, per landmark). Never wider than the joint marginal; for a
  /// measurement relative to the robot it loses only what the rest of the map says about their
  /// relative position (on the globe, S within 1.06x of the exact one: docs/results/real_time.md).
  /// Throws unknown_landmark_error, or numerical_error when a block is not positive definite.
  std::vector<Eigen::Matrix<double, X + M, X + M>> conditional_joints(std::span<const LandmarkId> ids) const;
  /// Every landmark's id and the mean the update linearizes at (SeifEstimate::recovered_mean), O(n)
  /// without a solve, whatever SeifOptions::estimate says: what a gate must predict from.
  std::vector<std::pair<LandmarkId, Landmark>> linearization_means() const {
    return landmarks_.id_mean_pairs([&](std::size_t slot) { return landmark_mean(slot); });
  }
  bool has_landmark(LandmarkId id) const { return landmarks_.contains(id); }
  std::size_t num_landmarks() const { return landmarks_.size(); }
  const std::vector<LandmarkId>& landmark_ids() const { return landmarks_.ids(); }
  Eigen::Index state_dim() const { return info_.dim(); }
  /// Ids of the landmarks linked to the robot, most recently observed first.
  std::vector<LandmarkId> active_landmarks() const;
  /// The information matrix, ordered (robot, landmarks in slot order).
  Eigen::SparseMatrix<double> information_matrix() const { return info_.to_sparse(); }
  const SparseInformation<X, M>& information() const { return info_; }
  const SeifOptions& options() const { return options_; }
  /// Stage times of the last update that succeeded (zeros before the first).
  const SeifUpdateTimes& last_update_times() const { return last_update_times_; }
  /// Updates that relocalized the robot (SeifSparsification::relocalization) since construction.
  std::uint64_t relocalizations() const { return relocalizations_; }
  /// Updates whose whole mean was recovered exactly because the map next to the block lagged
  /// (SeifOptions::stale_mean_probability) since construction.
  std::uint64_t stale_recoveries() const { return stale_recoveries_; }

 private:
  using Linearized = LinearizedObservation<Z, X, M>;
  using Init = LandmarkInit<M, X, Z>;
  using Factor = SparseCholesky;  ///< the project's one sparse factorization path (CHOLMOD when linked)
  /// Information that one observation adds: H^T W H and H^T W nu by blocks, W = Q^-1.
  /// r_x, r_m are the factor's gradient at the robot state and landmark mean it was linearized at.
  struct MeasurementInformation {
    std::size_t slot;
    Eigen::Matrix<double, X, X> xx;
    Eigen::Matrix<double, X, M> xm;
    Eigen::Matrix<double, M, M> mm;
    Eigen::Matrix<double, X, 1> r_x;
    Eigen::Matrix<double, M, 1> r_m;
    LandmarkId id;
    State at_x;     ///< where it was linearized: the robot state
    Landmark at_m;  ///< and the landmark mean
  };
  /// A new landmark as the conditional m = init.m + J_m_x dx + noise with covariance J_m_z Q J_m_z^T.
  struct NewLandmark {
    LandmarkId id;
    Landmark mean;
    Eigen::Matrix<double, X, X> xx;  ///< J_m_x^T W J_m_x
    Eigen::Matrix<double, X, M> xm;  ///< -J_m_x^T W
    Eigen::Matrix<double, M, M> mm;  ///< W
  };

  static Eigen::Index offset_of(std::size_t slot) { return LandmarkStore<M>::template offset_of<X>(slot); }
  Landmark landmark_mean(std::size_t slot) const { return landmarks_.mean(slot); }

  /// Nothing when the model cannot use the observation here (its id then goes to `unusable`).
  std::optional<Linearized> linearize(const ObservationType& observation, std::vector<LandmarkId>& unusable) const;
  MeasurementInformation measurement_information(const Linearized& lin) const;
  void gate(std::vector<Linearized>& observations, UpdateResult& result) const;
  /// The motion update (eqs. 20-26) from the robot's transition G and noise R to the moved mean.
  void apply_motion(const State& moved, const Eigen::Matrix<double, X, X>& G, const Eigen::Matrix<double, X, X>& R);
  /// update() without re-acquisition.
  UpdateResult update_information(std::span<const ObservationType> observations);
  using Reacquisition = PoseReacquisition<Space, Sensor, State, X>;
  using Recovery = LostPoseRecovery<SeifSlam, Reacquisition>;
  friend Recovery;
  std::vector<typename Reacquisition::Sighting> rejected_sightings(std::span<const ObservationType> observations,
                                                                   const UpdateResult& result) const;
  std::optional<NewLandmark> new_landmark(const ObservationType& observation, std::vector<LandmarkId>& unusable) const;
  /// The linear factor `info`, linearized at the current mean, added to the information form.
  void add(const MeasurementInformation& info);
  /// The linear factor `info` taken out again, the mean having moved since it was linearized.
  void take_out(const MeasurementInformation& info);
  void add_factor(const MeasurementInformation& info, double sign, const Eigen::Matrix<double, X, 1>& r_x,
                  const Eigen::Matrix<double, M, 1>& r_m);
  /// The iterated update (SeifOptions::iterations): `step` relinearized at the recovered mean and the
  /// mean recovered again, until it stops moving; `squared_pivots` keeps the last recovery's.
  void relinearize_at_iterates(std::span<const ObservationType> known, std::vector<MeasurementInformation>& step,
                               const State& prior, std::optional<Eigen::VectorXd>& squared_pivots);
  /// `step` linearized again at the current mean; nothing when an observation cannot be used there.
  std::optional<std::vector<MeasurementInformation>> relinearize(std::span<const ObservationType> known,
                                                                 const std::vector<MeasurementInformation>& step) const;
  /// The mean after this step's measurements: exact when due, else over the active block.
  std::optional<Eigen::VectorXd> recover_step_mean();
  /// ESEIF, iterated: the whole step (the held-back measurements too) iterated to its mean, then the
  /// held-back ones, linearized there, taken out again for relocalize().
  void iterate_before_relocalizing(std::span<const ObservationType> known,
                                   const std::vector<MeasurementInformation>& applied,
                                   std::vector<MeasurementInformation>& held_back, std::vector<std::size_t> observed,
                                   const State& prior);
  void augment(const NewLandmark& landmark);
  std::vector<std::size_t> add_step(const std::vector<MeasurementInformation>& measurements,
                                    const std::vector<NewLandmark>& landmarks);
  /// What a failed step restores besides the information form (which journals itself).
  struct Undo {
    State x;
    std::vector<std::pair<std::size_t, Landmark>> means;  ///< old means of moved landmarks, in order
    std::optional<Eigen::VectorXd> all_means;             ///< every mean, when an exact recovery moved all
    std::vector<std::size_t> active_queue;
    std::uint64_t updates;
    std::size_t landmarks;
  };
  template <class Step>
  void atomically(Step step);
  void move_landmark_mean(std::size_t slot, const Eigen::Matrix<double, M, 1>& dm);
  void require_finite_robot_and_active(const char* what) const;
  void require_factorizable_robot_and_active(const char* what);
  void recover_mean_exactly_in_transaction();
  /// This update is one of every exact_recovery_period-th (SeifOptions): its mean is recovered exactly.
  bool exact_recovery_due() const {
    return options_.exact_recovery_period > 0 && updates_ % static_cast<std::uint64_t>(options_.exact_recovery_period) == 0;
  }
  /// The squared pivots of the active block's factor when one was computed (active_block recovery).
  std::optional<Eigen::VectorXd> recover_mean_locally();
  void recover_mean_by_coordinate_descent();
  /// Whether this update's sparsification will deactivate landmarks (the thesis's; ESEIF relocalizes).
  bool sparsification_due() const {
    return options_.sparsification == SeifSparsification::thesis && options_.max_active > 0 &&
           active_queue_.size() > options_.max_active;
  }
  Eigen::VectorXd recover_mean_of_active_block() {
    const bool sparsifies = sparsification_due();
    return recover_mean_of_block(active_queue_, sparsifies ? options_.max_active : active_queue_.size(), sparsifies);
  }
  Eigen::VectorXd recover_mean_of_block(const std::vector<std::size_t>& slots, std::size_t leading,
                                        bool sparsification_follows);
  /// The positions in B = (robot, slots...) of the landmarks among the first `leading` of `slots`
  /// that have no landmark links (linked to the robot alone: those this update added).
  std::vector<Eigen::Index> unlinked_positions(const std::vector<std::size_t>& slots, std::size_t leading) const;
  void apply_mean_recovery(const std::vector<std::size_t>& slots, const Eigen::VectorXd& delta,
                           const Eigen::VectorXd& r_after);
  /// SeifOptions::stale_mean_probability: the whole mean recovered exactly when a landmark in
  /// changed_residuals_ lags its neighbours by more than the gate.
  void recover_exactly_if_stale();
  void robot_and_landmarks_block(const std::vector<std::size_t>& slots, Eigen::Ref<Eigen::MatrixXd> D) const;
  void gather_links_below(const std::vector<std::size_t>& slots, std::size_t a, Eigen::Ref<Eigen::MatrixXd> D,
                          std::size_t first) const;
  void fill_robot_and_diagonal_blocks(const std::vector<std::size_t>& slots, Eigen::Ref<Eigen::MatrixXd> D) const;
  static void require_factorizable_block(Eigen::Ref<Eigen::MatrixXd> D, const char* what);
  /// A predicate true for exactly the given slots (in marked_slots_), valid until the next call.
  auto mark_slots(const std::vector<std::size_t>& slots);
  void update_active_queue(const std::vector<std::size_t>& observed_slots);
  /// ESEIF: the observations to relocalize the robot from, taken out of `observations`, when the
  /// update would leave more than max_active landmarks linked to the robot: max_active of them, or
  /// as many more as carry relocalization_min_information (none when all of them do not: the active
  /// set then overflows until a step can relocalize, up to relocalization_active_bound(), past
  /// which any set that determines the pose will do).
  std::vector<MeasurementInformation> hold_back_for_relocalization(std::vector<MeasurementInformation>& observations,
                                                                   std::size_t new_landmarks) const;
  std::vector<Eigen::Matrix<double, X, X>> information_about_robot(const std::vector<MeasurementInformation>& observations) const;
  /// The trailing entries of the robot state no measurement sees (core/conditionally_linear.hpp).
  static constexpr int kUnseenTail = conditionally_linear_dims_v<Motion>;
  Eigen::MatrixXd relocalized_tail_information(const PoseEstimate& prior) const;
  std::optional<Eigen::Matrix<double, X - kUnseenTail, X - kUnseenTail>> seen_information_given_map() const;
  static void pick_most_informative(std::vector<MeasurementInformation>& observations,
                                    std::vector<Eigen::Matrix<double, X, X>>& about_robot, std::size_t k,
                                    Eigen::Matrix<double, X, X>& chosen);
  bool carries_enough(const Eigen::Matrix<double, X, X>& chosen,
                      const Eigen::Matrix<double, X - kUnseenTail, X - kUnseenTail>& reference, double share) const;
  /// carries_enough's share when any held-back set that determines the pose will do.
  static constexpr double kAnyShare = -std::numeric_limits<double>::infinity();
  /// SeifOptions::relocalization_active_bound, 0 read as none.
  std::size_t relocalization_active_bound() const {
    return options_.relocalization_active_bound != 0 ? options_.relocalization_active_bound
                                                     : std::numeric_limits<std::size_t>::max();
  }
  /// Omega' = Omega_mm - Omega_mx Omega_xx^-1 Omega_xm and r' likewise, over the active landmarks
  /// only; leaves the robot with no information and no links.
  void marginalize_robot();
  void relocalize(const std::vector<MeasurementInformation>& held_back, std::vector<std::size_t> observed);
  /// The squared pivots of the Cholesky factor of S_xx when it sparsified. `active_block_gathered`:
  /// block_workspace_ holds Omega over (robot, active queue) as mean recovery gathered it (Omega has
  /// not changed since), which sparsification then reads instead of gathering its rows again.
  std::optional<Eigen::Matrix<double, X, 1>> sparsify(bool active_block_gathered);
  void require_factorizable_after_update(const std::optional<Eigen::VectorXd>& squared_pivots,
                                         const std::optional<Eigen::Matrix<double, X, 1>>& robot_squared_pivots);
  std::shared_ptr<const Factor> factorization() const;
  /// What SeifOptions::estimate adds to the recovered means: Omega^-1 r (exact_mean) or nothing.
  std::shared_ptr<const Eigen::VectorXd> estimate_correction() const;
  State estimated_pose_mean() const;
  Landmark estimated_landmark_mean(std::size_t slot) const;
  Eigen::MatrixXd marginal_covariance(Eigen::Index offset, Eigen::Index size) const;
  /// The joint covariance of the robot and the landmark blocks starting at `offsets`, in that order.
  Eigen::MatrixXd joint_covariance(const std::vector<Eigen::Index>& offsets) const;
  void touch() { ++revision_; }

  Motion motion_;
  Sensor sensor_;
  SeifOptions options_;
  /// The information a relocalized robot gets on the tail no measurement sees (T x T; empty when
  /// T = 0 or without relocalization).
  Eigen::MatrixXd tail_information_;
  InnovationGate gate_;
  State x_;
  State propagated_;  ///< the robot state after the last prediction (observability constraints)
  SparseInformation<X, M> info_;
  LandmarkStore<M> landmarks_;  ///< ids, slots, means and first means (first_estimate_jacobians)
  SeifUpdateTimes last_update_times_;
  std::vector<std::size_t> active_queue_;  ///< slots linked to the robot, most recently observed first
  std::uint64_t updates_ = 0;
  std::uint64_t relocalizations_ = 0;
  std::uint64_t stale_recoveries_ = 0;
  double stale_gate_ = 0.0;  ///< chi-square quantile of SeifOptions::stale_mean_probability (0: off)
  bool recovered_stale_mean_ = false;  ///< this update recovered the whole mean for staleness (scratch)
  std::uint64_t revision_ = 0;
  Undo* undo_ = nullptr;  ///< the open transaction's undo record
  VersionedCache<Factor> factor_;  ///< factorization of Omega at revision_ (thread-safe)
  VersionedCache<Eigen::VectorXd> correction_;  ///< Omega^-1 r at revision_ (exact_mean only)
  MatrixWorkspace block_workspace_;   ///< the dense robot-and-landmarks block of the step (scratch)
  MatrixWorkspace factor_workspace_;  ///< its Cholesky factor (scratch)
  SlotSet marked_slots_;  ///< mark_slots' slots (scratch)
  /// The landmarks outside a recovered block whose residual this update's recoveries changed (scratch).
  SlotSet changed_residuals_;
  Recovery recovery_;  ///< re-acquisition of a lost pose (off unless options_.reacquisition says)
};

}  // namespace sextant

#include "sextant/backends/detail/seif_slam_impl.hpp"

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_SEIF_SLAM
#include "sextant/compiled/extern_instances.hpp"
