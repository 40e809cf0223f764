#pragma once
/// \file FastSLAM 1.0 and 2.0 (thesis §3.7; Montemerlo et al.), a Rao-Blackwellized particle filter,
/// for any motion and measurement model pair.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <unordered_map>
#include <vector>

#include "sextant/core/backend_types.hpp"
#include "sextant/core/landmark_pool.hpp"
#include "sextant/core/chi_square.hpp"
#include "sextant/core/concepts.hpp"
#include "sextant/core/conditionally_linear.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/innovation_gate.hpp"
#include "sextant/core/particle_path.hpp"
#include "sextant/core/persistent_array.hpp"
#include "sextant/core/student_t.hpp"
#include "sextant/core/update_result.hpp"

namespace sextant {

enum class FastSlamVersion {
  v1,  ///< sample the pose from the motion model (eq. 74); weight by the measurement likelihood (eqs. 79-81)
  v2,  ///< sample from a proposal that folds in the measurements (eqs. 82-92); weight by eq. 93
};

/// Where map() takes its landmarks from.
enum class FastSlamMap {
  best_particle,     ///< the particle with the largest weight
  weighted_average,  ///< per landmark, the moment-matched mixture over all particles
};

/// What a particle does with the trailing state entries its motion model declares conditionally linear
/// (core/conditionally_linear.hpp; e.g. the 12D camera's velocity and angular rate). Models without
/// such entries behave the same either way.
enum class FastSlamLinearTail {
  sampled,  ///< sampled with the rest of the state, as FastSLAM does (the default: steadier at 100 particles)
  kalman,   ///< kept as a Kalman filter given the particle's sampled path (a marginalized particle filter)
};

struct FastSlamOptions {
  std::size_t particles = 50;
  FastSlamVersion version = FastSlamVersion::v2;
  double resample_threshold = 0.5;  ///< resample when N_eff < threshold * particles (1 = always, 0 = never)
  FastSlamMap map_estimate = FastSlamMap::best_particle;
  std::uint64_t seed = 1;
  /// Per-particle data association (update_unassociated): a measurement whose smallest normalized
  /// innovation squared over a particle's landmarks exceeds this starts a new landmark there.
  /// 0 (the default) = the chi-square quantile at 0.9999 for the measurement's dimension (2: 18.42,
  /// 3: 21.11, 4: 23.51); at 0.99 one re-observation in a hundred would become a duplicate (seen on
  /// the ship, where a 2-3 sigma compass error happens every few dozen steps).
  double new_landmark_nis = 0.0;
  /// Ids given to the landmarks that particles create in update_unassociated: first, first + 1, ...
  /// A landmark keeps its id in every particle that descends from the one that created it.
  LandmarkId first_unassociated_id = LandmarkId{1} << 62;
  /// In (0, 1): an observation of a known landmark whose innovation fails the chi-square test
  /// (core/innovation_gate.hpp) against the cloud's predictive distribution (the particles' mixture,
  /// moment-matched: accepted_by_cloud) is used by no particle and weighs on none;
  /// UpdateResult::rejected lists them. Per particle, a particle would ignore what refutes it. 0 = off.
  double gate_probability = 0.0;
  /// docs/results/globe.md measures both on the 12D camera.
  FastSlamLinearTail linear_tail = FastSlamLinearTail::sampled;
  /// FastSLAM 2.0's proposal iterated (EkfOptions::iterations' Gauss-Newton over a particle's pose
  /// and the landmarks the step sees, these marginalized): up to this many linearizations of the
  /// step's paired measurements, each at the previous pass's pose and the landmarks' means given it.
  /// 1 = the textbook proposal, each measurement linearized where the ones before it moved the mean.
  /// update_unassociated associates in the first pass and iterates what it paired. It matters where
  /// a landmark is close to the sensor compared with the pose's spread (docs/results/iterated_ekf.md).
  int iterations = 1;
  /// Degrees of freedom nu of the measurement noise as a Student-t (core/student_t.hpp: heavy tails,
  /// gross outliers): each observation of a known or associated landmark updates with its noise Q
  /// scaled by (nu + NIS) / (nu + d), NIS against the innovation covariance S of that update, and
  /// weighs on its particle by the t density with scale S instead of the Gaussian's, so that one
  /// sighting far off its landmark neither drags the pose and landmark nor kills the particle that has
  /// them right. The new-landmark weight takes the same density. 0 (the default) = Gaussian.
  double student_t_dof = 0.0;
  /// Keep each particle's path (core/particle_path.hpp) for path_posterior(), FastSLAM's estimate of
  /// the whole path given every measurement so far. Off: no path is kept and a step costs nothing
  /// more. On: one pose per particle a step, shared between copies (memory ~ steps + particles x the
  /// depth where their ancestries meet).
  bool keep_paths = false;
};

/// One landmark of one particle: an EKF over its position (eqs. 75-78).
template <int M>
struct LandmarkGaussian {
  Eigen::Matrix<double, M, 1> mean = Eigen::Matrix<double, M, 1>::Zero();
  Eigen::Matrix<double, M, M> cov = Eigen::Matrix<double, M, M>::Identity();
  bool alive = true;  ///< false once removed
  LandmarkId id = 0;  ///< the landmark's id (for landmarks a particle created by its own association)
};

/// FastSLAM: N particles, each a pose and a map of independent landmark EKFs. `Map` holds a
/// particle's landmarks: PersistentArray (default) shares them between particles after resampling;
/// CopiedArray copies them (O(J) per copy), for comparison.
/// Threads: const methods (pose(), map(), landmark(), effective_sample_size(), ...) may be called from several threads
/// at once on one estimator; a non-const one (predict, update, remove_landmark) must not overlap any other call on it.
/// Independent estimators share nothing (tests/backends/concurrent_reads_test.cpp, under
/// ThreadSanitizer with ./run.sh test-tsan).
template <class Motion, class Sensor, template <class> class Map = PersistentArray>
class FastSlam {
  static_assert(ModelsFit<Motion, Sensor>::value, "FastSlam: the models do not fit (see the message above)");

