#pragma once
/// \file What motion and measurement models return: predictions with their Jacobians and noise.

#include <Eigen/Core>

namespace sextant {

/// Result of a motion model: x' = g(x, u, dt) (thesis eq. 10), its Jacobian G = dg/dx in the
/// tangent space (eq. 13) and the process noise R in state space (R = V M V^T, eq. 11).
template <class State, int X>
struct MotionPrediction {
  State x;
  Eigen::Matrix<double, X, X> J_x_x;
  Eigen::Matrix<double, X, X> R;
};

/// Result of a measurement model: z_hat = h(x, m) (eq. 98), H split into its robot block
/// J_z_x and landmark block J_z_m (eq. 99), and the measurement noise Q.
template <int Z, int X, int M>
struct MeasurementPrediction {
  Eigen::Matrix<double, Z, 1> z;
  Eigen::Matrix<double, Z, X> J_z_x;
  Eigen::Matrix<double, Z, M> J_z_m;
  Eigen::Matrix<double, Z, Z> Q;
};

/// Result of the inverse measurement model m = h^-1(x, z) for a new landmark, with the Jacobians
/// that give its covariance and cross-covariance: P_mm = J_m_x P_xx J_m_x^T + J_m_z Q J_m_z^T.
template <int M, int X, int Z>
struct LandmarkInit {
  Eigen::Matrix<double, M, 1> m;
  Eigen::Matrix<double, M, X> J_m_x;
  Eigen::Matrix<double, M, Z> J_m_z;
  Eigen::Matrix<double, Z, Z> Q;
};

/// Optional, for full SLAM: the motion factor between two poses as a residual whose covariance does
/// not depend on the poses (e.g. odometry in the robot frame), with its Jacobians. A model whose
/// process noise R depends on the state should offer it: Gauss-Newton on minus(x', g(x, u)) with
/// W = R(x)^-1 would treat W as constant and converge only linearly.
template <int X>
struct BetweenFactor {
  Eigen::Matrix<double, X, 1> r;       ///< zero when x_to = g(x_from, u) exactly
  Eigen::Matrix<double, X, X> J_from;  ///< dr / dx_from (tangent space)
  Eigen::Matrix<double, X, X> J_to;    ///< dr / dx_to
  Eigen::Matrix<double, X, X> cov;     ///< covariance of r
};

}  // namespace sextant
