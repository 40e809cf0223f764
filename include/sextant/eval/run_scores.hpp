#pragma once
/// \file The average of many runs (Summary) computed from each run's few numbers (RunScores): what a
/// Monte Carlo study keeps of a run, so runs made in other processes or on other machines
/// (eval/study_records.hpp) average to the same table, to the bit, as runs made here.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sextant/eval/metrics.hpp"

namespace sextant::eval {

/// One run's scores: per-run means over its steps (eqs. 108-111) and its time.
struct RunScores {
  std::size_t steps = 0;  ///< timed steps
  double pose_mae = 0.0, pose_rmse = 0.0, pose_rmse_aligned = 0.0, pose_mae_aligned = 0.0;
  double map_mae = 0.0, map_mae_over_time = 0.0, map_mae_aligned = 0.0;
  double pose_nees_inside = 0.0, map_nees_inside = 0.0;  ///< fractions inside the one-sided NEES bound
  double pose_anees = 0.0;                              ///< mean pose NEES over the run's steps
  /// Share of the steps whose pose covariance rests on fewer effective particles than the pose has
  /// dimensions + 1 (a particle filter's collapsed cloud of points): its NEES there measures the
  /// sample, not the filter, and the step does not count as inside the bound.
  double pose_undersampled = 0.0;
  double pose_anees_supported = 0.0;  ///< mean pose NEES over the steps that are not undersampled (NaN: none is)
  double total_seconds = 0.0;
  std::size_t failed_steps = 0;  ///< steps skipped (StepErrors::skip)
  std::string first_failure;     ///< the first skipped step's message
};

/// Averages over runs: MAE of pose and map, share of NEES inside the one-sided bound, time, and
/// with two or more runs the pose ANEES (over runs and steps) with the two-sided interval of that
/// average (time_averaged_anees_interval).
struct Summary {
  double pose_mae = 0.0, map_mae = 0.0, map_mae_over_time = 0.0;
  double pose_rmse = 0.0;  ///< root mean square of the position error over the steps, averaged over runs
  double pose_rmse_aligned = 0.0;  ///< the same after rigid alignment of the trajectory to the truth (evo's APE)
  double pose_mae_aligned = 0.0, map_mae_aligned = 0.0;  ///< after rigid alignment to the truth
  double pose_nees_inside = 0.0, map_nees_inside = 0.0;  ///< fractions in [0, 1]
  double total_seconds = 0.0, seconds_per_step = 0.0;
  double pose_anees = 0.0;
  std::optional<Interval> anees_interval;
  double pose_undersampled = 0.0;  ///< RunScores::pose_undersampled averaged over runs
  double pose_anees_supported = 0.0;  ///< RunScores::pose_anees_supported averaged over runs
  double pose_mae_std = 0.0;  ///< standard deviation of the per-run pose MAE
  double map_mae_std = 0.0;
  std::size_t failed_steps = 0;  ///< steps skipped over all runs (StepErrors::skip)
  std::string first_failure;     ///< the first run's first skipped step that has one

  /// Marks every score NaN (a run without ground truth has only its time).
  void mark_unscored() {
    constexpr double none = std::numeric_limits<double>::quiet_NaN();
    pose_mae = map_mae = map_mae_over_time = pose_rmse = pose_rmse_aligned = pose_mae_aligned = map_mae_aligned = none;
    pose_nees_inside = map_nees_inside = pose_anees = pose_mae_std = map_mae_std = pose_undersampled =
        pose_anees_supported = none;
    anees_interval.reset();
  }
};

/// The pose's NEES scores of one run: the share of steps inside the one-sided bound at `confidence`,
/// the average, and the share of steps whose covariance rests on fewer than pose_dof + 1 effective
/// particles (`support`, per step; empty: every step's covariance is a Gaussian's), which never
/// count as inside; the average over the other steps beside the average over all.
inline void add_pose_consistency(RunScores& s, const std::vector<double>& nees, const std::vector<double>& support,
                                 int pose_dof, double confidence) {
  if (nees.empty()) {  // no step to score (e.g. every one failed)
    s.pose_nees_inside = s.pose_undersampled = s.pose_anees = s.pose_anees_supported = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  const double bound = nees_upper_bound(pose_dof, confidence);
  std::size_t inside = 0, undersampled = 0;
  double supported_sum = 0.0;
  for (std::size_t k = 0; k < nees.size(); ++k) {
    const bool sampled_too_thinly = k < support.size() && support[k] < pose_dof + 1.0;
    undersampled += sampled_too_thinly;
    inside += !sampled_too_thinly && nees[k] <= bound;
    if (!sampled_too_thinly) supported_sum += nees[k];
  }
  const double steps = static_cast<double>(nees.size());
  s.pose_nees_inside = static_cast<double>(inside) / steps;
  s.pose_undersampled = static_cast<double>(undersampled) / steps;
  s.pose_anees = mean(nees);
  if (undersampled == 0) s.pose_anees_supported = s.pose_anees;
  else if (undersampled == nees.size()) s.pose_anees_supported = std::numeric_limits<double>::quiet_NaN();
  else s.pose_anees_supported = supported_sum / static_cast<double>(nees.size() - undersampled);
}

namespace detail {
inline double sample_standard_deviation(const std::vector<double>& v) {
  const double m = mean(v);
  double sum = 0.0;
  for (double x : v) sum += (x - m) * (x - m);
  return v.size() > 1 ? std::sqrt(sum / static_cast<double>(v.size() - 1)) : 0.0;
}
}  // namespace detail

/// The average of `runs` in the order given (the sums run in that order: a study's table depends on
/// the order of its seeds, not on where they ran).
inline Summary summarize(const std::vector<RunScores>& runs, int pose_dof, double confidence = 0.95) {
  Summary s;
  if (runs.empty()) return s;
  const double n = static_cast<double>(runs.size());
  std::vector<double> pose_maes, map_maes, nees_averages;
  for (const auto& r : runs) {
    pose_maes.push_back(r.pose_mae);
    s.pose_rmse += r.pose_rmse / n;
    s.pose_rmse_aligned += r.pose_rmse_aligned / n;
    map_maes.push_back(r.map_mae);
    s.pose_nees_inside += r.pose_nees_inside / n;
    s.map_nees_inside += r.map_nees_inside / n;
    s.total_seconds += r.total_seconds / n;
    s.map_mae_over_time += r.map_mae_over_time / n;
    s.pose_mae_aligned += r.pose_mae_aligned / n;
    s.map_mae_aligned += r.map_mae_aligned / n;
    s.pose_undersampled += r.pose_undersampled / n;
    s.pose_anees_supported += r.pose_anees_supported / n;
    nees_averages.push_back(r.pose_anees);
    s.failed_steps += r.failed_steps;
    if (s.first_failure.empty()) s.first_failure = r.first_failure;
  }
  s.pose_mae = mean(pose_maes);
  s.map_mae = mean(map_maes);
  s.pose_mae_std = detail::sample_standard_deviation(pose_maes);
  s.map_mae_std = detail::sample_standard_deviation(map_maes);
  s.seconds_per_step = s.total_seconds / static_cast<double>(std::max<std::size_t>(1, runs.front().steps));
  s.pose_anees = mean(nees_averages);
  if (runs.size() > 1 && std::isfinite(s.pose_anees))
    s.anees_interval = time_averaged_anees_interval(pose_dof, nees_averages, confidence);
  return s;
}

}  // namespace sextant::eval
