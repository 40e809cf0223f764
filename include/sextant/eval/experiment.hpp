#pragma once
/// \file One back-end on one dataset with ground truth: per-step pose error and NEES, final map
/// error and NEES, timing (thesis §4.3); and the average of many such runs with the ANEES.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sextant/core/seconds_since.hpp"
#include "sextant/eval/alignment.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/eval/run_scores.hpp"
#include "sextant/eval/runner.hpp"

namespace sextant::eval {

/// A per-step callback that does nothing.
struct NoStepCallback {
  void operator()(std::size_t) const {}
};

/// Full SLAM's final optimization: the Gauss-Newton iterations it took, whether it converged
/// (step or cost change below its tolerance) before its iteration limit, the iteration whose
/// estimate it kept (the last unless an earlier one had the lower cost), and the iteration whose cost
/// rose, after which its steps were damped (-1: none; GraphOptions::damp_after_rise).
struct OptimizationOutcome {
  int iterations = 0;
  bool converged = true;
  int best_iteration = 0;
  int damped_from = -1;
};

/// Accuracy, consistency and time of one run.
template <class State>
struct RunSummary {
  std::vector<double> pose_error;  ///< AE of the position after each step (eq. 108)
  std::vector<double> pose_nees;   ///< NEES of the pose after each step (eq. 110)
  /// A particle filter's pose_sample_support() after each step (empty for other back-ends): how many
  /// effective particles the pose covariance, and so its NEES, rests on.
  std::vector<double> pose_support;
  std::vector<double> seconds;     ///< time of each step
  std::vector<State> trajectory;   ///< pose mean after each step
  std::vector<double> map_error;   ///< AE of each landmark of the final map (eq. 109)
  std::vector<double> map_nees;    ///< NEES of each landmark of the final map (eq. 111)
  std::vector<double> pose_error_aligned;  ///< position error after rigid alignment of the trajectory to the truth
  std::vector<double> map_error_aligned;   ///< landmark error after rigid alignment of the final map to the truth
  /// The thesis's map MAE "over time": the mean landmark error of the map held after each step,
  /// averaged over the steps (a filter's early maps count); for full SLAM, the final map's.
  double map_error_over_time = 0.0;
  double total_seconds = 0.0;
  StepFailures failures;  ///< steps skipped under StepErrors::skip (for_each_step)
  std::optional<OptimizationOutcome> optimization;  ///< full SLAM whose optimize() reports one (GraphSlam)
};

namespace detail {
/// Length of the position error of `estimate` against `truth`: the leading `position_dim` entries of
/// Space::minus (all of them for -1), or Space::position_error where the chart's tangent mixes the
/// rotation into the position (Se2WorldSpace).
template <class Space, class State>
double position_error(const State& estimate, const State& truth, int position_dim) {
  if constexpr (requires { Space::position_error(estimate, truth); })
    return Space::position_error(estimate, truth).norm();
  else {
    const auto error = Space::minus(estimate, truth);
    const int n = position_dim < 0 ? static_cast<int>(error.size()) : std::min<int>(position_dim, error.size());
    return error.head(n).norm();
  }
}

/// Errors after the best rigid alignment of `estimate` onto `truth` (points of dimension dim, 2 or
/// 3, given as the leading entries of each vector); empty for other dimensions.
template <class A, class B>
std::vector<double> aligned_position_errors(const std::vector<A>& estimate, const std::vector<B>& truth, int dim) {
  auto run = [&]<int D>() {
    std::vector<Eigen::Matrix<double, D, 1>> e, t;
    for (std::size_t i = 0; i < estimate.size(); ++i) {
      e.push_back(estimate[i].template head<D>());
      t.push_back(truth[i].template head<D>());
    }
    return aligned_errors<D>(e, t);
  };
  if (dim == 2) return run.template operator()<2>();
  if (dim == 3) return run.template operator()<3>();
  return {};
}

/// Aligned errors of the trajectory (pose after step k against true pose k + 1) and of the map.
template <class Summary, class Map, class Dataset>
void add_aligned_errors(Summary& out, const Map& map, const Dataset& dataset, int position_dim) {
  std::vector<std::decay_t<decltype(dataset.true_poses[0])>> truth(dataset.true_poses.begin() + 1,
                                                                   dataset.true_poses.begin() + 1 + out.trajectory.size());
  if (position_dim < 0) position_dim = static_cast<int>(truth.empty() ? 0 : truth.front().size());
  out.pose_error_aligned = aligned_position_errors(out.trajectory, truth, position_dim);
  using Point = std::decay_t<decltype(map.front().mean)>;
  std::vector<Point> estimated, true_points;
  for (const auto& landmark : map) {
    estimated.push_back(landmark.mean);
    true_points.push_back(dataset.true_landmarks.at(landmark.id));
  }
  out.map_error_aligned = aligned_position_errors(estimated, true_points, static_cast<int>(Point::RowsAtCompileTime));
}

/// Scores a smoothed trajectory (entry 0 the start, entry k the pose after step k) and the final map.
template <class Space, class Summary, class Poses, class Map, class Dataset>
void score_trajectory(Summary& out, const Poses& trajectory, const Map& final_map, const Dataset& dataset,
                      int position_dim) {
  for (std::size_t k = 1; k < trajectory.size(); ++k) {
    const auto error = Space::minus(trajectory[k].mean, dataset.true_poses[k]);
    out.pose_error.push_back(position_error<Space>(trajectory[k].mean, dataset.true_poses[k], position_dim));
    out.pose_nees.push_back(nees_or_infinity(error, trajectory[k].cov));
    out.trajectory.push_back(trajectory[k].mean);
  }
  auto map = evaluate_map(final_map, dataset.true_landmarks);
  out.map_error = std::move(map.errors);
  out.map_nees = std::move(map.nees);
  out.map_error_over_time = mean(out.map_error);
  add_aligned_errors(out, final_map, dataset, position_dim);
}
/// predict + update over every step of the data set (for_each_step), each timed into out.seconds
/// and out.total_seconds; after(k) once step k is done.
template <class Backend, class Dataset, class Summary, class After>
void run_timed_steps(Backend& backend, const Dataset& dataset, Summary& out, After after, StepErrors on_error) {
  for_each_step(
      backend, dataset.steps, PlainUpdate{},
      [&](std::size_t k, double seconds, const UpdateResult&) {
        out.seconds.push_back(seconds);
        out.total_seconds += seconds;
        after(k);
      },
      failures_under(on_error, out.failures));
}

/// Full SLAM's optimize(), its time added to out.total_seconds and, where it reports them, its
/// iterations, convergence and kept iterate to out.optimization.
template <class Backend, class Summary>
void optimize_timed(Backend& backend, Summary& out) {
  const auto start = std::chrono::steady_clock::now();
  if constexpr (requires { backend.optimize().converged; }) {
    const auto summary = backend.optimize();
    out.optimization = OptimizationOutcome{summary.iterations, summary.converged, summary.best_iteration, summary.damped_from};
  } else {
    backend.optimize();
  }
  out.total_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace detail

/// Runs `backend` over dataset.steps and scores it against dataset.true_poses (row k + 1 is the
/// pose after step k) and dataset.true_landmarks. The position error is the norm of the first
/// `position_dim` entries of minus(estimate, truth) (default: all of them). on_step(k) is called
/// after step k (progress reports). on_error: whether a failed step ends the run (for_each_step).
template <class Backend, class Dataset, class OnStep = NoStepCallback>
RunSummary<typename Backend::State> evaluate_run(Backend& backend, const Dataset& dataset, int position_dim = -1,
                                                 OnStep on_step = {}, StepErrors on_error = StepErrors::propagate) {
  using Space = typename Backend::Space;
  RunSummary<typename Backend::State> out;
  double map_error_sum = 0.0;
  std::size_t steps_with_map = 0;
  const auto record = run(backend, dataset.steps, [&](std::size_t k, const Backend& b) {
    on_step(k);
    if constexpr (requires { b.pose_sample_support(); }) out.pose_support.push_back(b.pose_sample_support());
    const auto map = b.map();
    if (map.empty()) return;
    map_error_sum += mean(evaluate_map(map, dataset.true_landmarks).errors);
    ++steps_with_map;
  }, on_error);
  out.failures = record.failures;
  out.map_error_over_time = steps_with_map ? map_error_sum / static_cast<double>(steps_with_map) : 0.0;
  for (std::size_t k = 0; k < record.steps.size(); ++k) {
    const auto& pose = record.steps[k].pose;
    const auto error = Space::minus(pose.mean, dataset.true_poses[k + 1]);
    out.pose_error.push_back(detail::position_error<Space>(pose.mean, dataset.true_poses[k + 1], position_dim));
    out.pose_nees.push_back(nees_or_infinity(error, pose.cov));
    out.seconds.push_back(record.steps[k].seconds);
    out.trajectory.push_back(pose.mean);
  }
  const auto final_map = backend.map();
  auto map = evaluate_map(final_map, dataset.true_landmarks);
  out.map_error = std::move(map.errors);
  out.map_nees = std::move(map.nees);
  out.total_seconds = record.total_seconds;
  detail::add_aligned_errors(out, final_map, dataset, position_dim);
  return out;
}

/// Full SLAM (a back-end with optimize() and trajectory()): records every step, optimizes once,
/// then scores the optimized trajectory and map. `seconds` holds the recording time of each step;
/// total_seconds adds the optimization.
template <class Backend, class Dataset, class OnStep = NoStepCallback>
  requires requires(Backend& b) { b.optimize(); b.trajectory(); }
RunSummary<typename Backend::State> evaluate_smoothed_run(Backend& backend, const Dataset& dataset, int position_dim = -1,
                                                          OnStep on_step = {},
                                                          StepErrors on_error = StepErrors::propagate) {
  using Space = typename Backend::Space;
  RunSummary<typename Backend::State> out;
  detail::run_timed_steps(backend, dataset, out, on_step, on_error);
  detail::optimize_timed(backend, out);
  detail::score_trajectory<Space>(out, backend.trajectory(), backend.map(), dataset, position_dim);
  return out;
}

/// A particle filter scored by its path posterior (path_posterior(): the path its particles hold
/// after the last step, weighted by the last weights), as full SLAM's smoothed trajectory is; the
/// path's support per step as pose_support. `seconds` holds each step's time; total_seconds adds
/// the path's extraction.
template <class Backend, class Dataset, class OnStep = NoStepCallback>
  requires requires(const Backend& b) { b.path_posterior(); }
RunSummary<typename Backend::State> evaluate_path_run(Backend& backend, const Dataset& dataset, int position_dim = -1,
                                                      OnStep on_step = {}, StepErrors on_error = StepErrors::propagate) {
  using Space = typename Backend::Space;
  RunSummary<typename Backend::State> out;
  detail::run_timed_steps(backend, dataset, out, on_step, on_error);
  const auto start = std::chrono::steady_clock::now();
  const auto path = backend.path_posterior();
  out.total_seconds += seconds_since(start);
  if (path.poses.size() != out.seconds.size() + 1)
    throw invalid_input_error("evaluate_path_run: the path holds " + std::to_string(path.poses.size()) + " poses for " +
                              std::to_string(out.seconds.size()) + " steps and the start (a predict failed)");
  detail::score_trajectory<Space>(out, path.poses, backend.map(), dataset, position_dim);
  out.pose_support.assign(path.support.begin() + 1, path.support.end());
  return out;
}

/// The scores of one run, reduced to the numbers the average over runs needs (RunScores), with the
/// bound of the one-sided NEES test at `confidence`.
template <class State>
RunScores scores_of(const RunSummary<State>& r, int pose_dof, int landmark_dof, double confidence = 0.95) {
  RunScores s;
  s.steps = r.seconds.size();
  s.pose_mae = mean_or_nan(r.pose_error);
  s.pose_rmse = rms_or_nan(r.pose_error);
  s.pose_rmse_aligned = rms_or_nan(r.pose_error_aligned);
  s.pose_mae_aligned = mean_or_nan(r.pose_error_aligned);
  s.map_mae = mean_or_nan(r.map_error);
  s.map_mae_over_time = r.map_error.empty() ? std::numeric_limits<double>::quiet_NaN() : r.map_error_over_time;
  s.map_mae_aligned = mean_or_nan(r.map_error_aligned);
  add_pose_consistency(s, r.pose_nees, r.pose_support, pose_dof, confidence);
  s.map_nees_inside = fraction_at_most_or_nan(r.map_nees, nees_upper_bound(landmark_dof, confidence));
  s.total_seconds = r.total_seconds;
  s.failed_steps = r.failures.total();
  s.first_failure = r.failures.first;
  return s;
}

/// The average of runs (summarize over their RunScores, in the order given).
template <class State>
Summary summarize(const std::vector<RunSummary<State>>& runs, int pose_dof, int landmark_dof, double confidence = 0.95) {
  std::vector<RunScores> scores;
  scores.reserve(runs.size());
  for (const auto& r : runs) scores.push_back(scores_of(r, pose_dof, landmark_dof, confidence));
  return summarize(scores, pose_dof, confidence);
}

/// A run without ground truth (e.g. Victoria Park): the trajectory and the time of every step and
/// nothing scored. Full SLAM (optimize() and trajectory()) is optimized once at the end and gives
/// its smoothed trajectory; a filter its pose after each step.
template <class Backend, class Dataset, class OnStep = NoStepCallback>
RunSummary<typename Backend::State> record_unscored_run(Backend& backend, const Dataset& dataset, OnStep on_step = {},
                                                        StepErrors on_error = StepErrors::propagate) {
  RunSummary<typename Backend::State> out;
  detail::run_timed_steps(
      backend, dataset, out,
      [&](std::size_t k) {
        if constexpr (!requires { backend.optimize(); }) out.trajectory.push_back(backend.pose().mean);
        on_step(k);
      },
      on_error);
  if constexpr (requires { backend.optimize(); backend.trajectory(); }) {
    detail::optimize_timed(backend, out);
    for (const auto& pose : backend.pose_means()) out.trajectory.push_back(pose);
    if (!out.trajectory.empty()) out.trajectory.erase(out.trajectory.begin());  // the start, not a step's pose
  }
  return out;
}

}  // namespace sextant::eval
