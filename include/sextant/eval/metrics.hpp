#pragma once
/// \file Accuracy and consistency metrics of the thesis (seed 000, §4.3.1): absolute error
/// (eqs. 108-109), MAE, RMSE, NEES (eqs. 110-111), ANEES over Monte Carlo runs and chi-square bounds.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include <boost/math/distributions/students_t.hpp>

#include "sextant/core/chi_square.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"

namespace sextant::eval {

/// AE = ||estimate - truth|| (eqs. 108, 109).
template <class A, class B>
double absolute_error(const Eigen::MatrixBase<A>& estimate, const Eigen::MatrixBase<B>& truth) {
  return (estimate - truth).norm();
}

/// NEES = e^T C^-1 e (eqs. 110, 111), by a Cholesky solve; throws numerical_error if C is not PD.
template <class E, class C>
double nees(const Eigen::MatrixBase<E>& error, const Eigen::MatrixBase<C>& cov) {
  return mahalanobis_squared(cholesky_or_throw(cov.eval(), "covariance in NEES"), error);
}

/// NEES, or +infinity when the covariance is not positive definite (a collapsed estimate, e.g. a
/// particle cloud of identical particles, is maximally overconfident): for evaluations that must
/// not stop at one degenerate step.
template <class E, class C>
double nees_or_infinity(const Eigen::MatrixBase<E>& error, const Eigen::MatrixBase<C>& cov) {
  const Eigen::LLT<typename C::PlainObject> llt(cov.eval());
  if (llt.info() != Eigen::Success || !cov.allFinite()) return std::numeric_limits<double>::infinity();
  return mahalanobis_squared(llt, error);
}

/// Mean of the values (MAE when they are absolute errors); 0 for an empty range.
inline double mean(std::span<const double> values) {
  if (values.empty()) return 0.0;
  return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

/// Root mean square of the values (RMSE when they are absolute errors).
inline double rms(std::span<const double> values) {
  if (values.empty()) return 0.0;
  const double sum_sq = std::accumulate(values.begin(), values.end(), 0.0, [](double s, double v) { return s + v * v; });
  return std::sqrt(sum_sq / static_cast<double>(values.size()));
}

/// Fraction of values at or below the bound (e.g. share of steps whose NEES is inside 5.991).
inline double fraction_at_most(std::span<const double> values, double bound) {
  if (values.empty()) return 0.0;
  const auto inside = std::count_if(values.begin(), values.end(), [bound](double v) { return v <= bound; });
  return static_cast<double>(inside) / static_cast<double>(values.size());
}

/// A score over no values is none: NaN (a table prints "-"), not the 0 of an empty mean(), which
/// would read as a perfect score (e.g. a back-end whose every step failed).
inline double mean_or_nan(std::span<const double> values) {
  return values.empty() ? std::numeric_limits<double>::quiet_NaN() : mean(values);
}
inline double rms_or_nan(std::span<const double> values) {
  return values.empty() ? std::numeric_limits<double>::quiet_NaN() : rms(values);
}
inline double fraction_at_most_or_nan(std::span<const double> values, double bound) {
  return values.empty() ? std::numeric_limits<double>::quiet_NaN() : fraction_at_most(values, bound);
}

/// One-sided upper bound of NEES for `dof` degrees of freedom at `confidence`
/// (5.991 for 2 dof and 7.815 for 3 dof at 0.95, thesis §4.3.1).
inline double nees_upper_bound(int dof, double confidence = 0.95) { return chi_square_quantile(dof, confidence); }

/// Two-sided interval of the ANEES (mean NEES over `runs` independent runs) of a consistent
/// estimator: N * ANEES ~ chi2(N * dof), so the bounds are chi2 quantiles divided by N.
struct Interval {
  double lower;
  double upper;
  bool contains(double value) const { return value >= lower && value <= upper; }
};
inline Interval anees_interval(int dof, int runs, double confidence = 0.95) {
  if (runs <= 0) throw invalid_input_error("anees_interval needs runs > 0, got " + std::to_string(runs));
  const double total_dof = static_cast<double>(dof) * runs;
  const double tail = 0.5 * (1.0 - confidence);
  return {chi_square_quantile(total_dof, tail) / runs, chi_square_quantile(total_dof, 1.0 - tail) / runs};
}

/// Two-sided interval, under consistency, of the NEES averaged over K steps and N runs. The runs
/// are independent but the steps of one run are not (the error at step k carries into k + 1), so
/// no chi-square with N K dof applies. Each run's time average a_i = (1/K) sum_k NEES_ik has mean
/// dof; the a_i are i.i.d., so their mean lies in dof +- t_{N-1} s / sqrt(N) (s: sample standard
/// deviation of the a_i; Student's t at the given confidence), its lower end at least 0: a NEES
/// is never negative, where runs that scatter widely would put dof - t s / sqrt(N). Needs N >= 2.
inline Interval time_averaged_anees_interval(int dof, std::span<const double> per_run_averages,
                                             double confidence = 0.95) {
  const std::size_t n = per_run_averages.size();
  if (n < 2) throw invalid_input_error("time_averaged_anees_interval needs at least 2 runs");
  const double mean_value = mean(per_run_averages);
  double sum_sq = 0.0;
  for (double a : per_run_averages) sum_sq += (a - mean_value) * (a - mean_value);
  const double s = std::sqrt(sum_sq / static_cast<double>(n - 1));
  const double t = boost::math::quantile(boost::math::students_t(static_cast<double>(n - 1)), 0.5 * (1.0 + confidence));
  const double half_width = t * s / std::sqrt(static_cast<double>(n));
  return {std::max(0.0, dof - half_width), dof + half_width};
}

/// Per-step ANEES: element-wise mean over runs of per-step NEES series of equal length.
inline std::vector<double> anees_per_step(const std::vector<std::vector<double>>& nees_per_run) {
  if (nees_per_run.empty()) return {};
  const std::size_t steps = nees_per_run.front().size();
  std::vector<double> out(steps, 0.0);
  for (const auto& run : nees_per_run) {
    if (run.size() != steps) throw invalid_input_error("anees_per_step: runs have different lengths");
    for (std::size_t k = 0; k < steps; ++k) out[k] += run[k];
  }
  for (double& v : out) v /= static_cast<double>(nees_per_run.size());
  return out;
}

/// Per-landmark accuracy and consistency of a map against ground truth (eqs. 109, 111).
struct MapEvaluation {
  std::vector<LandmarkId> ids;      ///< landmarks of the estimate, in its order
  std::vector<double> errors;       ///< AE per landmark
  std::vector<double> nees;         ///< NEES per landmark
};

/// Evaluates every estimated landmark against `truth`; throws unknown_landmark_error when the
/// estimate holds a landmark that the ground truth does not.
template <int M, class Truth>
MapEvaluation evaluate_map(const std::vector<LandmarkEstimate<M>>& map, const std::map<LandmarkId, Truth>& truth) {
  MapEvaluation out;
  for (const auto& landmark : map) {
    const auto it = truth.find(landmark.id);
    if (it == truth.end())
      throw unknown_landmark_error("landmark " + std::to_string(landmark.id) + " has no ground truth");
    const Eigen::Matrix<double, M, 1> error = landmark.mean - it->second;
    out.ids.push_back(landmark.id);
    out.errors.push_back(error.norm());
    out.nees.push_back(nees_or_infinity(error, landmark.cov));
  }
  return out;
}

}  // namespace sextant::eval
