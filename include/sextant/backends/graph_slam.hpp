#pragma once
/// \file GraphSLAM (thesis §3.6, Appendix B): full SLAM over every pose and landmark in information
/// form, for any motion and measurement model pair.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/backend_types.hpp"
#include "sextant/core/landmark_store.hpp"
#include "sextant/core/rollback_guard.hpp"
#include "sextant/core/concepts.hpp"
#include "sextant/core/factor_information.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/landmark_pool.hpp"
#include "sextant/core/robust_kernel.hpp"
#include "sextant/core/selected_inverse.hpp"
#include "sextant/core/sparse_cholesky.hpp"
#include "sextant/core/state_space.hpp"
#include "sextant/core/update_result.hpp"
#include "sextant/core/versioned_cache.hpp"
#include "sextant/backends/detail/graph_slam_online_state.hpp"
#include "sextant/backends/detail/graph_slam_lag_state.hpp"

namespace sextant {

/// How the linearized system is solved in each Gauss-Newton iteration.
enum class GraphSolver {
  /// The thesis (eqs. 66-73): eliminate every landmark by its own Schur complement, solve the
  /// reduced pose system by sparse Cholesky, then recover the landmarks.
  landmark_schur,
  /// Sparse Cholesky of the whole system (poses and landmarks) with a fill-reducing ordering:
  /// better when landmarks are seen from many poses spread along the trajectory (the Schur
  /// complement then fills in): 8x faster on the ship, 10x on cityTrees10000.
  full,
  /// landmark_schur when the landmark variables outnumber the pose variables (many short-lived
  /// features, as in visual SLAM), full otherwise.
  automatic,
};

struct GraphOptions {
  /// Iterations at most; the tolerances below end a converging optimization long before (every
  /// GraphSLAM row of the main table, the globe, Victoria Park: within 10). Robust kernels (iteratively
  /// reweighted) and far starts converge slowly: MRCLAM robot 3 with the Cauchy kernel needs more than 30.
  int max_iterations = 100;
  double step_tolerance = 1e-8;             ///< stop when max |delta| falls below this
  double relative_cost_tolerance = 1e-10;   ///< stop when |chi2 change| / chi2 falls below this
  GraphSolver solver = GraphSolver::automatic;
  bool levenberg_marquardt = false;  ///< damp the steps (lambda diag(Omega)); rejected steps count as iterations
  double initial_lambda = 1e-4;
  /// Gauss-Newton (levenberg_marquardt = false) of the whole graph: at the first iteration whose cost
  /// rises, go back to the iterate before it and go on damped as Levenberg-Marquardt from initial_lambda,
  /// which never moves to a higher cost, so that the optimization descends from there (a far start, a
  /// robust kernel's reweighting). Where Gauss-Newton descends, as on every data set of the main table,
  /// nothing changes. The windowed initialization's sub-parts stay plain: their few iterations find a
  /// start, and damped they left Victoria Park's (window 1000) too far from it to converge in 100.
  /// false: plain Gauss-Newton to the end, keeping its lowest-cost iterate.
  bool damp_after_rise = true;
  std::size_t window = 0;      ///< thesis §4.2.2: before the first full optimization, optimize growing
                               ///< sub-parts of `window` steps (0 = dead-reckoning initialization only)
  int window_iterations = 5;   ///< Gauss-Newton iterations per sub-part
  /// On measurement factors (outliers of a real sensor): Huber or Cauchy by iteratively reweighted
  /// Gauss-Newton (core/robust_kernel.hpp); none = plain least squares. Motion factors stay quadratic.
  RobustLoss measurement_loss{};
  /// Online mode (docs/derivations/incremental_graph_slam.md): every update() adds the frame's factors
  /// to the reduced pose system, refactorizes it from the oldest pose they reach (core/profile_cholesky.hpp)
  /// and takes one Gauss-Newton step, so that pose() and map() are smoothed after every frame.
  bool incremental = false;
  /// Online mode: a variable is relinearized when its step from its linearization point exceeds this
  /// share of its standard deviation in some coordinate: a pose's as it entered the graph (dead
  /// reckoning from the previous estimate), a landmark's given the poses (its information diagonal).
  double relinearize_threshold = 0.1;
  /// Fixed-lag mode (docs/derivations/fixed_lag_graph_slam.md; turns the online mode on): every update()
  /// takes one Gauss-Newton step over the newest `lag` poses and the landmarks they see, everything
  /// older marginalized into one dense prior, so that a frame costs the same however long the tracks
  /// and the trajectory (approximate: marginalized variables keep the estimate they left with). 0: the
  /// exact online mode above.
  std::size_t lag = 0;
  /// Fixed-lag mode: a landmark seen again after it left the window comes back with the marginal it
  /// left with as a prior (true), or from the window's measurements alone (false). The marginal has
  /// lost its correlation with the poses and landmarks marginalized with it, so re-using it counts the
  /// closure's information twice: on the default globe (lag 10) pose NEES inside its 95% bound at 66%
  /// of the frames with it, 98% without, position 2.89 against 2.94 mm (docs/results/real_time.md).
  bool reuse_retired_marginals = false;
};

/// What optimize() reports.
struct OptimizationSummary {
  int iterations = 0;
  std::vector<double> cost;   ///< chi2 at the start and after every iteration
  std::vector<double> seconds;  ///< time since optimize() began at each entry of cost
  bool converged = false;
  double seconds_linearize = 0.0, seconds_eliminate = 0.0, seconds_solve = 0.0, seconds_recover = 0.0;
  /// Measurement factors the model could not evaluate at the final estimate (unobservable_error, e.g.
  /// a landmark behind the camera), left out of the last linearization.
  std::size_t unobservable_factors = 0;
  /// The iteration whose estimate optimize() kept (0: the start): the last one unless an earlier one
  /// had the lower cost (Gauss-Newton need not descend; Levenberg-Marquardt always keeps the last).
  int best_iteration = 0;
  /// Gauss-Newton with damp_after_rise: the iteration whose cost rose (its step undone), after which the
  /// steps were damped; -1 where none rose.
  int damped_from = -1;
};

/// GraphSLAM: records the prior, every motion and every measurement through the filters' face
/// (predict/update), and optimize() solves for all poses and landmarks by Gauss-Newton,
/// relinearizing until the step or the cost change is small. New poses start at dead reckoning,
/// new landmarks at the inverse measurement model. Marginal covariances of every pose and landmark
/// come from a selected inversion of the sparse information matrix.
/// Threads: const methods (pose(), map(), landmark(), ...) may be called from several threads
/// at once on one estimator; a non-const one (predict, update, remove_landmark, optimize, warm_start) must not overlap any other call on it.
/// Independent estimators share nothing (tests/backends/concurrent_reads_test.cpp, under
/// ThreadSanitizer with ./run.sh test-tsan).
template <class Motion, class Sensor>
class GraphSlam {
  static_assert(ModelsFit<Motion, Sensor>::value, "GraphSlam: the models do not fit (see the message above)");