 public:
  SEXTANT_BACKEND_TYPES;

  /// Trailing state entries the motion model declares conditionally linear (core/conditionally_linear.hpp):
  /// with FastSlamLinearTail::kalman each particle keeps them as a Kalman filter given its sampled
  /// path instead of sampling them.
  static constexpr int T = conditionally_linear_dims_v<Motion>;

  struct Particle {
    State x;  ///< the sampled entries, and the tail's mean given them
    /// Covariance of the conditionally linear tail given the sampled entries (zero outside it; all
    /// zero for a model without a tail).
    Eigen::Matrix<double, X, X> cov = Eigen::Matrix<double, X, X>::Zero();
    Map<LandmarkGaussian<M>> landmarks;  ///< indexed by the filter's landmark index (known ids)
    Map<LandmarkGaussian<M>> unassociated;  ///< landmarks this particle found by its own association
    double log_weight = 0.0;
    /// The Gaussian x was drawn from where the particle's weight does not depend on the draw (the
    /// prior, FastSLAM 2.0's proposal, eqs. 82-93): pose() averages these instead of the draws
    /// (Rao-Blackwellized). Where the weight does depend on it (FastSLAM 1.0), x itself with the
    /// tail's covariance.
    State drawn_from;
    Eigen::Matrix<double, X, X> drawn_cov = Eigen::Matrix<double, X, X>::Zero();
    std::size_t ancestor = 0;  ///< which of the first step's particles this one descends from
    /// After each step from the prior on, the Gaussian the particle's pose was drawn from (drawn_from
    /// and drawn_cov after the step's update; after a predict, the motion's prediction) rather than
    /// the draw, whose spread path_posterior() would only add as noise (options().keep_paths; empty
    /// otherwise).
    ParticlePath<PoseEstimate> path;
    /// x is a point from here on: its weight is about to depend on the draw.
    void forget_proposal() {
      drawn_from = x;
      drawn_cov = cov;
    }
  };

