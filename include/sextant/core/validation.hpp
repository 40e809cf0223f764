#pragma once
/// \file Input checks shared by the back-ends. Each throws a sextant error that names the problem;
/// back-ends call them before touching their state.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <concepts>
#include <span>
#include <string>
#include <unordered_set>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

/// Throws invalid_input_error naming `what` when a value (an Eigen vector or matrix, or any type
/// with allFinite(), such as a control carrying its own covariance) has NaN or Inf entries.
template <class T>
  requires requires(const T& t) { { t.allFinite() } -> std::convertible_to<bool>; }
void require_finite(const T& value, const std::string& what) {
  if (!value.allFinite()) throw invalid_input_error(what + " contains NaN or Inf");
}

/// Throws invalid_input_error unless dt is finite and strictly positive.
inline void require_positive_time_step(double dt) {
  if (!std::isfinite(dt) || dt <= 0.0)
    throw invalid_input_error("time step dt must be finite and > 0, got " + std::to_string(dt));
}

/// Throws invalid_input_error unless a matrix the caller was given (a covariance, an information) is
/// finite, symmetric (to 1e-9 of its largest entry) and positive definite; `what` names it.
template <int N>
void require_symmetric_positive_definite(const Eigen::Matrix<double, N, N>& a, const std::string& what) {
  if (!a.allFinite()) throw invalid_input_error(what + " contains NaN or Inf");
  const double scale = a.cwiseAbs().maxCoeff();
  if (!((a - a.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale)) throw invalid_input_error(what + " is not symmetric");
  if (Eigen::LLT<Eigen::Matrix<double, N, N>>(a).info() != Eigen::Success || !(scale > 0.0))
    throw invalid_input_error(what + " is not positive definite");
}

/// Throws numerical_error unless the process noise R of a motion step is finite, symmetric and
/// positive semi-definite, each up to rounding (relative 1e-9 of its largest entry): the one check
/// every back-end applies, so that none of them repairs (symmetrizes, clips) a broken model silently.
template <class Derived>
void require_process_noise(const Eigen::MatrixBase<Derived>& R) {
  if (!R.allFinite()) throw numerical_error("process noise R has NaN or Inf entries");
  const double scale = R.cwiseAbs().maxCoeff();
  const double tolerance = 1e-9 * scale;
  if (!((R - R.transpose()).cwiseAbs().maxCoeff() <= tolerance))
    throw numerical_error("process noise R is not symmetric");
  using Matrix = typename Derived::PlainObject;
  const Matrix symmetric = 0.5 * (R + R.transpose());
  // R + tolerance I has a Cholesky factor iff R's smallest eigenvalue is above -tolerance (to
  // rounding): the common case at the cost of a factorization; the eigenvalues only otherwise.
  if (Eigen::LLT<Matrix>(symmetric + tolerance * Matrix::Identity(R.rows(), R.cols())).info() == Eigen::Success) return;
  const double smallest = Eigen::SelfAdjointEigenSolver<Matrix>(symmetric, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
  if (!(smallest >= -tolerance))
    throw numerical_error("process noise R is not positive semi-definite (smallest eigenvalue " +
                          std::to_string(smallest) + ")");
}

/// The motion model's prediction at x, checked before any back-end uses it: mean, Jacobian G and
/// process noise R finite (numerical_error "motion model returned NaN or Inf" otherwise) and R
/// symmetric positive semi-definite (require_process_noise).
template <class Motion, class State, class Control>
auto checked_motion_prediction(const Motion& motion, const State& x, const Control& u, double dt) {
  auto prediction = motion.predict(x, u, dt);
  if (!Motion::Space::is_finite(prediction.x) || !prediction.J_x_x.allFinite() || !prediction.R.allFinite())
    throw numerical_error("motion model returned NaN or Inf");
  require_process_noise(prediction.R);
  return prediction;
}

/// Throws when an observation is not finite or a landmark id repeats within one update.
template <class Measurement>
void require_valid_observations(std::span<const Observation<Measurement>> observations) {
  std::unordered_set<LandmarkId> seen;
  seen.reserve(observations.size());
  for (const auto& observation : observations) {
    require_finite(observation.z, "measurement of landmark " + std::to_string(observation.landmark_id));
    if (!(observation.noise_scale > 0.0) || !std::isfinite(observation.noise_scale))
      throw invalid_input_error("measurement of landmark " + std::to_string(observation.landmark_id) + ": noise_scale " +
                                std::to_string(observation.noise_scale) + " is not a positive finite number");
    if (!seen.insert(observation.landmark_id).second)
      throw duplicate_landmark_error("landmark id " + std::to_string(observation.landmark_id) +
                                     " is observed twice in one update");
  }
}

/// A landmark known before it is seen (add_landmark): a finite mean, a symmetric positive definite
/// covariance, and an id that is not in the map yet (`in_map`: whether it is).
template <int M>
void require_valid_known_landmark(const LandmarkEstimate<M>& known, bool in_map) {
  const std::string what = "known landmark " + std::to_string(known.id);
  require_finite(known.mean, what + " mean");
  require_symmetric_positive_definite<M>(known.cov, what + " covariance");
  if (in_map) throw duplicate_landmark_error("landmark id " + std::to_string(known.id) + " is already in the map");
}

}  // namespace sextant
