#pragma once
/// \file EKF-SLAM (thesis §3.4) for any motion and measurement model pair.

#include <Eigen/Core>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "sextant/core/backend_types.hpp"
#include "sextant/core/state_space.hpp"
#include "sextant/core/landmark_store.hpp"
#include "sextant/core/rollback_guard.hpp"
#include "sextant/core/concepts.hpp"
#include "sextant/core/filter_linearization.hpp"
#include "sextant/core/observability_constraints.hpp"
#include "sextant/core/lost_pose_recovery.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/innovation_gate.hpp"
#include "sextant/core/joint_marginal.hpp"
#include "sextant/core/landmark_pool.hpp"
#include "sextant/core/linearized_observation.hpp"
#include "sextant/core/symmetric_matrix.hpp"
#include "sextant/core/update_result.hpp"

namespace sextant {

/// How the covariance is corrected after a measurement update.
enum class CovarianceUpdate {
  /// P <- P - C S^-1 C^T with C = P H^T, as a symmetric rank update of the lower triangle
  /// (thesis eq. 17): O(n^2 k / 2). Loses positive semi-definiteness when the measurements are
  /// far more accurate than the state (docs/ekf_covariance_update.md).
  symmetric,
  /// Joseph form P <- (I - K H) P (I - K H)^T + K Q K^T, evaluated as written with X = I - K H
  /// formed on the columns H touches: three n x n x k products and an n x n temporary.
  /// Keeps P positive semi-definite where the symmetric form cancels (docs/ekf_covariance_update.md).
  joseph,
};

struct EkfOptions {
  bool batch_update = true;  ///< one joint correction per step (one pass over P) or one per observation
  CovarianceUpdate covariance_update = CovarianceUpdate::symmetric;
  double gate_probability = 0.0;  ///< in (0, 1): reject observations with NIS above the chi2 quantile; 0 = off
  /// First-estimate Jacobians (Huang, Mourikis and Roumeliotis 2008, for landmarks): H is evaluated
  /// at each landmark's first estimate, the residual at its current one. With a motion Jacobian that
  /// does not depend on the estimate along the unobservable directions (G = I for SE(3) poses
  /// perturbed in the world frame), every H then shares one null space and the filter gains no
  /// information about the unobservable global pose (docs/results/vislam.md). Off: the textbook EKF.
  bool first_estimate_jacobians = false;
  /// The error-state filter's reset: after a correction delta, P is read in the tangent at the new
  /// robot state, P_x -> G P_x G^T with G = plus_jacobian(x, delta) (docs/derivations/
  /// state_space_jacobians.md); a no-op for additive charts. Off by default: it moves the pose part
  /// of the unobservable subspace that first-estimate Jacobians keep fixed, and measured it costs
  /// more than it brings (MRCLAM world chart with first estimates: 0.28-0.45 m -> 0.40-4.5 m).
  bool tangent_reset = false;
  /// Observability constraints (OC-EKF, core/observability_constraints.hpp): the robot's transition
  /// and every observation's Jacobian are replaced by the nearest ones that keep the world's rigid
  /// motions unobservable, as they are. Needs a state space that names them
  /// (Space::world_motion_directions; the 12D camera does) and point landmarks.
  bool observability_constraints = false;
  /// With the gate on: once it has rejected sightings of min_landmarks distinct landmarks and
  /// accepted none since, whether the pose is lost and where (one offset explains them, dead
  /// reckoning could have drifted that far, a copy moved there explains the next sightings better:
  /// core/pose_reacquisition.hpp); min_landmarks = 0 (the default) keeps rejecting. Without it a
  /// gated filter that comes back from a long gap beyond its own covariance never corrects again
  /// (docs/results/mrclam.md, stress cases). Needs the gate: a min_landmarks > 0 without it throws.
  ReacquisitionOptions reacquisition{};
  /// Iterated EKF (Bell and Cathey 1993: the update as Gauss-Newton on the prior and the step's
  /// measurements): up to this many linearizations per update, each at the previous one's corrected
  /// robot and landmarks, the covariance corrected once with the last Jacobians. 1 = the textbook
  /// EKF, linearized at the prediction. Iterations cost O(n k) each beside the O(n^2 k) covariance
  /// correction; they matter where a landmark is close to the sensor compared with the robot's
  /// predicted uncertainty (docs/results/iterated_ekf.md).
  int iterations = 1;
};

/// EKF-SLAM: joint Gaussian over the robot state and a growing set of landmarks. Only the lower
/// triangle of the joint covariance P is stored and updated, which halves the memory traffic of
/// the O(n^2) covariance correction.
/// Prediction touches only the robot rows and columns of P (eqs. 10-13); an update uses only the
/// robot and landmark blocks of H, so P H^T costs O(n) per observation (eqs. 14-17); new landmarks
/// are added with the cross-covariance of the model's inverse.
/// Threads: const methods (pose(), map(), landmark(), covariance(), ...) may be called from several threads
/// at once on one estimator; a non-const one (predict, update, remove_landmark, reserve) must not overlap any other call on it.
/// Independent estimators share nothing (tests/backends/concurrent_reads_test.cpp, under
/// ThreadSanitizer with ./run.sh test-tsan).
template <class Motion, class Sensor>
class EkfSlam {
  static_assert(ModelsFit<Motion, Sensor>::value, "EkfSlam: the models do not fit (see the message above)");

