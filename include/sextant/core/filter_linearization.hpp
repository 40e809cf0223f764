#pragma once
/// \file The filters' linearization of one observation (EKF, SEIF, and their iterated updates): the
/// model linearized at a robot state and landmark mean, its Jacobians then taken at the landmark's
/// first estimate (core/first_estimates.hpp) and constrained to keep the unobservable directions
/// (core/observability_constraints.hpp) when the filter's options ask for them.

#include <optional>
#include <vector>

#include "sextant/core/first_estimates.hpp"
#include "sextant/core/linearized_observation.hpp"
#include "sextant/core/observability_constraints.hpp"

namespace sextant {

/// Which Jacobians a filter's observations get (EkfOptions, SeifOptions).
struct JacobianChoice {
  bool first_estimate_jacobians = false;
  bool observability_constraints = false;
};

/// `observation` linearized at robot state x and landmark mean m; `first` is the landmark's first
/// estimate, `propagated` the robot state after the last prediction. Nothing when the model cannot
/// use the observation there (its id then goes to `unusable`).
template <class Space, class Sensor, class Landmark, class Observation>
auto linearize_for_filter(const Sensor& sensor, const typename Space::Point& x, const Landmark& m,
                          const Landmark& first, const Observation& observation, Eigen::Index offset,
                          const typename Space::Point& propagated, JacobianChoice choice,
                          std::vector<LandmarkId>& unusable) {
  auto lin = linearize_if_observable(sensor, x, m, observation.z, observation.landmark_id, offset,
                                     observation.noise_scale, unusable);
  if (!lin) return lin;
  if (choice.first_estimate_jacobians) use_first_estimate_jacobians(sensor, x, first, observation.z, *lin);
  constrain_observation_if<Space>(choice.observability_constraints, *lin, propagated, first);
  return lin;
}

}  // namespace sextant