  FastSlam(Motion motion, Sensor sensor, const PoseEstimate& prior, FastSlamOptions options = {});

  /// FastSLAM 1.0 samples every particle's pose here; 2.0 only predicts the mean and samples in
  /// update(), where the measurements shape the proposal. FastSLAM 2.0's weight (eq. 93) depends on
  /// the particle before the draw, so update() weighs and resamples the cloud first and each copy of
  /// a particle then draws its own pose from the proposal (the fully adapted order, Pitt and
  /// Shephard 1999; docs/results/fastslam_gap.md): resampling never leaves identical copies.
  void predict(const Control& u, double dt);
  /// Observations with known landmark ids; new ids are added to every particle.
  UpdateResult update(std::span<const ObservationType> observations);
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }
  /// Measurements without ids: each particle associates them to its own landmarks by maximum
  /// likelihood, or starts new ones (thesis §7.2). A new landmark gets the next id from
  /// options().first_unassociated_id on; `initialized` counts those of the most likely particle,
  /// whose landmarks map() lists beside the known ones. `most_likely`, when given, receives per
  /// measurement the id of the landmark that particle paired it with or started for it (the
  /// association a run with the ids withheld is scored by; eval/particle_association.hpp).
  UpdateResult update_unassociated(std::span<const Measurement> measurements,
                                   std::vector<LandmarkId>* most_likely = nullptr);

  void remove_landmark(LandmarkId id);

  /// The weighted mixture of the particles' pose Gaussians (tangent space around the best particle):
  /// FastSLAM 2.0's proposals after an update (Particle::drawn_from), each particle's motion
  /// prediction after a predict, and FastSLAM 1.0's points; the covariance is the mixture's (within
  /// plus between particles). Taken after the last update and before its resampling, which would
  /// duplicate particles and shrink the spread.
  PoseEstimate pose() const;
  /// How many particles pose()'s covariance rests on where the particles are points in their sampled
  /// entries (FastSLAM 1.0, whose weights depend on the draws): 1 / sum of the squared weights, the
  /// particles at one pose counted as one. Below the pose's dimension + 1 that covariance is a sample
  /// too small to span the pose's directions, and its NEES measures the sample, not the filter.
  /// +inf where every particle reports a Gaussian (FastSLAM 2.0's proposals, a predict's motion, the
  /// dead-reckoned frame before the first landmark).
  double pose_sample_support() const;
  /// FastSLAM's estimate of the path (options().keep_paths): entry 0 the prior, entry k the pose
  /// after the k-th step, each the weighted mixture, over today's particles, of the pose their
  /// ancestor had then (Montemerlo et al. 2002: the particles sample the path posterior; the weights
  /// of the last step weigh every earlier pose of a path). The frame's uncertainty of today is added
  /// to each. `support` is 1 / sum of the squared weights of the distinct ancestors at each step: 1
  /// where every path runs through one ancestor (path degeneracy), the covariance there being that
  /// one ancestor's proposal alone.
  struct PathPosterior {
    std::vector<PoseEstimate> poses;
    std::vector<double> support;
  };
  PathPosterior path_posterior() const;
  MapEstimate map() const;
  LandmarkEstimate<M> landmark(LandmarkId id) const;
  bool has_landmark(LandmarkId id) const;
  std::size_t num_landmarks() const;
  std::vector<LandmarkId> landmark_ids() const;
  const std::vector<Particle>& particles() const { return particles_; }
  /// Normalized weights of the particles.
  std::vector<double> weights() const;
  /// Effective sample size 1 / sum w^2 of the normalized weights.
  double effective_sample_size() const;
  /// How many of the first step's particles the cloud descends from: 1 means every path shares one
  /// ancestor (the path degeneracy that makes FastSLAM inconsistent over long runs).
  std::size_t distinct_ancestors() const;
  std::size_t resamplings() const { return resamplings_; }
  const FastSlamOptions& options() const { return options_; }