 public:
  SEXTANT_BACKEND_TYPES;

  EkfSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, EkfOptions options = {});

  /// Motion update over dt with control u (eqs. 10-11). Throws invalid_input_error on NaN/Inf or dt <= 0.
  void predict(const Control& u, double dt);

  /// Corrects with observations of known landmarks and adds the unknown ones to the map.
  /// Throws on NaN/Inf, repeated ids or a non positive definite innovation; the state is then unchanged.
  UpdateResult update(std::span<const ObservationType> observations);
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }

  /// Reserves memory for a map of `landmarks` landmarks (the covariance is (X + M n)^2 doubles).
  void reserve(std::size_t landmarks) { cov_.reserve(X + M * static_cast<Eigen::Index>(landmarks)); }

  /// Marginalizes a landmark out of the joint Gaussian. Throws unknown_landmark_error.
  void remove_landmark(LandmarkId id);

  /// Puts a landmark known before it is seen (a surveyed beacon, a map from an earlier run) into the
  /// map with the given mean and covariance, uncorrelated with the robot and the other landmarks;
  /// its first estimate (first-estimate Jacobians) is that mean. Throws duplicate_landmark_error for
  /// an id in the map, invalid_input_error for a mean or covariance with NaN or Inf or a covariance
  /// that is not symmetric positive definite; the state is then unchanged.
  void add_landmark(const LandmarkEstimate<M>& known);

  /// Moves the robot's mean by d (Space::plus) and adds d d^T to its covariance: the pose taken
  /// as lost by d, with the uncertainty of not knowing whether it was (core/pose_reacquisition.hpp).
  /// Throws invalid_input_error on a d that is not finite; the state is then unchanged.
  void reacquire_pose(const Eigen::Matrix<double, X, 1>& d);

  /// In its space's canonical coordinates (in_canonical_coordinates: an update can carry a pitch past 90°).
  PoseEstimate pose() const {
    return in_canonical_coordinates<Space>(PoseEstimate{x_, symmetric_diagonal_block<X>(cov_.view(), 0)});
  }
  LandmarkEstimate<M> landmark(LandmarkId id) const { return landmark_at(landmarks_.slot(id)); }
  MapEstimate map() const;
  /// Every landmark's id and mean, O(n): map() without its covariances (what a front-end needs to
  /// find the landmarks in view before asking joint_marginal() for those).
  std::vector<std::pair<LandmarkId, Landmark>> landmark_means() const {
    return landmarks_.id_mean_pairs([&](std::size_t slot) { return landmark_mean(slot); });
  }
  /// The joint Gaussian of the robot and the landmarks `ids`, in that order (for data association,
  /// core/data_association.hpp): a gather from P, O((X + M k)^2). Throws unknown_landmark_error.
  JointMarginal<State, M> joint_marginal(std::span<const LandmarkId> ids) const;
  bool has_landmark(LandmarkId id) const { return landmarks_.contains(id); }
  std::size_t num_landmarks() const { return landmarks_.size(); }
  /// Joint covariance of (robot, landmarks in slot order), dimension X + M * num_landmarks().
  /// A copy: O(n^2).
  Eigen::MatrixXd covariance() const { return cov_.view().template selfadjointView<Eigen::Lower>(); }
  /// Dimension of the joint state, X + M * num_landmarks().
  Eigen::Index state_dim() const { return cov_.dim(); }
  const std::vector<LandmarkId>& landmark_ids() const { return landmarks_.ids(); }
  const EkfOptions& options() const { return options_; }

 private:
  using Linearized = LinearizedObservation<Z, X, M>;
  using Init = LandmarkInit<M, X, Z>;
  /// A correction computed without touching the state: delta for the mean and the factors of
  /// the covariance decrease.
  struct Correction {
    Eigen::VectorXd delta;
    State x;                   ///< plus(x, delta_x), the corrected robot state
    Eigen::MatrixXd Wt;        ///< symmetric form: C L^-T (n x Zk), P' = P - Wt Wt^T
    Eigen::MatrixXd P_joseph;  ///< Joseph form: the whole corrected P
    /// G = plus_jacobian(x, delta_x): the corrected P, held in the tangent at the old x, is read at
    /// the new one as G P G^T on the robot's rows (docs/derivations/state_space_jacobians.md); none
    /// for an additive chart, where G = I.
    std::optional<Eigen::Matrix<double, X, X>> reset;
  };

  static Eigen::Index offset_of(std::size_t slot) { return LandmarkStore<M>::template offset_of<X>(slot); }
  LandmarkEstimate<M> landmark_at(std::size_t slot) const;
  Landmark landmark_mean(std::size_t slot) const { return landmarks_.mean(slot); }

  /// Everything one update will change, computed without touching the state.
  struct Plan {
    std::optional<Correction> correction;
    std::vector<std::pair<LandmarkId, Init>> new_landmarks;
  };

  /// The observations the model can use here; the others go to result.unusable.
  std::vector<Linearized> linearize(std::span<const ObservationType> known, UpdateResult& result) const;
  std::optional<Linearized> linearize_at(const ObservationType& observation, std::size_t slot, const State& x,
                                         const Landmark& m, std::vector<LandmarkId>& unusable) const;
  Eigen::Matrix<double, Eigen::Dynamic, Z> cross_covariance(const Linearized& obs) const;
  /// H_i C: observation i's Jacobian applied to C (rows of the stacked state), from the robot and
  /// landmark rows only.
  template <class Matrix>
  static Eigen::Matrix<double, Z, Eigen::Dynamic> jacobian_times(const Linearized& obs, const Matrix& C) {
    return obs.J_z_x * C.template topRows<X>() + obs.J_z_m * C.template middleRows<M>(obs.offset);
  }
  void gate(std::vector<Linearized>& observations, UpdateResult& result) const;
  /// with_covariance = false: the mean's correction only (delta, x), for the iterated EKF's iterates.
  Correction compute_correction(const std::vector<Linearized>& observations, bool with_covariance = true) const;
  /// The iterated EKF (EkfOptions::iterations): `observations` relinearized at its iterates.
  void relinearize_at_iterates(std::span<const ObservationType> known, std::vector<Linearized>& observations) const;
  /// The observations relinearized at the robot and landmarks `correction` moves to, their residual
  /// referred back to the prior (z - h(x_i) + H_i delta_i); none when one of them is not observable there.
  std::optional<std::vector<Linearized>> relinearize(std::span<const ObservationType> known,
                                                     const std::vector<Linearized>& observations,
                                                     const Correction& correction) const;
  Eigen::MatrixXd joseph_covariance(const std::vector<Linearized>& observations, const Eigen::MatrixXd& K) const;
  Plan plan(std::span<const ObservationType> known, std::span<const ObservationType> fresh, UpdateResult& result) const;
  /// update() without re-acquisition: the EKF's correction and augmentation (eqs. 14-17).
  UpdateResult correct_and_augment(std::span<const ObservationType> observations);
  using Reacquisition = PoseReacquisition<Space, Sensor, State, X>;
  using Recovery = LostPoseRecovery<EkfSlam, Reacquisition>;
  friend Recovery;
  std::vector<typename Reacquisition::Sighting> rejected_sightings(std::span<const ObservationType> observations,
                                                                   const UpdateResult& result) const;
  void commit(const Plan& plan);
  void apply(const Correction& correction);
  template <class Lower>
  static void reset_robot_tangent(Lower& P, const Eigen::Matrix<double, X, X>& G);
  void augment(LandmarkId id, const Init& init);

  Motion motion_;
  Sensor sensor_;
  EkfOptions options_;
  InnovationGate gate_;
  State x_;
  State propagated_;  ///< the robot state after the last prediction (observability constraints)
  LandmarkStore<M> landmarks_;  ///< ids, slots, means and first means (first_estimate_jacobians)
  GrowableSquareMatrix cov_;     ///< P; only its lower triangle is kept up to date
  Recovery recovery_;  ///< re-acquisition of a lost pose (off unless options_.reacquisition says)
};

}  // namespace sextant

#include "sextant/backends/detail/ekf_slam_impl.hpp"
#include "sextant/backends/detail/ekf_reacquisition_impl.hpp"

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_EKF_SLAM
#include "sextant/compiled/extern_instances.hpp"
