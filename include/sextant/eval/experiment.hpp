#pragma once
/// \file One back-end on one dataset with ground truth: per-step pose error and NEES, final map
/// error and NEES, timing (thesis §4.3); and the average of many such runs with the ANEES.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <optional>
#include <vector>

#include "sextant/eval/metrics.hpp"
#include "sextant/eval/runner.hpp"

namespace sextant::eval {

/// A per-step callback that does nothing.
struct NoStepCallback {
  void operator()(std::size_t) const {}
};

/// Accuracy, consistency and time of one run.
template <class State>
struct RunSummary {
  std::vector<double> pose_error;  ///< AE of the position after each step (eq. 108)
  std::vector<double> pose_nees;   ///< NEES of the pose after each step (eq. 110)
  std::vector<double> seconds;     ///< time of each step
  std::vector<State> trajectory;   ///< pose mean after each step
  std::vector<double> map_error;   ///< AE of each landmark of the final map (eq. 109)
  std::vector<double> map_nees;    ///< NEES of each landmark of the final map (eq. 111)
  /// The thesis's map MAE "over time": the mean landmark error of the map held after each step,
  /// averaged over the steps (a filter's early maps count); for full SLAM, the final map's.
  double map_error_over_time = 0.0;
  double total_seconds = 0.0;
};

/// Runs `backend` over dataset.steps and scores it against dataset.true_poses (row k + 1 is the
/// pose after step k) and dataset.true_landmarks. The position error is the norm of the first
/// `position_dim` entries of minus(estimate, truth) (default: all of them). on_step(k) is called
/// after step k (progress reports).
template <class Backend, class Dataset, class OnStep = NoStepCallback>
RunSummary<typename Backend::State> evaluate_run(Backend& backend, const Dataset& dataset, int position_dim = -1,
                                                 OnStep on_step = {}) {
  using Space = typename Backend::Space;
  RunSummary<typename Backend::State> out;
  double map_error_sum = 0.0;
  std::size_t steps_with_map = 0;
  const auto record = run(backend, dataset.steps, [&](std::size_t k, const Backend& b) {
    on_step(k);
    const auto map = b.map();
    if (map.empty()) return;
    map_error_sum += mean(evaluate_map(map, dataset.true_landmarks).errors);
    ++steps_with_map;
  });
  out.map_error_over_time = steps_with_map ? map_error_sum / static_cast<double>(steps_with_map) : 0.0;
  for (std::size_t k = 0; k < record.steps.size(); ++k) {
    const auto& pose = record.steps[k].pose;
    const auto error = Space::minus(pose.mean, dataset.true_poses[k + 1]);
    const int n = position_dim < 0 ? static_cast<int>(error.size()) : std::min<int>(position_dim, error.size());
    out.pose_error.push_back(error.head(n).norm());
    out.pose_nees.push_back(nees_or_infinity(error, pose.cov));
    out.seconds.push_back(record.steps[k].seconds);
    out.trajectory.push_back(pose.mean);
  }
  auto map = evaluate_map(backend.map(), dataset.true_landmarks);
  out.map_error = std::move(map.errors);
  out.map_nees = std::move(map.nees);
  out.total_seconds = record.total_seconds;
  return out;
}

/// Full SLAM (a back-end with optimize() and trajectory()): records every step, optimizes once,
/// then scores the optimized trajectory and map. `seconds` holds the recording time of each step;
/// total_seconds adds the optimization.
template <class Backend, class Dataset, class OnStep = NoStepCallback>
  requires requires(Backend& b) { b.optimize(); b.trajectory(); }
RunSummary<typename Backend::State> evaluate_smoothed_run(Backend& backend, const Dataset& dataset, int position_dim = -1,
                                                          OnStep on_step = {}) {
  using Space = typename Backend::Space;
  using Clock = std::chrono::steady_clock;
  RunSummary<typename Backend::State> out;
  for (const auto& step : dataset.steps) {
    const auto start = Clock::now();
    backend.predict(step.control, step.dt);
    backend.update(step.observations);
    out.seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    out.total_seconds += out.seconds.back();
    on_step(out.seconds.size() - 1);
  }
  const auto start = Clock::now();
  backend.optimize();
  out.total_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  const auto trajectory = backend.trajectory();
  for (std::size_t k = 1; k < trajectory.size(); ++k) {
    const auto error = Space::minus(trajectory[k].mean, dataset.true_poses[k]);
    const int n = position_dim < 0 ? static_cast<int>(error.size()) : std::min<int>(position_dim, error.size());
    out.pose_error.push_back(error.head(n).norm());
    out.pose_nees.push_back(nees_or_infinity(error, trajectory[k].cov));
    out.trajectory.push_back(trajectory[k].mean);
  }
  auto map = evaluate_map(backend.map(), dataset.true_landmarks);
  out.map_error = std::move(map.errors);
  out.map_nees = std::move(map.nees);
  out.map_error_over_time = mean(out.map_error);
  return out;
}

/// Averages over runs: MAE of pose and map, share of NEES inside the one-sided bound, time, and
/// with two or more runs the pose ANEES with its two-sided interval.
struct Summary {
  double pose_mae = 0.0, map_mae = 0.0, map_mae_over_time = 0.0;
  double pose_nees_inside = 0.0, map_nees_inside = 0.0;  ///< fractions in [0, 1]
  double total_seconds = 0.0, seconds_per_step = 0.0;
  double pose_anees = 0.0;
  std::optional<Interval> anees_interval;
  double pose_mae_std = 0.0;  ///< standard deviation of the per-run pose MAE
  double map_mae_std = 0.0;
};

template <class State>
Summary summarize(const std::vector<RunSummary<State>>& runs, int pose_dof, int landmark_dof, double confidence = 0.95) {
  Summary s;
  if (runs.empty()) return s;
  const double n = static_cast<double>(runs.size());
  std::vector<double> pose_maes, map_maes;
  std::vector<std::vector<double>> nees_runs;
  for (const auto& r : runs) {
    pose_maes.push_back(mean(r.pose_error));
    map_maes.push_back(mean(r.map_error));
    s.pose_nees_inside += fraction_at_most(r.pose_nees, nees_upper_bound(pose_dof, confidence)) / n;
    s.map_nees_inside += fraction_at_most(r.map_nees, nees_upper_bound(landmark_dof, confidence)) / n;
    s.total_seconds += r.total_seconds / n;
    s.map_mae_over_time += r.map_error_over_time / n;
    nees_runs.push_back(r.pose_nees);
  }
  auto standard_deviation = [](const std::vector<double>& v) {
    const double m = mean(v);
    double sum = 0.0;
    for (double x : v) sum += (x - m) * (x - m);
    return v.size() > 1 ? std::sqrt(sum / static_cast<double>(v.size() - 1)) : 0.0;
  };
  s.pose_mae = mean(pose_maes);
  s.map_mae = mean(map_maes);
  s.pose_mae_std = standard_deviation(pose_maes);
  s.map_mae_std = standard_deviation(map_maes);
  s.seconds_per_step = s.total_seconds / static_cast<double>(std::max<std::size_t>(1, runs.front().seconds.size()));
  s.pose_anees = mean(anees_per_step(nees_runs));
  if (runs.size() > 1) s.anees_interval = anees_interval(pose_dof, static_cast<int>(runs.size()), confidence);
  return s;
}

}  // namespace sextant::eval