 private:
  struct PendingMotion {
    Control u;
    double dt;
  };

  /// What a step commits at its end: particles, random engine and estimate move together.
  struct Transaction {
    std::vector<Particle> particles;
    std::mt19937_64 rng;
    std::optional<PoseEstimate> estimate;
    double support;  ///< pose_sample_support() of `estimate`
    std::vector<PendingMotion> pending;
    LandmarkId next_unassociated_id;
    bool resampled = false;
    Eigen::Matrix<double, X, X> frame_cov;
    bool frame_fixed;
    std::size_t best;  ///< the most likely particle (see best_)
  };
  Transaction begin() const {
    return {particles_, rng_, estimate_, support_, pending_, next_unassociated_id_, false, frame_cov_, frame_fixed_, best_};
  }
  /// Before the first landmark the particles would differ only by where they put the map (a rigid
  /// motion no later measurement can see): they move together at the dead-reckoned mean, and the
  /// spread they would have had is kept as frame_cov_, the uncertainty of the map's frame.
  void predict_without_map(const Control& u, double dt);
  void fix_frame_if_mapped(Transaction& t) const;
  void commit(Transaction&& t);
  /// With options().keep_paths: each particle's path gains its pose after a predict (extend), or its
  /// last pose becomes the one the update drew (settle).
  void extend_paths(Transaction& t, const std::vector<PoseEstimate>& components) const;
  void settle_paths(Transaction& t) const;

