#pragma once
/// \file Input checks shared by the back-ends. Each throws a sextant error that names the problem;
/// back-ends call them before touching their state.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <span>
#include <string>
#include <unordered_set>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

/// Throws invalid_input_error naming `what` when a value (an Eigen vector or matrix, or any type
/// with allFinite(), such as a control carrying its own covariance) has NaN or Inf entries.
template <class T>
  requires requires(const T& t) { { t.allFinite() } -> std::convertible_to<bool>; }
void require_finite(const T& value, const std::string& what) {
  if (!value.allFinite()) throw invalid_input_error(what + " contains NaN or Inf");
}

/// Throws invalid_input_error unless dt is finite and strictly positive.
inline void require_positive_time_step(double dt) {
  if (!std::isfinite(dt) || dt <= 0.0)
    throw invalid_input_error("time step dt must be finite and > 0, got " + std::to_string(dt));
}

/// Throws when an observation is not finite or a landmark id repeats within one update.
template <class Measurement>
void require_valid_observations(std::span<const Observation<Measurement>> observations) {
  std::unordered_set<LandmarkId> seen;
  seen.reserve(observations.size());
  for (const auto& observation : observations) {
    require_finite(observation.z, "measurement of landmark " + std::to_string(observation.landmark_id));
    if (!seen.insert(observation.landmark_id).second)
      throw duplicate_landmark_error("landmark id " + std::to_string(observation.landmark_id) +
                                     " is observed twice in one update");
  }
}

}  // namespace sextant
