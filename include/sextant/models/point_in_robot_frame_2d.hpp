#pragma once
/// \file A landmark measured as a point in the planar robot's frame: z = Rot(h)^T (m - p), as in
/// the iSAM LANDMARK records (Victoria Park, cityTrees) and laser-extracted tree trunks.

#include <Eigen/Core>
#include <cmath>

#include "sextant/core/model_results.hpp"

namespace sextant {

struct PointInRobotFrame2D {
  using Landmark = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;

  Eigen::Matrix2d Q = Eigen::Matrix2d::Identity();  ///< measurement covariance in the robot frame

  /// z = Rot(h)^T (m - p); J_z_x = [-Rot^T, dRot^T/dh (m - p)], J_z_m = Rot^T.
  MeasurementPrediction<2, 3, 2> predict(const Eigen::Vector3d& x, const Landmark& m) const {
    const double c = std::cos(x(2)), s = std::sin(x(2));
    const Eigen::Vector2d d = m - x.head<2>();
    Eigen::Matrix2d Rt;
    Rt << c, s, -s, c;
    MeasurementPrediction<2, 3, 2> out;
    out.z = Rt * d;
    out.J_z_x.leftCols<2>() = -Rt;
    out.J_z_x.col(2) << -s * d.x() + c * d.y(), -c * d.x() - s * d.y();
    out.J_z_m = Rt;
    out.Q = Q;
    return out;
  }

  Measurement residual(const Measurement& z, const Measurement& z_hat) const { return z - z_hat; }

  /// m = p + Rot(h) z; J_m_x = [I, dRot/dh z], J_m_z = Rot.
  LandmarkInit<2, 3, 2> initialize(const Eigen::Vector3d& x, const Measurement& z) const {
    const double c = std::cos(x(2)), s = std::sin(x(2));
    Eigen::Matrix2d R;
    R << c, -s, s, c;
    LandmarkInit<2, 3, 2> out;
    out.m = x.head<2>() + R * z;
    out.J_m_x.leftCols<2>().setIdentity();
    out.J_m_x.col(2) << -s * z.x() - c * z.y(), c * z.x() - s * z.y();
    out.J_m_z = R;
    out.Q = Q;
    return out;
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D
#include "sextant/compiled/extern_instances.hpp"
