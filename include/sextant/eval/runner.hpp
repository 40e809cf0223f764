#pragma once
/// \file Drives any back-end over any stream of steps: the one step loop (for_each_step) that every
/// run in eval, the examples, tests and benchmarks goes through, and run(), which records the pose
/// estimate and the time of every step.

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

/// The update of a plain run: backend.update(step.observations).
struct PlainUpdate {
  template <class Backend, class Step>
  UpdateResult operator()(Backend& backend, const Step& step, std::size_t) const {
    return backend.update(step.observations);
  }
};

/// The step loop: for every step k, backend.predict(control, dt) then update(backend, step, k),
/// timed together; then after(k, seconds, result) with what the update returned. Exceptions from
/// the back-end propagate.
template <class Backend, class Steps, class Update, class After>
void for_each_step(Backend& backend, const Steps& steps, Update&& update, After&& after) {
  using Clock = std::chrono::steady_clock;
  std::size_t k = 0;
  for (const auto& step : steps) {
    const auto start = Clock::now();
    backend.predict(step.control, step.dt);
    UpdateResult result = update(backend, step, k);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    after(k++, seconds, std::move(result));
  }
}

/// Runs predict(control, dt) then update(observations) for every step; calls
/// observer(step_index, backend) after each. Exceptions from the back-end propagate.
template <class Backend, class Steps, class Observer = NoObserver>
  requires SlamBackend<Backend>
auto run(Backend& backend, const Steps& steps, Observer&& observer = {}) {
  RunRecord<decltype(backend.pose())> record;
  record.steps.reserve(std::size(steps));
  for_each_step(backend, steps, PlainUpdate{}, [&](std::size_t k, double seconds, UpdateResult update) {
    record.total_seconds += seconds;
    record.steps.push_back({backend.pose(), seconds, std::move(update)});
    observer(k, std::as_const(backend));
  });
  return record;
}

}  // namespace sextant::eval
