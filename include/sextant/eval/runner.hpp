#pragma once
/// \file Drives any back-end over any stream of steps: the one step loop (for_each_step) that every
/// run in eval, the examples, tests and benchmarks goes through, and run(), which records the pose
/// estimate and the time of every step.

#include <chrono>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/concepts.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/update_result.hpp"

namespace sextant::eval {

/// What a run does when a step's predict or update throws a sextant::error.
enum class StepErrors {
  propagate,  ///< the exception leaves the run (tests, benchmarks: a failure is a finding)
  skip,       ///< the step is counted and the run goes on: a program on real data reports, never ends
};

/// The steps a run skipped because their predict or update threw. The back-ends give the strong
/// guarantee, so a skipped predict leaves the back-end as it was before the step (its update is not
/// tried: the observations belong to a pose the filter did not reach), and a skipped update leaves it
/// as the predict left it.
struct StepFailures {
  std::size_t predict = 0, update = 0;
  std::string first;  ///< "step k: predict|update: what" of the first failure

  std::size_t total() const { return predict + update; }
  void record(std::size_t k, bool in_predict, const error& e) {
    ++(in_predict ? predict : update);
    if (first.empty()) first = "step " + std::to_string(k) + ": " + (in_predict ? "predict" : "update") + ": " + e.what();
  }
};

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
  StepFailures failures;  ///< the steps skipped under StepErrors::skip
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
/// timed together; then after(k, seconds, result) with what the update returned. With `failures`
/// null a sextant::error from the back-end propagates; otherwise it is recorded there, after() is
/// called with an empty result and the loop goes on (StepErrors::skip).
template <class Backend, class Steps, class Update, class After>
void for_each_step(Backend& backend, const Steps& steps, Update&& update, After&& after,
                   StepFailures* failures = nullptr) {
  using Clock = std::chrono::steady_clock;
  std::size_t k = 0;
  for (const auto& step : steps) {
    const auto start = Clock::now();
    UpdateResult result;
    bool in_predict = true;
    try {
      backend.predict(step.control, step.dt);
      in_predict = false;
      result = update(backend, step, k);
    } catch (const error& e) {
      if (!failures) throw;
      failures->record(k, in_predict, e);
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    after(k++, seconds, std::move(result));
  }
}

/// The failure record for_each_step takes under `policy`: `failures` to skip, none to propagate.
inline StepFailures* failures_under(StepErrors policy, StepFailures& failures) {
  return policy == StepErrors::skip ? &failures : nullptr;
}

/// Runs predict(control, dt) then update(observations) for every step; calls
/// observer(step_index, backend) after each. Exceptions from the back-end propagate, or with
/// StepErrors::skip are counted in the record's `failures` (for_each_step).
template <class Backend, class Steps, class Observer = NoObserver>
  requires SlamBackend<Backend>
auto run(Backend& backend, const Steps& steps, Observer&& observer = {}, StepErrors on_error = StepErrors::propagate) {
  RunRecord<decltype(backend.pose())> record;
  record.steps.reserve(std::size(steps));
  for_each_step(
      backend, steps, PlainUpdate{},
      [&](std::size_t k, double seconds, UpdateResult update) {
        record.total_seconds += seconds;
        record.steps.push_back({backend.pose(), seconds, std::move(update)});
        observer(k, std::as_const(backend));
      },
      failures_under(on_error, record.failures));
  return record;
}

}  // namespace sextant::eval
