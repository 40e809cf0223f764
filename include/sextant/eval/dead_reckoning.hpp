#pragma once
/// \file Dead reckoning: the motion model's mean integrated over a step stream's controls from a
/// start state, with no measurement (eq. 10 without the covariance): the baseline a SLAM back-end
/// must beat on the same controls.

#include <vector>

namespace sextant::eval {

/// States after each step: out[k] is the state after steps[k] (the start itself is not included).
template <class Motion, class State, class Steps>
std::vector<State> dead_reckoning(const Motion& motion, const State& start, const Steps& steps) {
  std::vector<State> out;
  out.reserve(std::size(steps));
  State x = start;
  for (const auto& step : steps) out.push_back(x = motion.predict(x, step.control, step.dt).x);
  return out;
}

}  // namespace sextant::eval
