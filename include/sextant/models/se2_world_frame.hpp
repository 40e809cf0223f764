#pragma once
/// \file Planar models with the pose perturbed in the world frame. Any SE(2) motion model whose Space
/// is Se2Space (x, y, heading perturbed additively) and any measurement model for it can be wrapped:
/// the wrapped pair has the same predictions, with every Jacobian and noise covariance expressed in
/// the world-frame perturbation x (+) d = (Rot(d_h) p + d_p, h + d_h), the planar form of
/// Se3Perturbation::world. Why: in this chart the unobservable directions of planar SLAM (a global
/// translation rho and rotation phi move the pose by d = (rho, phi) and each landmark by
/// rho + phi J m) do not depend on the robot's estimate, and a body-frame motion has the Jacobian I
/// exactly. With the measurement Jacobians at each landmark's first estimate
/// (EkfOptions::first_estimate_jacobians) every H then annihilates the same null space and the EKF
/// gains no spurious information about the global heading (Huang, Mourikis and Roumeliotis 2008;
/// docs/derivations/se2_world_frame.md). In the additive chart the same needs the motion Jacobian at
/// the previous prediction instead of the current estimate.

#include <Eigen/Core>
#include <cmath>
#include <type_traits>
#include <utility>

#include "sextant/core/concepts.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/se2_space.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant {

/// (x, y, heading) perturbed in the world frame: plus(x, d) = (Rot(d_h) p + d_p, wrap(h + d_h)),
/// minus(a, b) = the d with plus(b, d) = a.
struct Se2WorldSpace {
  static constexpr int kDim = 3;
  using Point = Eigen::Vector3d;
  using Tangent = Eigen::Vector3d;

  static Point plus(const Point& x, const Tangent& d) {
    const double c = std::cos(d(2)), s = std::sin(d(2));
    return {c * x(0) - s * x(1) + d(0), s * x(0) + c * x(1) + d(1), wrap_angle(x(2) + d(2))};
  }
  static Tangent minus(const Point& a, const Point& b) {
    const double h = wrap_angle(a(2) - b(2)), c = std::cos(h), s = std::sin(h);
    return {a(0) - (c * b(0) - s * b(1)), a(1) - (s * b(0) + c * b(1)), h};
  }
  static bool is_finite(const Point& x) { return x.allFinite(); }
  /// The position error in metres (minus() mixes in the heading error times the distance from the
  /// origin): what eval reports as position error.
  static Eigen::Vector2d position_error(const Point& a, const Point& b) { return a.head<2>() - b.head<2>(); }

  /// d plus(x, d) / d d at d = 0, read in the additive chart: the world perturbation moves the
  /// position by d_p + d_h J p, J = [0 -1; 1 0].
  static Eigen::Matrix3d to_additive(const Point& x) {
    Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
    T(0, 2) = -x(1);
    T(1, 2) = x(0);
    return T;
  }
  /// The Jacobians of minus and plus (docs/derivations/state_space_jacobians.md), J = [0 -1; 1 0],
  /// r = minus(a, b): d minus(plus(a, e), b) / de = [I J r_p; 0 1] (a turn of a about the origin
  /// turns the residual's position with it);
  static Eigen::Matrix3d minus_jacobian_first(const Point& a, const Point& b) {
    const Tangent r = minus(a, b);
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(0, 2) = -r(1);
    D(1, 2) = r(0);
    return D;
  }
  /// d minus(a, plus(b, e)) / de = [-Rot(r_h) 0; 0 -1];
  static Eigen::Matrix3d minus_jacobian_second(const Point& a, const Point& b) {
    const double h = wrap_angle(a(2) - b(2)), c = std::cos(h), s = std::sin(h);
    Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
    D.topLeftCorner<2, 2>() << -c, s, -s, -c;
    D(2, 2) = -1.0;
    return D;
  }
  /// G with plus(x, d + e) = plus(plus(x, d), G e) to first order: [I -J d_p; 0 1].
  static Eigen::Matrix3d plus_jacobian(const Point&, const Tangent& d) {
    Eigen::Matrix3d G = Eigen::Matrix3d::Identity();
    G(0, 2) = d(1);
    G(1, 2) = -d(0);
    return G;
  }
  /// The inverse of to_additive(x).
  static Eigen::Matrix3d from_additive(const Point& x) {
    Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
    T(0, 2) = x(1);
    T(1, 2) = -x(0);
    return T;
  }
};

/// A planar motion model with its Jacobians and noise in the world-frame perturbation:
/// G_w = T(x')^-1 G T(x), R_w = T(x')^-1 R T(x')^-T, and the GraphSLAM factor's Jacobians J T.
template <class Motion>
struct InWorldFrame : Motion {
  static_assert(std::is_same_v<typename Motion::Space, Se2Space>, "InWorldFrame wraps a model on Se2Space");
  using Space = Se2WorldSpace;
  using typename Motion::State;
  using typename Motion::Control;

  InWorldFrame() = default;
  explicit InWorldFrame(Motion model) : Motion(std::move(model)) {}

  MotionPrediction<State, 3> predict(const State& x, const Control& u, double dt) const {
    auto out = Motion::predict(x, u, dt);
    const Eigen::Matrix3d back = Space::from_additive(out.x);
    out.J_x_x = back * out.J_x_x * Space::to_additive(x);
    out.R = back * out.R * back.transpose();
    out.R = (0.5 * (out.R + out.R.transpose())).eval();
    return out;
  }
  BetweenFactor<3> between(const State& from, const State& to, const Control& u, double dt) const
    requires HasBetweenFactor<Motion>
  {
    auto out = Motion::between(from, to, u, dt);
    out.J_from = out.J_from * Space::to_additive(from);
    out.J_to = out.J_to * Space::to_additive(to);
    return out;
  }
};

/// A measurement model for planar robots with its robot Jacobians in the world-frame perturbation.
template <class Sensor>
struct SeenInWorldFrame : Sensor {
  using typename Sensor::Landmark;
  using typename Sensor::Measurement;
  static constexpr int Z = Measurement::RowsAtCompileTime, M = Landmark::RowsAtCompileTime;

  SeenInWorldFrame() = default;
  explicit SeenInWorldFrame(Sensor model) : Sensor(std::move(model)) {}

  MeasurementPrediction<Z, 3, M> predict(const Eigen::Vector3d& x, const Landmark& m) const {
    auto out = Sensor::predict(x, m);
    out.J_z_x = out.J_z_x * Se2WorldSpace::to_additive(x);
    return out;
  }
  LandmarkInit<M, 3, Z> initialize(const Eigen::Vector3d& x, const Measurement& z) const {
    auto out = Sensor::initialize(x, z);
    out.J_m_x = out.J_m_x * Se2WorldSpace::to_additive(x);
    return out;
  }
};

/// A pose Gaussian given in the additive chart, expressed in the world-frame perturbation.
inline Gaussian<Eigen::Vector3d, 3> in_world_frame(const Gaussian<Eigen::Vector3d, 3>& additive) {
  const Eigen::Matrix3d back = Se2WorldSpace::from_additive(additive.mean);
  return {additive.mean, back * additive.cov * back.transpose()};
}

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_SE2_WORLD_FRAME
#include "sextant/compiled/extern_instances.hpp"
