#pragma once
/// \file Drives any back-end over any stream of steps, recording the pose estimate and the time
/// of every step. Examples, tests and benchmarks all use it.

#include <chrono>
#include <iterator>
#include <utility>
#include <vector>

#include "sextant/core/concepts.hpp"
#include "sextant/core/update_result.hpp"

namespace sextant::eval {

/// What the runner records for one step.
template <class PoseEstimate>
struct StepRecord {
  PoseEstimate pose;    ///< estimate after the step's update
  double seconds;       ///< wall time of predict + update
  UpdateResult update;  ///< what the update reported
};

template <class PoseEstimate>
struct RunRecord {
  std::vector<StepRecord<PoseEstimate>> steps;
  double total_seconds = 0.0;
};

/// An observer that does nothing.
struct NoObserver {
  template <class Backend>
  void operator()(std::size_t, const Backend&) const {}
};

/// Runs predict(control, dt) then update(observations) for every step; calls
/// observer(step_index, backend) after each. Exceptions from the back-end propagate.
template <class Backend, class Steps, class Observer = NoObserver>
  requires SlamBackend<Backend>
auto run(Backend& backend, const Steps& steps, Observer&& observer = {}) {
  using Clock = std::chrono::steady_clock;
  RunRecord<decltype(backend.pose())> record;
  record.steps.reserve(std::size(steps));
  std::size_t index = 0;
  for (const auto& step : steps) {
    const auto start = Clock::now();
    backend.predict(step.control, step.dt);
    UpdateResult update = backend.update(step.observations);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    record.total_seconds += seconds;
    record.steps.push_back({backend.pose(), seconds, std::move(update)});
    observer(index++, std::as_const(backend));
  }
  return record;
}

}  // namespace sextant::eval
