#pragma once
/// \file Re-acquiring a gated filter whose pose has left its own covariance (issue 35).
///
/// After a long spell without sightings, odometry whose error is systematic (a wheel's scale, a
/// heading bias) can put the pose several of the motion model's sigmas off; a chi-square gate then
/// rejects every returning sighting and the filter never corrects again (MRCLAM Dataset6 with a
/// minute of sightings removed: robot 2's heading 0.84 rad off at 3.3 sigma). A rejection is
/// ambiguous: the sighting may be an outlier, or the pose may be wrong. Three questions decide:
///
/// 1. Do the rejected sightings since the last accepted one (at least `min_landmarks` distinct
///    landmarks) agree on one robot offset d? Each sighting was made at the estimate x_i of its
///    time; since nothing was accepted since, those estimates are dead reckoning and share one
///    error, a rigid motion of the world, which the state space's plus() applies to each:
///      d = argmin sum_i |r_i(d)|^2,  r_i(d) = S_i^-1/2 residual(z_i, h(plus(x_i, d), m_i)),
///    with S_i = J_m P_m J_m^T + Q (the sighting's covariance with the robot known), found by
///    Gauss-Newton. It must explain them jointly: sum |r_i|^2 within the chi-square quantile of
///    Z k - X dof, as joint compatibility asks of a pairing (Neira and Tardos 2001) with the pose
///    offset as the unknown. (Asking it of each sighting too lets one real outlier among them
///    block the re-acquisition: measured, docs/results/mrclam.md.)
/// 2. Could the pose have drifted that far since the last accepted sighting? d^T (c^2 D)^-1 d
///    within the chi-square quantile of X dof, with D the covariance dead reckoning alone has
///    gathered since then (D <- G D G^T + R from zero) and c = `drift_factor`: how much the motion
///    model may understate real odometry drift. A burst of outliers right after a fix asks for a
///    jump dead reckoning cannot make and stays rejected, however consistent it looks.
/// 3. Does the moved pose explain what follows? The filter keeps going as it is and a copy of it,
///    moved by d with d d^T added to its pose covariance (the back-end's reacquire_pose), runs
///    beside it on the next `probation` sightings; the copy replaces the filter only if its
///    predictive likelihood of them is higher (each sighting's N(nu; 0, S) with the NIS clipped at
///    the gate: an outlier model flat beyond it). The likelihood charges the copy for its wider
///    covariance, which counting the sightings each gate accepts would not. A hypothesis bought
///    with a consistent burst loses to the filter once real sightings come back.
///
/// This class answers questions 1 and 2 and keeps the record; the back-end runs the probation
/// (PoseProbation below). D, the record and the probation are reset by any accepted sighting.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sextant/core/chi_square.hpp"
#include "sextant/core/concepts.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

struct ReacquisitionOptions {
  /// Distinct landmarks among the rejected sightings before the offset is looked for; 0 = never
  /// (the filter keeps rejecting), the default: on seed 004's stereo data, full of outliers, it
  /// moves the pose where the clean file's dead reckoning says it should not (docs/results/mrclam.md).
  /// Three, where it is on (sextant-run's MRCLAM family), leave a planar pose's joint test
  /// 2 x 3 - 3 = 3 dof.
  int min_landmarks = 0;
  /// c in question 2: how many times its own standard deviation real odometry may drift beyond the
  /// motion model's dead reckoning. Five: MRCLAM's odometry residuals over 1 s are 2.5-4 times the
  /// model's (docs/results/mrclam.md), with a margin; the filter is not tuned by it otherwise.
  double drift_factor = 5.0;
  /// Sightings of known landmarks the two hypotheses are compared over (question 3); a burst of
  /// outliers longer than the record's test plus this looks like a lost pose to any window.
  int probation = 20;
};

template <class Space, class Sensor, class State, int X>
class PoseReacquisition {
 public:
  using Landmark = typename Sensor::Landmark;
  using Measurement = typename Sensor::Measurement;
  static constexpr int Z = measurement_dim_v<Sensor>;
  using Offset = Eigen::Matrix<double, X, 1>;
  using Drift = Eigen::Matrix<double, X, X>;

  /// One sighting the gate rejected.
  struct Sighting {
    LandmarkId id = 0;
    State x;        ///< the robot's estimate when it was made
    Landmark m;     ///< the landmark's mean then
    Measurement z;
    Eigen::Matrix<double, Z, Z> S;  ///< J_m P_m J_m^T + Q: its covariance with the robot known
  };
  /// The sighting `observation` made from the robot at x of a landmark with mean m and covariance
  /// P_mm; nothing where the model cannot predict it (it then tells nothing about an offset).
  template <class Observation, class LandmarkCovariance>
  static std::optional<Sighting> sighting(const Sensor& sensor, const State& x, const Landmark& m,
                                          const Observation& observation, const LandmarkCovariance& P_mm) {
    try {
      const auto p = with_noise_scale(sensor.predict(x, m), observation.noise_scale);
      return Sighting{observation.landmark_id, x, m, observation.z, symmetrized(p.J_z_m * P_mm * p.J_z_m.transpose() + p.Q)};
    } catch (const error&) {
      return std::nullopt;
    }
  }

