#pragma once
/// \file A 6D robot (x, y, z, yaw, pitch, roll) driven by odometry increments measured in its own
/// frame, each with its own 6x6 covariance: MRPT's CActionRobotMovement3D. Jacobians are exact, by
/// automatic differentiation of the pose composition.

#include <Eigen/Core>

#include "sextant/core/autodiff.hpp"
#include "sextant/core/model_results.hpp"
#include "sextant/core/pose3_euler_space.hpp"

namespace sextant {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// An odometry increment (dx, dy, dz, dyaw, dpitch, droll) in the robot frame and its covariance.
struct OdometryIncrement3D {
  Vector6d delta = Vector6d::Zero();
  Matrix6d cov = Matrix6d::Identity();
  bool allFinite() const { return delta.allFinite() && cov.allFinite(); }
};

/// x' = x (+) delta (pose composition); G = dx'/dx, R = V cov V^T with V = dx'/ddelta. dt is not used.
struct Se3Odometry {
  using State = Vector6d;
  using Control = OdometryIncrement3D;
  using Space = Pose3EulerSpace;
  static constexpr int kDim = 6;

  MotionPrediction<State, 6> predict(const State& x, const Control& u, double /*dt*/) const {
    const auto f = value_and_jacobians<6>(
        [](const auto& pose, const auto& delta) {
          using Scalar = typename std::decay_t<decltype(pose)>::Scalar;
          return compose<Scalar>(pose, delta);
        },
        x, u.delta);
    MotionPrediction<State, 6> out;
    out.x = Space::plus(f.value, Vector6d::Zero());
    out.J_x_x = f.jacobian_a;
    const Matrix6d& V = f.jacobian_b;
    out.R = V * u.cov * V.transpose();
    out.R = (0.5 * (out.R + out.R.transpose())).eval();
    return out;
  }

  /// The odometry factor: r = ((-)x_from (+) x_to) - delta, angles wrapped; cov = u.cov.
  BetweenFactor<6> between(const State& from, const State& to, const Control& u, double /*dt*/) const {
    const auto f = value_and_jacobians<6>(
        [&u](const auto& a, const auto& b) {
          using Scalar = typename std::decay_t<decltype(a)>::Scalar;
          return euler_difference<Scalar>(relative_pose<Scalar>(a, b), u.delta.cast<Scalar>());
        },
        from, to);
    BetweenFactor<6> out;
    out.r = f.value;
    out.J_from = f.jacobian_a;
    out.J_to = f.jacobian_b;
    out.cov = u.cov;
    return out;
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_SE3_ODOMETRY
#include "sextant/compiled/extern_instances.hpp"
