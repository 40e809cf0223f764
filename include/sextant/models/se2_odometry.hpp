#pragma once
/// \file A planar robot driven by odometry increments measured in its own frame, each with its own
/// covariance (wheel odometry, MRPT's CActionRobotMovement2D, the iSAM/g2o EDGE2 and ODOMETRY records).

#include <Eigen/Core>
#include <cmath>

#include "sextant/core/model_results.hpp"
#include "sextant/core/se2_space.hpp"

namespace sextant {

/// An odometry increment (dx, dy, dheading) in the robot frame and its covariance.
struct OdometryIncrement2D {
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  bool allFinite() const { return delta.allFinite() && cov.allFinite(); }
};

/// x' = x (+) delta: (x + c dx - s dy, y + s dx + c dy, wrap(h + dh)), c = cos h, s = sin h.
/// G = dx'/dx, R = V cov V^T with V = dx'/ddelta = blockdiag(Rot(h), 1). dt is not used.
struct Se2Odometry {
  using State = Eigen::Vector3d;
  using Control = OdometryIncrement2D;
  using Space = Se2Space;
  static constexpr int kDim = 3;

  MotionPrediction<State, 3> predict(const State& x, const Control& u, double /*dt*/) const {
    const double c = std::cos(x(2)), s = std::sin(x(2));
    const double dx = u.delta(0), dy = u.delta(1);
    MotionPrediction<State, 3> out;
    out.x = Space::plus(x, Eigen::Vector3d(c * dx - s * dy, s * dx + c * dy, u.delta(2)));
    out.J_x_x << 1, 0, -s * dx - c * dy, 0, 1, c * dx - s * dy, 0, 0, 1;
    Eigen::Matrix3d V = Eigen::Matrix3d::Identity();
    V.topLeftCorner<2, 2>() << c, -s, s, c;
    out.R = V * u.cov * V.transpose();
    out.R = (0.5 * (out.R + out.R.transpose())).eval();
    return out;
  }

  /// The odometry factor in the robot frame (iSAM/g2o EDGE2): r = (x_from (-) x_to) - delta, i.e.
  /// r_xy = Rot(h_from)^T (p_to - p_from) - delta_xy, r_h = wrap(h_to - h_from - delta_h), cov = u.cov.
  BetweenFactor<3> between(const State& from, const State& to, const Control& u, double /*dt*/) const {
    const double c = std::cos(from(2)), s = std::sin(from(2));
    const Eigen::Vector2d d = to.head<2>() - from.head<2>();
    Eigen::Matrix2d Rt;
    Rt << c, s, -s, c;
    BetweenFactor<3> out;
    out.r << Rt * d - u.delta.head<2>(), wrap_angle(to(2) - from(2) - u.delta(2));
    out.J_from.setZero();
    out.J_from.topLeftCorner<2, 2>() = -Rt;
    out.J_from.block<2, 1>(0, 2) << -s * d.x() + c * d.y(), -c * d.x() - s * d.y();
    out.J_from(2, 2) = -1.0;
    out.J_to.setZero();
    out.J_to.topLeftCorner<2, 2>() = Rt;
    out.J_to(2, 2) = 1.0;
    out.cov = u.cov;
    return out;
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_SE2_ODOMETRY
#include "sextant/compiled/extern_instances.hpp"