  /// The most recent rejections the test reads: the older ones were made further back along the
  /// dead-reckoned path, and the record stays bounded through a long spell of outliers.
  static constexpr std::size_t kWindow = 32;

  /// Off: nothing is recorded and no offset is ever found.
  PoseReacquisition() = default;
  /// probability: the gate's, used for all three chi-square tests.
  PoseReacquisition(const ReacquisitionOptions& options, double probability) : options_(options), probability_(probability) {
    if (options.min_landmarks < 0)
      throw invalid_input_error("reacquisition.min_landmarks must be >= 0, got " + std::to_string(options.min_landmarks));
    if (!(options.drift_factor > 0.0 && std::isfinite(options.drift_factor)))
      throw invalid_input_error("reacquisition.drift_factor must be positive and finite, got " + std::to_string(options.drift_factor));
    if (options.probation < 1)
      throw invalid_input_error("reacquisition.probation must be >= 1, got " + std::to_string(options.probation));
    if (on() && !(probability > 0.0 && probability < 1.0))
      throw invalid_input_error("pose re-acquisition needs the gate on (gate_probability in (0, 1))");
  }

  bool on() const { return options_.min_landmarks > 0; }
  const std::vector<Sighting>& record() const { return record_; }

  /// D after a motion step with transition G and noise R (pure; set_drift keeps it).
  Drift drift_after(const Drift& G, const Drift& R) const { return G * drift_ * G.transpose() + R; }
  void set_drift(const Drift& drift) noexcept { drift_ = drift; }

  /// An accepted sighting: the pose is where the filter says, within its covariance.
  void accepted() noexcept {
    record_.clear();
    drift_.setZero();
  }
  /// Forgets the rejections (a hypothesis was tried on them), keeps D.
  void forget_record() noexcept { record_.clear(); }

  /// Adds the sightings an update rejected (none accepted) and returns the offset d the pose is
  /// lost by, if questions 1 and 2 say so; the record is then cleared.
  std::optional<Offset> add_rejected(std::vector<Sighting> sightings, const Sensor& sensor) {
    if (!on()) return std::nullopt;
    for (auto& s : sightings) record_.push_back(std::move(s));
    if (record_.size() > kWindow) record_.erase(record_.begin(), record_.end() - static_cast<std::ptrdiff_t>(kWindow));
    if (distinct_landmarks() < static_cast<std::size_t>(options_.min_landmarks)) return std::nullopt;
    auto offset = common_offset(sensor);
    if (offset && !plausible_drift(*offset)) offset.reset();
    if (offset) record_.clear();
    return offset;
  }

  /// Question 1 on the record: the offset, if it explains the sightings jointly.
  std::optional<Offset> common_offset(const Sensor& sensor) const {
    const double dof = static_cast<double>(Z) * static_cast<double>(record_.size()) - X;
    if (dof <= 0.0) return std::nullopt;
    try {
      std::vector<Eigen::Matrix<double, Z, Z>> whiten;  // S_i^-1/2 as L^-1
      for (const auto& s : record_) {
        const Eigen::LLT<Eigen::Matrix<double, Z, Z>> llt(s.S);
        if (llt.info() != Eigen::Success) return std::nullopt;
        whiten.push_back(llt.matrixL().solve(Eigen::Matrix<double, Z, Z>::Identity()));
      }
      const auto d = gauss_newton(sensor, whiten);
      if (!d) return std::nullopt;
      if (!(residuals(sensor, whiten, *d).squaredNorm() <= chi_square_quantile(dof, probability_))) return std::nullopt;
      return d;
    } catch (const error&) {  // a sighting the model cannot predict at a trial pose (e.g. behind a camera)
      return std::nullopt;
    }
  }