  /// The particle after a draw from N(mean, cov): its sampled entries drawn, its tail kept Gaussian.
  void draw_into(Particle& particle, const PoseEstimate& gaussian, std::mt19937_64& rng) const;
  bool keeps_tail() const { return T > 0 && options_.linear_tail == FastSlamLinearTail::kalman; }
  /// Cov(tail | rest) of a Gaussian over the state where the particles keep a tail, else zero.
  Eigen::Matrix<double, X, X> kept_tail(const Eigen::Matrix<double, X, X>& cov) const;
  /// N(g(x, u), G C G^T + R) for a particle at x whose tail has covariance C (checked prediction).
  PoseEstimate motion_gaussian(const State& x, const Eigen::Matrix<double, X, X>& cov, const Control& u, double dt) const;
  void apply_pending_motion_v1(Transaction& t) const;
  /// What became of one observation in one particle.
  enum class Outcome : char { used, gated, unusable };
  /// What one landmark update adds to the particle's log weight, and what became of the observation.
  struct LandmarkUpdate {
    double log_likelihood;
    Outcome outcome;
  };
  using PoseMatrix = Eigen::Matrix<double, X, X>;
  static constexpr std::size_t kNewLandmark = ~std::size_t{0};  ///< association: no landmark, start one
  using Prediction = decltype(std::declval<const Sensor&>().predict(std::declval<const State&>(), std::declval<const Landmark&>()));
  /// What an update makes of an innovation nu with covariance S whose noise part is Q: its NIS
  /// against S, the factor c on Q (1 for Gaussian noise; FastSlamOptions::student_t_dof), the
  /// Cholesky factor of the covariance the update uses, S + (c - 1) Q, and the observation's log
  /// likelihood against S (its factor of the particle's weight).
  struct WeighedInnovation {
    double nis;
    double noise_factor;
    Eigen::LLT<Eigen::Matrix<double, Z, Z>> llt;
    double log_likelihood;
  };
  WeighedInnovation weigh_innovation(const Eigen::Matrix<double, Z, Z>& S, const Eigen::Matrix<double, Z, 1>& nu,
                                     const Eigen::Matrix<double, Z, Z>& Q, const char* what) const;
  /// A measurement of a landmark against the Gaussian proposal of the pose (FastSLAM 2.0), weighed
  /// with S = H_x Sigma H_x^T + H_m Sigma_m H_m^T + Q.
  struct ProposalInnovation {
    Prediction prediction;
    Eigen::Matrix<double, Z, 1> nu;
    WeighedInnovation weighed;
  };
  auto predict_if_observable(const State& x, const Landmark& m, double noise_scale) const -> std::optional<Prediction>;
  std::vector<ObservationType> add_new_landmarks(std::vector<Particle>& particles, std::span<const ObservationType> fresh,
                                                 std::vector<LandmarkId>& unusable) const;
  LandmarkUpdate update_landmark(Particle& particle, std::size_t index, const Measurement& z, double noise_scale,
                                 bool unassociated) const;
  ProposalInnovation proposal_innovation(Prediction prediction, const PoseMatrix& cov, const LandmarkGaussian<M>& landmark,
                                         const Measurement& z, const Eigen::Matrix<double, Z, 1>& offset) const;
  static Eigen::Matrix<double, Z, Z> proposal_covariance(const Prediction& prediction, const PoseMatrix& cov,
                                                         const LandmarkGaussian<M>& landmark);
  static constexpr const char* kProposalS = "proposal innovation covariance";
  static double fold_into_proposal(State& mean, PoseMatrix& cov, const ProposalInnovation& innovation);
  std::vector<Outcome> propose_v2(Particle& particle, const PoseEstimate& prior, std::span<const ObservationType> known,
                                  const std::vector<bool>& accepted) const;
  /// Where a pass of the iterated proposal linearizes: a pose, and per measurement its landmark.
  struct ProposalLinearization {
    State x;
    std::vector<Landmark> m;
  };
  /// A Gaussian proposal of a particle's pose, the particle's log weight with it, and (iterated) where
  /// the next pass linearizes.
  struct FoldedProposal {
    State mean;
    PoseMatrix cov;
    double log_weight;
    ProposalLinearization next;
  };
  std::optional<FoldedProposal> fold_proposal(double log_weight, const PoseEstimate& prior,
                                              std::span<const ObservationType> known,
                                              std::span<const LandmarkGaussian<M>* const> landmarks,
                                              std::vector<Outcome>& outcomes, const ProposalLinearization* at) const;
  FoldedProposal iterated_proposal(double log_weight, const PoseEstimate& prior,
                                   std::span<const ObservationType> observations,
                                   std::span<const LandmarkGaussian<M>* const> landmarks,
                                   std::vector<Outcome>& outcomes) const;
  FoldedProposal iterated_proposal_of_matches(const Particle& particle, double log_weight, const PoseEstimate& prior,
                                              std::span<const Measurement> measurements,
                                              const std::vector<std::size_t>& match) const;
  /// A measurement a pass folded: its index, the pose it was linearized at, its innovation.
  struct FoldedMeasurement {
    std::size_t i;
    State x_i;
    ProposalInnovation innovation;
  };
  ProposalLinearization next_linearization(std::span<const ObservationType> known,
                                           std::span<const LandmarkGaussian<M>* const> landmarks, const State& x,
                                           const std::vector<FoldedMeasurement>& folded,
                                           const ProposalLinearization* at) const;
  void draw_from_proposal(Particle& particle, std::span<const ObservationType> known, std::vector<Outcome>& outcomes,
                          std::mt19937_64& rng) const;
  std::vector<PoseEstimate> pose_priors(const std::vector<Particle>& particles, const PendingMotion* motion) const;
  /// Per observation of a known landmark: whether the gate on the cloud lets it through.
  std::vector<bool> accepted_by_cloud(const std::vector<Particle>& particles, const std::vector<PoseEstimate>& poses,
                                      std::span<const ObservationType> known) const;
  std::vector<Outcome> update_known_landmarks(Particle& particle, std::span<const ObservationType> known,
                                              const std::vector<bool>& accepted) const;
  std::vector<std::size_t> associate_and_propose(Particle& particle, std::span<const Measurement> measurements,
                                                 bool proposal, const std::vector<PendingMotion>& pending) const;
  double new_landmark_log_weight(const State& x, const Measurement& z) const;
  void map_unassociated(Particle& particle, std::span<const Measurement> measurements,
                        const std::vector<std::size_t>& match, bool proposal, Transaction& t) const;
  std::vector<std::size_t> associate_in_particle(Particle& particle, State& mean, PoseMatrix& cov,
                                                 std::span<const Measurement> measurements, bool proposal) const;
  std::vector<std::size_t> normalize_and_resample(Transaction& t) const;
  /// The weighted mixture of the particles' pose Gaussians (components: pose_components of the cloud).
  PoseEstimate cloud_estimate(const std::vector<Particle>& cloud, const std::vector<PoseEstimate>& components) const;
  template <class Component>
  PoseEstimate mixture_in_frame(const std::vector<double>& w, std::size_t reference, Component&& component) const;
  /// A particle's pose Gaussian: its proposal, or its pose moved by the pending motions (checked).
  PoseEstimate pose_component(const Particle& particle, const std::vector<PendingMotion>& pending) const;
  std::vector<PoseEstimate> pose_components(const std::vector<Particle>& cloud,
                                            const std::vector<PendingMotion>& pending) const;
  double point_support(const std::vector<Particle>& cloud, const std::vector<PendingMotion>& pending,
                       bool frame_fixed) const;
  static std::vector<double> normalized_weights(const std::vector<Particle>& particles);
  static double effective_sample_size_of(const std::vector<double>& normalized);
  bool is_current(std::size_t index) const {
    const auto it = index_.find(id_of_index_[index]);
    return it != index_.end() && it->second == index;
  }
  /// The particle with the largest weight now (the first of equal ones).
  static std::size_t heaviest_particle(const std::vector<Particle>& particles);
  /// The most likely particle (best_): the one whose landmarks map() lists.
  std::size_t best_particle() const { return best_; }
  std::optional<LandmarkEstimate<M>> unassociated_landmark(LandmarkId id) const;
  /// A landmark covariance in the particles' frame plus the frame's uncertainty (its translation:
  /// the leading M entries of the state, as the runner's scoring assumes).
  Eigen::Matrix<double, M, M> in_world_frame(const Eigen::Matrix<double, M, M>& cov) const {
    static_assert(X >= M, "FastSlam: the pose must hold the landmark's position first");
    return cov + frame_cov_.template topLeftCorner<M, M>();
  }

