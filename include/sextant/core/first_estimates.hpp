#pragma once
/// \file First-estimate Jacobians (Huang, Mourikis and Roumeliotis 2008, for landmarks): the step
/// that evaluates an observation's H at the landmark's mean when it entered the map (kept by the
/// landmark store, core/landmark_store.hpp) while its residual stays at the current estimate.
/// Shared by the filters (EKF, SEIF).

#include <Eigen/Core>
#include <vector>

#include "sextant/core/linearized_observation.hpp"

namespace sextant {

/// Replaces lin's H with the one at the landmark's first estimate `first`; the residual stays the
/// one at the current estimate. Where the model cannot predict from the first estimate (e.g.
/// behind the camera from here), H stays current. Only H is taken from there: the noise stays lin's.
template <class Sensor, class State, class Landmark, class Measurement, int Z, int X, int M>
void use_first_estimate_jacobians(const Sensor& sensor, const State& x, const Landmark& first, const Measurement& z,
                                  LinearizedObservation<Z, X, M>& lin) {
  std::vector<LandmarkId> unusable_from_first;
  const auto at_first = linearize_if_observable(sensor, x, first, z, lin.id, lin.offset, 1.0, unusable_from_first);
  if (!at_first) return;
  lin.J_z_x = at_first->J_z_x;
  lin.J_z_m = at_first->J_z_m;
}

}  // namespace sextant
