#pragma once
/// \file One observation linearized at the current estimate: the two non-zero blocks of H, the
/// noise and the residual. Filters in moment and information form consume the same record.

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

template <int Z, int X, int M>
struct LinearizedObservation {
  LandmarkId id;
  Eigen::Index offset;                  ///< first row of the landmark block in the stacked state
  Eigen::Matrix<double, Z, X> J_z_x;    ///< robot block of H (thesis eq. 18)
  Eigen::Matrix<double, Z, M> J_z_m;    ///< landmark block of H
  Eigen::Matrix<double, Z, Z> Q;        ///< measurement noise
  Eigen::Matrix<double, Z, 1> residual; ///< z - h(x, m), wrapped by the model
};

/// Linearizes `sensor` at robot state x and landmark mean m for measurement z, whose noise is
/// `noise_scale` times the model's (Observation::noise_scale). Throws
/// numerical_error when the model returns NaN or Inf, when Q is not positive definite, or when the
/// squared residual weighted by Q^-1 overflows: a measurement that implausible (e.g. 1e300 m from
/// its prediction, or a residual of 1 with sigma 1e-160) is rejected by every back-end, since
/// no Gaussian update can use it (docs/reliability.md). A large but finite one is accepted
/// unless the back-end's gate is on.
template <class Sensor, class State, class Landmark, class Measurement>
auto linearize_observation(const Sensor& sensor, const State& x, const Landmark& m, const Measurement& z,
                           LandmarkId id, Eigen::Index offset, double noise_scale) {
  const auto prediction = with_noise_scale(sensor.predict(x, m), noise_scale);
  using Prediction = decltype(prediction);
  constexpr int Z = decltype(Prediction::z)::RowsAtCompileTime;
  constexpr int X = decltype(Prediction::J_z_x)::ColsAtCompileTime;
  constexpr int M = decltype(Prediction::J_z_m)::ColsAtCompileTime;
  LinearizedObservation<Z, X, M> out{id, offset, prediction.J_z_x, prediction.J_z_m, prediction.Q,
                                     sensor.residual(z, prediction.z)};
  if (!out.J_z_x.allFinite() || !out.J_z_m.allFinite() || !out.Q.allFinite() || !out.residual.allFinite())
    throw numerical_error("measurement model returned NaN or Inf for landmark " + std::to_string(id));
  const auto llt = cholesky_or_throw(out.Q, "measurement noise Q of landmark " + std::to_string(id));
  if (!std::isfinite(mahalanobis_squared(llt, out.residual)))
    throw numerical_error("measurement of landmark " + std::to_string(id) +
                          ": its squared residual weighted by Q^-1 overflows (the measurement is too far from "
                          "its prediction for the noise model)");
  return out;
}

/// linearize_observation, or nothing when the model cannot use the observation at this estimate
/// (unobservable_error, e.g. the landmark behind the camera): its id then goes to `unusable`.
template <class Sensor, class State, class Landmark, class Measurement>
auto linearize_if_observable(const Sensor& sensor, const State& x, const Landmark& m, const Measurement& z,
                             LandmarkId id, Eigen::Index offset, double noise_scale, std::vector<LandmarkId>& unusable)
    -> std::optional<decltype(linearize_observation(sensor, x, m, z, id, offset, noise_scale))> {
  try {
    return linearize_observation(sensor, x, m, z, id, offset, noise_scale);
  } catch (const unobservable_error&) {
    unusable.push_back(id);
    return std::nullopt;
  }
}

}  // namespace sextant