 public:
  SEXTANT_BACKEND_TYPES;

  GraphSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, GraphOptions options = {});

  /// Adds a pose x_{k+1} = g(x_k, u, dt) and its motion factor (eqs. 60-61).
  void predict(const Control& u, double dt);
  /// Adds measurement factors at the newest pose (eqs. 62-63); new landmarks start at the inverse model.
  UpdateResult update(std::span<const ObservationType> observations);
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }

  /// Gauss-Newton over all poses and landmarks. Throws numerical_error (estimate unchanged) when
  /// a noise matrix or the information matrix is not positive definite.
  OptimizationSummary optimize();

  /// Marginalizes a landmark: its factors become one linear factor over the poses that saw it.
  void remove_landmark(LandmarkId id);

  /// Replaces the current estimate before optimize() (e.g. with a filter's trajectory and map): every
  /// pose, and the landmarks `map` lists; every other landmark starts again where update() started
  /// it, at the inverse model of its first measurement, now from the new pose (a filter that keeps a
  /// pool of landmarks no longer holds most of them at the end), or keeps its mean where the model
  /// cannot place it from there (unobservable_error).
  void warm_start(std::span<const State> poses, const MapEstimate& map);

  /// The newest pose, O(1): its current mean, and as covariance its exact marginal as of the last
  /// optimize(), propagated by the motion model (G P G^T + R) through the poses added since, the
  /// uncertainty of the dead-reckoned mean that pose holds until the next optimize(). Measurements
  /// recorded since the last optimize() do not shrink it. trajectory() gives exact marginals.
  /// Online mode: after each update() the mean is the step's estimate and the covariance the newest
  /// pose's marginal in the linearized system (one block of the incremental factor).
  /// Every pose estimate is given in its space's canonical coordinates (in_canonical_coordinates).
  PoseEstimate pose() const { return in_canonical_coordinates<Space>(PoseEstimate{poses_.back(), newest_cov_}); }
  /// Every pose x_0 .. x_K with its marginal covariance.
  std::vector<PoseEstimate> trajectory() const;
  LandmarkEstimate<M> landmark(LandmarkId id) const;
  MapEstimate map() const;
  /// Every landmark's id and mean, O(n): map() without the selected inversion its covariances need
  /// (which costs much more when landmarks are seen from many poses, as in visual SLAM).
  std::vector<std::pair<LandmarkId, Landmark>> landmark_means() const {
    return landmarks_.id_mean_pairs([&](std::size_t slot) { return landmark_mean(slot); });
  }
  bool has_landmark(LandmarkId id) const { return landmarks_.contains(id); }
  std::size_t num_landmarks() const { return landmarks_.size(); }
  std::size_t num_poses() const { return poses_.size(); }
  const std::vector<LandmarkId>& landmark_ids() const { return landmarks_.ids(); }
  const std::vector<State>& pose_means() const { return poses_; }
  /// chi2 of all factors at the current estimate.
  double cost() const;
  /// The information matrix of all poses then all landmarks (slot order) at the current estimate.
  Eigen::SparseMatrix<double> information_matrix() const;
  const GraphOptions& options() const { return options_; }
  /// Symbolic analyses done by the sparse solver so far (it keeps one while the pattern is unchanged).
  int symbolic_analyses() const { return solver_.analyses(); }
  /// Online mode: what the last update() did (rows refactorized, variables relinearized); fixed-lag
  /// mode: first_row is the step's oldest pose, linearized_landmarks the landmarks in its window.
  const OnlineStepSummary& last_online_step() const { return online_.last_step; }

 private:
  struct MotionRecord {
    Control u;
    double dt;
  };
  struct MeasurementRecord {
    std::size_t pose;
    Measurement z;
    double noise_scale;  ///< Observation::noise_scale
  };
  /// A marginalized landmark: 1/2 d^T Lambda d - eta^T d over the stacked d = minus(x_p, linearization_p).
  struct LinearFactor {
    std::vector<std::size_t> poses;
    std::vector<State> linearization;
    Eigen::MatrixXd Lambda;
    Eigen::VectorXd eta;
  };
  struct Linearization;  // defined in the implementation
  struct BestIterate;    // defined in the implementation
  using Online = OnlineGraphState<X, M, State>;
  struct PriorInformation {
    Eigen::Matrix<double, X, X> Lambda;
    Eigen::Matrix<double, X, 1> g;
    double cost;
  };

  template <class Inits>
  void record_measurements(std::size_t pose, const std::vector<const ObservationType*>& used, const Inits& inits);
  BetweenFactor<X> motion_factor(std::size_t k, const State& from, const State& to) const;
  FactorInformation<X, X> motion_information(std::size_t k, const State& from, const State& to) const;
  PriorInformation prior_information_at(const State& x0) const;
  template <class PoseAt>
  typename Online::PoseFactor marginal_information(const LinearFactor& factor, PoseAt&& pose_at) const;
  std::optional<FactorInformation<X, M>> measurement_information(std::size_t slot, const MeasurementRecord& record, const State& x,
                                                                 const Landmark& m) const;
  template <int D>
  static void require_factorizable_extension(const Eigen::Matrix<double, X, X>& P, const Eigen::Matrix<double, D, X>& J,
                                             const Eigen::Matrix<double, D, D>& C, const std::string& what);
  Linearization linearize(std::size_t pose_count) const;
  void add_prior_factor(Linearization& sys) const;
  void add_motion_factors(Linearization& sys) const;
  void add_marginal_factors(Linearization& sys) const;
  void add_measurement_factors(Linearization& sys) const;
  auto predict_if_observable(const State& x, const Landmark& m) const
      -> std::optional<decltype(std::declval<const Sensor&>().predict(x, m))>;
  Eigen::VectorXd solve_by_landmark_schur(const Linearization& system, OptimizationSummary& summary) const;
  Eigen::VectorXd solve_full(const Linearization& system, OptimizationSummary& summary) const;
  Eigen::VectorXd solve(const Linearization& system, double lambda, OptimizationSummary& summary) const;
  void apply(const Linearization& system, const Eigen::VectorXd& delta);
  OptimizationSummary gauss_newton(std::size_t pose_count, int max_iterations, Linearization* final_system = nullptr,
                                   bool damp_after_rise = false);
  void reinitialize_after(std::size_t pose_count);
  void initialize_in_windows();
  std::shared_ptr<const SelectedInverse> marginals() const;
  bool uses_landmark_schur(const Linearization& system) const;
  Eigen::Matrix<double, X, X> newest_pose_marginal(const Linearization& system);
  Landmark landmark_mean(std::size_t slot) const { return landmarks_.mean(slot); }
  void touch() { ++revision_; }
  // Online mode (graph_slam_online_impl.hpp)
  struct OnlinePlan;
  void step_online(const std::vector<std::size_t>& touched_slots);
  void plan_linearization_points(OnlinePlan& plan) const;
  void plan_pose_factors(OnlinePlan& plan) const;
  void stage_online_factors(OnlinePlan& plan);
  void plan_estimate(OnlinePlan& plan, const Eigen::VectorXd& delta_poses) const;
  void commit_online_step(OnlinePlan& plan);
  typename Online::LandmarkLinearization linearize_landmark_online(std::size_t slot, const OnlinePlan& plan) const;
  typename Online::PoseFactor linearize_pose_factor_online(const typename Online::PoseFactor& which,
                                                           const OnlinePlan& plan) const;
  void restart_online() { online_ = Online{}; }
  LinearFactor marginal_factor(std::size_t slot) const;
  template <class PoseAt>
  LinearFactor eliminated_landmark_factor(const std::vector<typename Online::Term>& terms,
                                          const Eigen::LLT<Eigen::Matrix<double, M, M>>& H, const Landmark& b_j,
                                          PoseAt&& pose_at) const;
  void remove_landmark_online(std::size_t slot, std::optional<typename Online::PoseFactor> held);
  // Fixed-lag mode (graph_slam_lag_impl.hpp)
  using Lag = FixedLagState<X, M, State>;
  using LagSys = LagSystem<X, M>;
  using LagSolve = LagSolution<X, M>;
  struct LagEstimate;
  struct LagPlan;
  std::vector<std::size_t> lag_slots(const std::vector<std::size_t>& touched_slots) const;
  void add_lag_prior(LagSys& sys, const LagEstimate& at, const typename Lag::Prior& prior) const;
  void add_lag_pose_prior(LagSys& sys, const LagEstimate& at) const;
  void add_lag_motion(LagSys& sys, const LagEstimate& at, std::size_t k) const;
  void add_lag_measurements(LagSys& sys, const LagEstimate& at, std::size_t slot, std::size_t from,
                               std::size_t to) const;
  void add_retired_prior(LagSys& sys, const LagEstimate& at, std::size_t slot, const Lag& window) const;
  LagSys lag_system(const std::vector<std::size_t>& slots, const LagEstimate& at, MatrixWorkspace& memory) const;
  std::string lag_variable_at(const LagSys& sys, Eigen::Index row) const;
  typename Lag::Prior marginalized_prior(std::optional<std::size_t> pose, const std::vector<std::size_t>& slots,
                                            const LagEstimate& at, const Lag& window, MatrixWorkspace& memory) const;
  void slide_window(LagPlan& plan, const std::vector<std::size_t>& slots, const LagSys& sys,
                    const LagSolve& solved, MatrixWorkspace& memory) const;
  bool in_lag_prior(std::size_t slot) const;
  void step_lag(const std::vector<std::size_t>& touched_slots);
  Lag lag_without(std::size_t slot, MatrixWorkspace& memory) const;

  Motion motion_;
  Sensor sensor_;
  GraphOptions options_;
  PoseEstimate prior_;
  Eigen::Matrix<double, X, X> prior_information_;
  std::vector<State> poses_;
  std::vector<MotionRecord> motions_;                          ///< motions_[k]: pose k -> k + 1
  std::vector<std::vector<MeasurementRecord>> measurements_;   ///< per landmark slot
  std::vector<LinearFactor> linear_factors_;
  LandmarkStore<M> landmarks_;
  bool windows_done_ = false;
  std::uint64_t revision_ = 0;
  Eigen::Matrix<double, X, X> newest_cov_;  ///< see pose()
  std::vector<Eigen::Matrix<double, X, 1>> entry_sigma_;  ///< each pose's standard deviations as it was added (online mode)
  /// Keeps the symbolic analysis while the pattern is unchanged (non-const paths only). CHOLMOD chooses
  /// simplicial or supernodal by the factor's fill, as for pose graphs and as Ceres lets it: the
  /// whole system's factor is sparse on the ship and cityTrees (2.5-2.9x and 3.2-3.5x faster than
  /// supernodal on the same assembly);
  /// the globe's systems and the ship's landmark Schur complement took the same time either way
  /// (docs/benchmarks.md, "GraphSLAM vs Ceres").
  mutable SparseCholesky solver_{SparseCholesky::Factorization::by_fill};
  VersionedCache<SelectedInverse> marginals_;  ///< at revision_ (thread-safe)
  Online online_;  ///< the incrementally factorized reduced system (online mode)
  Lag lag_;  ///< the window's prior and retired landmarks (fixed-lag mode)
  LagScratch lag_scratch_;  ///< the fixed-lag step's dense blocks (scratch)
};

}  // namespace sextant

#include "sextant/backends/detail/graph_slam_impl.hpp"
#include "sextant/backends/detail/graph_slam_online_impl.hpp"
#include "sextant/backends/detail/graph_slam_lag_impl.hpp"

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_GRAPH_SLAM
#include "sextant/compiled/extern_instances.hpp"
