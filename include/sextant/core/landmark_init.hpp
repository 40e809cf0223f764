#pragma once
/// \file The inverse measurement model of a new landmark, checked: every back-end adds landmarks
/// through this one call.

#include <optional>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

/// sensor.initialize(x, z) for landmark `id`, its Q scaled by `noise_scale` (Observation::noise_scale); throws numerical_error when the model returns NaN or
/// Inf, a measurement noise Q that is not positive definite, or a landmark whose covariance from
/// the measurement, J_m_z Q J_m_z^T, overflows (a range-bearing landmark at 1e300 m: r^2 sigma^2).
template <class Sensor, class State, class Measurement>
auto initialize_landmark(const Sensor& sensor, const State& x, const Measurement& z, LandmarkId id,
                         double noise_scale) {
  auto init = with_noise_scale(sensor.initialize(x, z), noise_scale);
  if (!init.m.allFinite() || !init.J_m_x.allFinite() || !init.J_m_z.allFinite() || !init.Q.allFinite())
    throw numerical_error("inverse measurement model returned NaN or Inf for landmark " + std::to_string(id));
  cholesky_or_throw(init.Q, "measurement noise Q of new landmark " + std::to_string(id));
  if (!(init.J_m_z * init.Q * init.J_m_z.transpose()).allFinite())
    throw numerical_error("covariance of new landmark " + std::to_string(id) +
                          " overflows: it is measured too far away for the noise model");
  return init;
}

/// initialize_landmark, or nothing when the model cannot place this landmark (unobservable_error,
/// e.g. a stereo pair with disparity <= 0): its id then goes to `unusable`.
template <class Sensor, class State, class Measurement>
auto initialize_if_observable(const Sensor& sensor, const State& x, const Measurement& z, LandmarkId id,
                              double noise_scale, std::vector<LandmarkId>& unusable)
    -> std::optional<decltype(initialize_landmark(sensor, x, z, id, noise_scale))> {
  try {
    return initialize_landmark(sensor, x, z, id, noise_scale);
  } catch (const unobservable_error&) {
    unusable.push_back(id);
    return std::nullopt;
  }
}

}  // namespace sextant
