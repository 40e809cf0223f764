#pragma once
/// \file Drives a back-end over a step stream through a bounded landmark pool (the thesis's
/// vSLAM bookkeeping, core/landmark_pool_policy.hpp), recording the pose mean, the time and the
/// pool's bookkeeping of every step, and the pose with its covariance every few steps (a SEIF's
/// covariance needs a factorization of Omega, which costs more than its step once the map fills in).

#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "sextant/core/concepts.hpp"
#include "sextant/core/landmark_pool_policy.hpp"
#include "sextant/core/pose_mean.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/eval/runner.hpp"

namespace sextant::eval {

/// Whether step k of `count` has its covariance recorded: every period-th step and the last
/// (period 0: none).
inline bool is_sampled_step(std::size_t k, std::size_t count, std::size_t period) {
  return period > 0 && ((k + 1) % period == 0 || k + 1 == count);
}

template <class PoseEstimate>
struct SampledPose {
  std::size_t step;
  PoseEstimate estimate;
};

/// Mean NEES of sampled poses against reference poses (reference[step] is the true pose after that
/// step), the error Space::minus(reference, estimate); +infinity where a covariance is not positive
/// definite; NaN for none.
template <class Space, class PoseEstimate, class Pose>
double sampled_pose_anees(const std::vector<SampledPose<PoseEstimate>>& poses, const std::vector<Pose>& reference) {
  if (poses.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for (const auto& p : poses) sum += nees_or_infinity(Space::minus(reference.at(p.step), p.estimate.mean), p.estimate.cov);
  return sum / static_cast<double>(poses.size());
}

/// What the updates of a run reported, added up over its steps.
struct UpdateTotals {
  std::size_t corrected = 0, initialized = 0, rejected = 0, unusable = 0;
  void add(const UpdateResult& r) {
    corrected += r.corrected;
    initialized += r.initialized;
    rejected += r.rejected.size();
    unusable += r.unusable.size();
  }
};

template <class State, class PoseEstimate>
struct PooledRun {
  std::vector<State> means;                       ///< pose mean after each step
  std::vector<SampledPose<PoseEstimate>> poses;   ///< mean and covariance after every period-th step and the last
  std::vector<double> seconds;                    ///< predict + evictions + update of each step
  std::vector<PoolStepRecord> pool;               ///< bookkeeping of each step
  UpdateTotals updates;                           ///< what the updates reported, over all steps
  StepFailures failures;                          ///< steps skipped under StepErrors::skip
  double total_seconds = 0.0;
};

/// For every step (for_each_step): predict, evict what the pool asks for, update with the admitted
/// observations. covariance_period: record pose() after steps k with (k + 1) % period == 0 and after
/// the last. on_step(k, backend) after step k. Timing excludes the recording. on_error: whether a
/// failed step ends the run (for_each_step); a failed update may follow the evictions it planned.
template <class Backend, class Steps, class OnStep>
  requires SlamBackend<Backend>
auto run_through_pool(Backend& backend, const Steps& steps, PoolLimits limits, std::size_t covariance_period,
                      OnStep&& on_step, StepErrors on_error = StepErrors::propagate) {
  using Measurement = typename Backend::Measurement;
  PooledRun<typename Backend::State, decltype(backend.pose())> out;
  LandmarkPoolPolicy policy(limits);
  const std::size_t count = std::size(steps);
  const auto through_pool = [&](Backend& b, const auto& step, std::size_t k) {
    return update_through_pool(b, policy, std::span<const Observation<Measurement>>(step.observations), k);
  };
  for_each_step(backend, steps, through_pool, [&](std::size_t k, double seconds, const UpdateResult& result) {
    out.seconds.push_back(seconds);
    out.total_seconds += seconds;
    out.updates.add(result);
    out.means.push_back(pose_mean_of(backend));
    if (is_sampled_step(k, count, covariance_period)) out.poses.push_back({k, backend.pose()});
    on_step(k, std::as_const(backend));
  }, failures_under(on_error, out.failures));
  out.pool = policy.history();
  return out;
}

}  // namespace sextant::eval
