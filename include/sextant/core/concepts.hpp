#pragma once
/// \file The contracts between models and back-ends. Back-ends check them with static_assert,
/// so a model that does not fit gives one readable error instead of a template backtrace.

#include <concepts>
#include <span>
#include <vector>

#include "sextant/core/model_results.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

/// A state-space policy for states of type S with tangent dimension N: plus, minus, is_finite.
template <class Space, class S, int N>
concept StateSpace = requires(const S& x, const Eigen::Matrix<double, N, 1>& delta) {
  { Space::plus(x, delta) } -> std::convertible_to<S>;
  { Space::minus(x, x) } -> std::convertible_to<Eigen::Matrix<double, N, 1>>;
  { Space::is_finite(x) } -> std::convertible_to<bool>;
};

/// A motion model: types State, Control, Space, tangent dimension kDim and
/// predict(x, u, dt) -> MotionPrediction<State, kDim>. Controls are Eigen vectors.
template <class M>
concept MotionModel =
    requires { typename M::State; typename M::Control; typename M::Space; { M::kDim } -> std::convertible_to<int>; } &&
    StateSpace<typename M::Space, typename M::State, M::kDim> &&
    requires(const M& model, const typename M::State& x, const typename M::Control& u, double dt) {
      { model.predict(x, u, dt) } -> std::same_as<MotionPrediction<typename M::State, M::kDim>>;
      { u.allFinite() } -> std::convertible_to<bool>;
    };

/// A motion model that also offers the full-SLAM factor between two poses (see BetweenFactor).
template <class M>
concept HasBetweenFactor =
    MotionModel<M> && requires(const M& model, const typename M::State& x, const typename M::Control& u, double dt) {
      { model.between(x, x, u, dt) } -> std::same_as<BetweenFactor<M::kDim>>;
    };

/// Tangent dimension of a measurement model's Landmark and Measurement types.
template <class S>
inline constexpr int landmark_dim_v = S::Landmark::RowsAtCompileTime;
template <class S>
inline constexpr int measurement_dim_v = S::Measurement::RowsAtCompileTime;

/// A measurement model usable with robot states of motion model Motion: fixed-size Eigen
/// Landmark and Measurement, predict(x, m), residual(z, z_hat) and initialize(x, z).
template <class S, class Motion>
concept MeasurementModelFor =
    MotionModel<Motion> && requires { typename S::Landmark; typename S::Measurement; } &&
    (landmark_dim_v<S> > 0) && (measurement_dim_v<S> > 0) &&
    requires(const S& sensor, const typename Motion::State& x, const typename S::Landmark& m,
             const typename S::Measurement& z) {
      { sensor.predict(x, m) } -> std::same_as<MeasurementPrediction<measurement_dim_v<S>, Motion::kDim, landmark_dim_v<S>>>;
      { sensor.residual(z, z) } -> std::convertible_to<Eigen::Matrix<double, measurement_dim_v<S>, 1>>;
      { sensor.initialize(x, z) } -> std::same_as<LandmarkInit<landmark_dim_v<S>, Motion::kDim, measurement_dim_v<S>>>;
    };

/// Every back-end checks its models with static_assert(ModelsFit<Motion, Sensor>::value): a model
/// that does not fit fails with one of these messages instead of a template backtrace.
template <class Motion, class Sensor>
struct ModelsFit {
  static_assert(MotionModel<Motion>,
                "sextant back-end: Motion must satisfy sextant::MotionModel (types State, Control, Space, constant "
                "kDim, and predict(x, u, dt) returning MotionPrediction<State, kDim>)");
  static_assert(MeasurementModelFor<Sensor, Motion>,
                "sextant back-end: Sensor must satisfy sextant::MeasurementModelFor<Sensor, Motion> (fixed-size Eigen "
                "Landmark and Measurement, predict(x, m) -> MeasurementPrediction, residual(z, z_hat), "
                "initialize(x, z) -> LandmarkInit)");
  static constexpr bool value = MotionModel<Motion> && MeasurementModelFor<Sensor, Motion>;
};

/// The face every back-end shows: predict, update with observations, pose, map, remove_landmark.
template <class B>
concept SlamBackend = requires(B& backend, const B& const_backend, const typename B::Control& u, double dt,
                               std::span<const typename B::ObservationType> observations, LandmarkId id) {
  typename B::State;
  typename B::Control;
  typename B::ObservationType;
  backend.predict(u, dt);
  backend.update(observations);
  const_backend.pose();
  const_backend.map();
  backend.remove_landmark(id);
};

}  // namespace sextant
