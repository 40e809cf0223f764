#pragma once
/// \file Checks any user can run on their own models: every analytic Jacobian against central
/// differences in the tangent space, and the inverse measurement model against the forward one.
/// The result converts to bool and carries a readable report of every mismatch.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "sextant/core/concepts.hpp"
#include "sextant/core/conditionally_linear.hpp"

namespace sextant::testing {

struct CheckResult {
  bool passed = true;
  std::string report;  ///< one line per failed entry: which Jacobian, where, analytic vs numeric
  explicit operator bool() const { return passed; }
};

struct CheckOptions {
  double step = 1e-6;       ///< central-difference step in the tangent space
  double tolerance = 1e-5;  ///< allowed |analytic - numeric| / max(1, |numeric|)
};

namespace detail {

template <class A, class N>
void compare(const std::string& name, const Eigen::MatrixBase<A>& analytic, const Eigen::MatrixBase<N>& numeric,
             const CheckOptions& options, CheckResult& result) {
  for (Eigen::Index r = 0; r < numeric.rows(); ++r)
    for (Eigen::Index c = 0; c < numeric.cols(); ++c) {
      const double a = analytic(r, c), n = numeric(r, c);
      if (std::abs(a - n) > options.tolerance * std::max(1.0, std::abs(n)) || !std::isfinite(a)) {
        std::ostringstream line;
        line << name << "(" << r << "," << c << "): analytic " << a << " vs numeric " << n << "\n";
        result.passed = false;
        result.report += line.str();
      }
    }
}

/// Central difference of f at `base` along each axis of a tangent space of dimension N, where
/// `shift(base, delta)` moves the argument and f returns a vector compared by `difference`.
template <int N, class Base, class Shift, class F, class Difference>
Eigen::MatrixXd central_difference(const Base& base, Shift shift, F f, Difference difference, double step) {
  const auto center = f(base);
  Eigen::MatrixXd out(difference(center, center).size(), N);
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> delta = Eigen::Matrix<double, N, 1>::Zero();
    delta(i) = step;
    const auto forward = f(shift(base, delta));
    const auto backward = f(shift(base, (-delta).eval()));
    out.col(i) = (difference(forward, center) - difference(backward, center)) / (2.0 * step);
  }
  return out;
}

}  // namespace detail

/// Checks MotionPrediction::J_x_x of `model` at (x, u, dt): J = d minus(g(plus(x, d)), g(x)) / d d.
template <class Motion>
  requires MotionModel<Motion>
CheckResult check_motion_jacobians(const Motion& model, const typename Motion::State& x,
                                   const typename Motion::Control& u, double dt, CheckOptions options = {}) {
  using Space = typename Motion::Space;
  CheckResult result;
  const auto numeric = detail::central_difference<Motion::kDim>(
      x, [](const auto& s, const auto& d) { return Space::plus(s, d); },
      [&](const auto& s) { return model.predict(s, u, dt).x; },
      [](const auto& a, const auto& b) { return Space::minus(a, b); }, options.step);
  detail::compare("J_x_x", model.predict(x, u, dt).J_x_x, numeric, options, result);
  return result;
}

/// Checks J_from and J_to of a motion model's between(from, to, u, dt) factor, and that the factor
/// vanishes at to = predict(from, u, dt).
template <class Motion>
  requires HasBetweenFactor<Motion>
CheckResult check_between_jacobians(const Motion& model, const typename Motion::State& from,
                                    const typename Motion::State& to, const typename Motion::Control& u, double dt,
                                    CheckOptions options = {}) {
  using Space = typename Motion::Space;
  const auto shift = [](const auto& s, const auto& d) { return Space::plus(s, d); };
  const auto difference = [](const auto& a, const auto& b) { return (a - b).eval(); };
  CheckResult result;
  const auto factor = model.between(from, to, u, dt);
  detail::compare("J_from", factor.J_from,
                  detail::central_difference<Motion::kDim>(
                      from, shift, [&](const auto& x) { return model.between(x, to, u, dt).r; }, difference, options.step),
                  options, result);
  detail::compare("J_to", factor.J_to,
                  detail::central_difference<Motion::kDim>(
                      to, shift, [&](const auto& x) { return model.between(from, x, u, dt).r; }, difference, options.step),
                  options, result);
  detail::compare("between(from, predict(from, u)).r", model.between(from, model.predict(from, u, dt).x, u, dt).r,
                  Eigen::Matrix<double, Motion::kDim, 1>::Zero(), options, result);
  return result;
}