  Motion motion_;
  Sensor sensor_;
  FastSlamOptions options_;
  InnovationGate gate_;
  StudentTNoise noise_tails_;  ///< options_.student_t_dof
  std::vector<Particle> particles_;
  std::unordered_map<LandmarkId, std::size_t> index_;  ///< id -> index in every particle's map
  std::vector<LandmarkId> id_of_index_;  ///< index -> id; an index whose id was removed is stale
  LandmarkId next_unassociated_id_;
  std::vector<PendingMotion> pending_;  ///< v2: motion not yet sampled
  std::mt19937_64 rng_;
  std::size_t resamplings_ = 0;
  std::optional<PoseEstimate> estimate_;  ///< the weighted cloud of the last update, before resampling
  double support_ = std::numeric_limits<double>::infinity();  ///< pose_sample_support() of estimate_
  /// Uncertainty of the frame the particles map in, relative to the prior's: the prior and the motion
  /// before the first landmark (dead reckoning, not sampled); frozen from the first landmark on and
  /// added to the reported covariances (without the lever arm of its rotation part).
  Eigen::Matrix<double, X, X> frame_cov_;
  bool frame_fixed_ = false;  ///< a landmark has been mapped
  /// The particle with the largest weight; after a resampling, which leaves every weight equal, the
  /// first copy of the one that had it before (the most likely particle, not the sampler's first draw).
  std::size_t best_ = 0;
};

}  // namespace sextant

#include "sextant/backends/detail/fast_slam_impl.hpp"

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_FAST_SLAM
#include "sextant/compiled/extern_instances.hpp"
