#pragma once
/// \file Range, yaw and pitch to a 3D point landmark from a sensor mounted on a 6D robot (MRPT's
/// CObservationBearingRange): with l = the landmark in the sensor frame, z = (|l|, atan2(l_y, l_x),
/// -atan2(l_z, |l_xy|)) (pitch is minus the elevation, as CPose3D::sphericalCoordinates gives it).
/// Pairs with Se3Odometry. Jacobians by automatic differentiation.

#include <Eigen/Core>
#include <cmath>

#include "sextant/core/autodiff.hpp"
#include "sextant/core/model_results.hpp"
#include "sextant/core/pose3_euler_space.hpp"

namespace sextant {

struct RangeBearing3D {
  using Landmark = Eigen::Vector3d;
  using Measurement = Eigen::Vector3d;  ///< (range, yaw, pitch) in the sensor frame

  Eigen::Matrix<double, 6, 1> sensor_pose = Eigen::Matrix<double, 6, 1>::Zero();  ///< sensor on the robot
  Eigen::Matrix3d Q = Eigen::Matrix3d::Identity();  ///< covariance of (range, yaw, pitch)

  MeasurementPrediction<3, 6, 3> predict(const Eigen::Matrix<double, 6, 1>& x, const Landmark& m) const {
    const auto f = value_and_jacobians<3>(
        [this](const auto& pose, const auto& landmark) {
          using Scalar = typename std::decay_t<decltype(pose)>::Scalar;
          return spherical<Scalar>(point_in_frame<Scalar>(sensor_in_world<Scalar>(pose), landmark));
        },
        x, m);
    MeasurementPrediction<3, 6, 3> out;
    out.z = f.value;
    out.J_z_x = f.jacobian_a;
    out.J_z_m = f.jacobian_b;
    out.Q = Q;
    return out;
  }

  Measurement residual(const Measurement& z, const Measurement& z_hat) const {
    return {z(0) - z_hat(0), wrap_angle_generic(z(1) - z_hat(1)), wrap_angle_generic(z(2) - z_hat(2))};
  }

  /// m = sensor (+) (r cos(p) cos(y), r cos(p) sin(y), -r sin(p)).
  LandmarkInit<3, 6, 3> initialize(const Eigen::Matrix<double, 6, 1>& x, const Measurement& z) const {
    const auto f = value_and_jacobians<3>(
        [this](const auto& pose, const auto& measurement) {
          using Scalar = typename std::decay_t<decltype(pose)>::Scalar;
          using std::cos;
          using std::sin;
          const Pose3Euler<Scalar> sensor = sensor_in_world<Scalar>(pose);
          const Scalar r = measurement(0), yaw = measurement(1), pitch = measurement(2);
          const Eigen::Matrix<Scalar, 3, 1> local(r * cos(pitch) * cos(yaw), r * cos(pitch) * sin(yaw), -r * sin(pitch));
          return Eigen::Matrix<Scalar, 3, 1>(sensor.template head<3>() + rotation_of(sensor) * local);
        },
        x, z);
    LandmarkInit<3, 6, 3> out;
    out.m = f.value;
    out.J_m_x = f.jacobian_a;
    out.J_m_z = f.jacobian_b;
    out.Q = Q;
    return out;
  }

  /// The sensor's pose in the world: robot (+) mount.
  template <class Scalar>
  Pose3Euler<Scalar> sensor_in_world(const Pose3Euler<Scalar>& robot) const {
    return compose<Scalar>(robot, sensor_pose.cast<Scalar>());
  }

  /// (range, yaw, pitch) of a point in the sensor frame.
  template <class Scalar>
  static Eigen::Matrix<Scalar, 3, 1> spherical(const Eigen::Matrix<Scalar, 3, 1>& l) {
    using std::atan2;
    using std::sqrt;
    const Scalar horizontal = sqrt(l(0) * l(0) + l(1) * l(1));
    return {sqrt(horizontal * horizontal + l(2) * l(2)), atan2(l(1), l(0)), Scalar(-atan2(l(2), horizontal))};
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_RANGE_BEARING_3D
#include "sextant/compiled/extern_instances.hpp"
