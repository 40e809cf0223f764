#pragma once
/// \file Drives a back-end over a step stream through a bounded landmark pool (the thesis's
/// vSLAM bookkeeping, core/landmark_pool_policy.hpp), recording the pose mean, the time and the
/// pool's bookkeeping of every step, and the pose with its covariance every few steps (a SEIF's
/// covariance needs a factorization of Omega, which costs more than its step once the map fills in).

#include <chrono>
#include <span>
#include <utility>
#include <vector>

#include "sextant/core/concepts.hpp"
#include "sextant/core/landmark_pool_policy.hpp"

namespace sextant::eval {

/// The pose mean of any back-end, by pose_mean() where it has one (SEIF), else pose().mean.
template <class Backend>
typename Backend::State pose_mean_of(const Backend& backend) {
  if constexpr (requires { backend.pose_mean(); })
    return backend.pose_mean();
  else
    return backend.pose().mean;
}

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

template <class State, class PoseEstimate>
struct PooledRun {
  std::vector<State> means;                       ///< pose mean after each step
  std::vector<SampledPose<PoseEstimate>> poses;   ///< mean and covariance after every period-th step and the last
  std::vector<double> seconds;                    ///< predict + evictions + update of each step
  std::vector<PoolStepRecord> pool;               ///< bookkeeping of each step
  double total_seconds = 0.0;
};

/// For every step: predict, evict what the pool asks for, update with the admitted observations.
/// covariance_period: record pose() after steps k with (k + 1) % period == 0 and after the last.
/// on_step(k, backend) after step k. Timing excludes the recording.
template <class Backend, class Steps, class OnStep>
  requires SlamBackend<Backend>
auto run_through_pool(Backend& backend, const Steps& steps, PoolLimits limits, std::size_t covariance_period,
                      OnStep&& on_step) {
  using Clock = std::chrono::steady_clock;
  using Measurement = typename Backend::Measurement;
  PooledRun<typename Backend::State, decltype(backend.pose())> out;
  LandmarkPoolPolicy policy(limits);
  const std::size_t count = std::size(steps);
  std::size_t k = 0;
  for (const auto& step : steps) {
    const auto start = Clock::now();
    backend.predict(step.control, step.dt);
    update_through_pool(backend, policy, std::span<const Observation<Measurement>>(step.observations), k);
    out.seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    out.total_seconds += out.seconds.back();
    out.means.push_back(pose_mean_of(backend));
    if (is_sampled_step(k, count, covariance_period))
      out.poses.push_back({k, backend.pose()});
    on_step(k++, std::as_const(backend));
  }
  out.pool = policy.history();
  return out;
}

}  // namespace sextant::eval