/// Checks J_z_x and J_z_m of predict(x, m), and J_m_x and J_m_z of initialize(x, z), and that
/// predict(x, initialize(x, z).m) reproduces z.
/// Call as check_measurement_jacobians<MyMotion>(sensor, x, m).
template <class Motion, class Sensor>
  requires MeasurementModelFor<Sensor, Motion>
CheckResult check_measurement_jacobians(const Sensor& sensor, const typename Motion::State& x,
                                        const typename Sensor::Landmark& m, CheckOptions options = {}) {
  using Space = typename Motion::Space;
  using Landmark = typename Sensor::Landmark;
  using Measurement = typename Sensor::Measurement;
  constexpr int M = landmark_dim_v<Sensor>, Z = measurement_dim_v<Sensor>;
  const auto euclidean_shift = [](const auto& v, const auto& d) { return (v + d).eval(); };
  const auto euclidean_difference = [](const auto& a, const auto& b) { return (a - b).eval(); };
  const auto measurement_difference = [&](const auto& a, const auto& b) { return sensor.residual(a, b); };
  CheckResult result;

  const auto prediction = sensor.predict(x, m);
  detail::compare("J_z_x", prediction.J_z_x,
                  detail::central_difference<Motion::kDim>(
                      x, [](const auto& s, const auto& d) { return Space::plus(s, d); },
                      [&](const auto& s) { return Measurement(sensor.predict(s, m).z); }, measurement_difference,
                      options.step),
                  options, result);
  detail::compare("J_z_m", prediction.J_z_m,
                  detail::central_difference<M>(
                      m, euclidean_shift, [&](const Landmark& l) { return Measurement(sensor.predict(x, l).z); },
                      measurement_difference, options.step),
                  options, result);

  const Measurement z = prediction.z;
  const auto init = sensor.initialize(x, z);
  detail::compare("J_m_x", init.J_m_x,
                  detail::central_difference<Motion::kDim>(
                      x, [](const auto& s, const auto& d) { return Space::plus(s, d); },
                      [&](const auto& s) { return Landmark(sensor.initialize(s, z).m); }, euclidean_difference,
                      options.step),
                  options, result);
  detail::compare("J_m_z", init.J_m_z,
                  detail::central_difference<Z>(
                      z, euclidean_shift, [&](const Measurement& w) { return Landmark(sensor.initialize(x, w).m); },
                      euclidean_difference, options.step),
                  options, result);
  const auto round_trip = sensor.residual(Measurement(sensor.predict(x, init.m).z), z);
  detail::compare("inverse model: residual(predict(x, initialize(x, z)), z)", round_trip,
                  Eigen::Matrix<double, Z, 1>::Zero(), options, result);
  return result;
}

/// Checks what a motion model promises with kConditionallyLinearDims = T (core/conditionally_linear.hpp)
/// at (x, u, dt) with a landmark m: moving the tail by d moves g by exactly G d (a step of 1 and of
/// 10 times `tail_step` in each direction, so curvature shows), R does not change, and the
/// measurement neither changes nor has a Jacobian there.
template <class Motion, class Sensor>
  requires MeasurementModelFor<Sensor, Motion>
CheckResult check_conditionally_linear_tail(const Motion& model, const Sensor& sensor, const typename Motion::State& x,
                                            const typename Motion::Control& u, double dt,
                                            const typename Sensor::Landmark& m, double tail_step = 0.1,
                                            CheckOptions options = {.step = 0.0, .tolerance = 1e-10}) {
  using Space = typename Motion::Space;
  constexpr int X = Motion::kDim, T = conditionally_linear_dims_v<Motion>;
  CheckResult result;
  const auto at_x = model.predict(x, u, dt);
  const auto z = sensor.predict(x, m);
  detail::compare("J_z_x on the tail", z.J_z_x.template rightCols<T>(),
                  Eigen::Matrix<double, measurement_dim_v<Sensor>, T>::Zero(), options, result);
  for (int i = 0; i < T; ++i)
    for (double scale : {1.0, -10.0}) {
      Eigen::Matrix<double, X, 1> d = Eigen::Matrix<double, X, 1>::Zero();
      d(X - T + i) = scale * tail_step;
      const auto moved = model.predict(Space::plus(x, d), u, dt);
      const std::string where = " (tail entry " + std::to_string(i) + ", step " + std::to_string(d(X - T + i)) + ")";
      detail::compare("g" + where, Space::minus(moved.x, at_x.x), (at_x.J_x_x * d).eval(), options, result);
      detail::compare("R" + where, moved.R, at_x.R, options, result);
      detail::compare("z" + where, sensor.predict(Space::plus(x, d), m).z, z.z, options, result);
    }
  return result;
}

}  // namespace sextant::testing