  /// Question 2: d within c standard deviations of the drift dead reckoning allows since the fix.
  bool plausible_drift(const Offset& d) const {
    const Eigen::LDLT<Drift> ldlt(options_.drift_factor * options_.drift_factor * drift_);
    const auto pivots = ldlt.vectorD();
    if (ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-300)) return false;  // no motion since the fix
    const double m2 = d.dot(ldlt.solve(d));
    return std::isfinite(m2) && m2 <= chi_square_quantile(X, probability_);
  }

 private:
  std::size_t distinct_landmarks() const {
    std::vector<LandmarkId> ids;
    for (const auto& s : record_)
      if (std::find(ids.begin(), ids.end(), s.id) == ids.end()) ids.push_back(s.id);
    return ids.size();
  }

  /// The whitened residuals of every sighting with the dead-reckoned poses moved by d.
  Eigen::VectorXd residuals(const Sensor& sensor, const std::vector<Eigen::Matrix<double, Z, Z>>& whiten,
                            const Offset& d) const {
    Eigen::VectorXd r(Z * static_cast<Eigen::Index>(record_.size()));
    for (std::size_t i = 0; i < record_.size(); ++i) {
      const auto& s = record_[i];
      const auto predicted = sensor.predict(Space::plus(s.x, d), s.m);
      r.template segment<Z>(Z * static_cast<Eigen::Index>(i)) = whiten[i] * sensor.residual(s.z, predicted.z);
    }
    return r;
  }

  /// Gauss-Newton on d from 0 with central-difference Jacobians (plus() composes with the offset,
  /// so the model's own J_z_x, a derivative at the moved pose, is not d r / d d), halving a step
  /// that does not lower the cost.
  std::optional<Offset> gauss_newton(const Sensor& sensor, const std::vector<Eigen::Matrix<double, Z, Z>>& whiten) const {
    Offset d = Offset::Zero();
    Eigen::VectorXd r = residuals(sensor, whiten, d);
    for (int iteration = 0; iteration < 30; ++iteration) {
      Eigen::MatrixXd J(r.size(), X);
      for (int j = 0; j < X; ++j) {
        const double h = 1e-6 * std::max(1.0, std::abs(d(j)));
        Offset plus = d, minus = d;
        plus(j) += h;
        minus(j) -= h;
        J.col(j) = (residuals(sensor, whiten, plus) - residuals(sensor, whiten, minus)) / (2.0 * h);
      }
      const Eigen::Matrix<double, X, X> A = J.transpose() * J;
      const Eigen::LDLT<Eigen::Matrix<double, X, X>> normal(A);
      const auto pivots = normal.vectorD();
      if (normal.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff()))
        return std::nullopt;  // the sightings do not determine the robot's offset
      Offset step = -normal.solve(J.transpose() * r);
      const double cost = r.squaredNorm();
      bool lowered = false;
      for (int halving = 0; halving < 10 && !lowered; ++halving, step *= 0.5) {
        const Eigen::VectorXd trial = residuals(sensor, whiten, d + step);
        if (trial.allFinite() && trial.squaredNorm() <= cost) {
          d += step;
          r = trial;
          lowered = true;
        }
      }
      if (!lowered || step.norm() <= 1e-10 * std::max(1.0, d.norm())) break;
    }
    if (!d.allFinite()) return std::nullopt;
    return d;
  }

  ReacquisitionOptions options_{.min_landmarks = 0};
  double probability_ = 0.0;
  std::vector<Sighting> record_;
  Drift drift_ = Drift::Zero();
};

/// Question 3: a copy of the filter, moved to the offset, running beside it over the next
/// `probation` sightings of known landmarks. Copying a PoseProbation copies its candidate.
template <class Filter>
class PoseProbation {
 public:
  PoseProbation() = default;
  PoseProbation(const PoseProbation& other)
      : candidate_(other.candidate_ ? std::make_unique<Filter>(*other.candidate_) : nullptr),
        main_score_(other.main_score_), candidate_score_(other.candidate_score_), seen_(other.seen_) {}
  PoseProbation& operator=(const PoseProbation& other) {
    if (this != &other) *this = PoseProbation(other);
    return *this;
  }
  PoseProbation(PoseProbation&&) noexcept = default;
  PoseProbation& operator=(PoseProbation&&) noexcept = default;

  bool active() const { return candidate_ != nullptr; }
  Filter& candidate() { return *candidate_; }

  void start(std::unique_ptr<Filter> candidate) noexcept {
    candidate_ = std::move(candidate);
    main_score_ = candidate_score_ = 0.0;
    seen_ = 0;
  }
  void drop() noexcept { candidate_.reset(); }
  /// Counts one update: its sightings of known landmarks and each hypothesis's predictive
  /// log-likelihood of them (UpdateResult::log_likelihood); true once the probation is over.
  bool count(std::size_t sightings, double main_log_likelihood, double candidate_log_likelihood, int probation) noexcept {
    main_score_ += main_log_likelihood;
    candidate_score_ += candidate_log_likelihood;
    seen_ += sightings;
    return seen_ >= static_cast<std::size_t>(probation);
  }
  /// The candidate explains the sightings of the probation better: a higher likelihood, which
  /// charges the candidate's wider covariance (log det S) as well as rewarding its smaller
  /// innovations, where counting the sightings each gate accepts would favour the wider one.
  bool candidate_won() const { return candidate_score_ > main_score_; }
  /// The candidate, which the probation no longer holds.
  std::unique_ptr<Filter> release() noexcept { return std::move(candidate_); }

 private:
  std::unique_ptr<Filter> candidate_;
  double main_score_ = 0.0, candidate_score_ = 0.0;  ///< predictive log-likelihoods over the probation
  std::size_t seen_ = 0;
};

}  // namespace sextant
