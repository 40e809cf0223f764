#pragma once
/// \file Range and bearing to a point landmark from a sensor mounted on a planar robot (MRPT's
/// CObservationBearingRange with pitch 0, laser-extracted beacons). Pairs with Se2Odometry for
/// the robot: x = (x, y, heading), odometry increments in the robot frame.

#include <Eigen/Core>
#include <cmath>

#include "sextant/core/model_results.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant {

struct RangeBearing2D {
  using Landmark = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;  ///< (range, bearing), bearing in the sensor frame

  Eigen::Vector3d sensor_pose = Eigen::Vector3d::Zero();  ///< (x, y, heading) of the sensor on the robot
  Eigen::Matrix2d Q = Eigen::Matrix2d::Identity();         ///< covariance of (range, bearing)

  /// Sensor position s = p + Rot(h) t_s, heading h + h_s; with d = m - s, q = |d|^2:
  /// z = (sqrt q, wrap(atan2(d_y, d_x) - h - h_s)).
  MeasurementPrediction<2, 3, 2> predict(const Eigen::Vector3d& x, const Landmark& m) const {
    const double c = std::cos(x(2)), s = std::sin(x(2));
    const Eigen::Vector2d t(c * sensor_pose(0) - s * sensor_pose(1), s * sensor_pose(0) + c * sensor_pose(1));
    const Eigen::Vector2d d = m - x.head<2>() - t;
    const double q = d.squaredNorm(), r = std::sqrt(q);
    MeasurementPrediction<2, 3, 2> out;
    out.z << r, wrap_angle(std::atan2(d.y(), d.x()) - x(2) - sensor_pose(2));
    out.J_z_m << d.x() / r, d.y() / r, -d.y() / q, d.x() / q;
    out.J_z_x.leftCols<2>() = -out.J_z_m;
    // ds/dh = (-t_y, t_x), so dd/dh = (t_y, -t_x).
    const Eigen::Vector2d dd_dh(t.y(), -t.x());
    out.J_z_x.col(2) = out.J_z_m * dd_dh - Eigen::Vector2d(0.0, 1.0);
    out.Q = Q;
    return out;
  }

  Measurement residual(const Measurement& z, const Measurement& z_hat) const {
    return {z(0) - z_hat(0), wrap_angle(z(1) - z_hat(1))};
  }

  /// m = s + r (cos a, sin a), a = h + h_s + bearing.
  LandmarkInit<2, 3, 2> initialize(const Eigen::Vector3d& x, const Measurement& z) const {
    const double c = std::cos(x(2)), s = std::sin(x(2));
    const Eigen::Vector2d t(c * sensor_pose(0) - s * sensor_pose(1), s * sensor_pose(0) + c * sensor_pose(1));
    const double a = x(2) + sensor_pose(2) + z(1), ca = std::cos(a), sa = std::sin(a);
    LandmarkInit<2, 3, 2> out;
    out.m = x.head<2>() + t + z(0) * Eigen::Vector2d(ca, sa);
    out.J_m_x.leftCols<2>().setIdentity();
    out.J_m_x.col(2) << -t.y() - z(0) * sa, t.x() + z(0) * ca;
    out.J_m_z << ca, -z(0) * sa, sa, z(0) * ca;
    out.Q = Q;
    return out;
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_RANGE_BEARING_2D
#include "sextant/compiled/extern_instances.hpp"
