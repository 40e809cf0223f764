#pragma once
/// \file Rigid motions SE(3) as 4x4 homogeneous matrices T = [R p; 0 1], with tangent vectors
/// xi = (rho, phi) in R^6, translation part first (seed 004's u = (v, omega), eq. 14): hat and
/// vee, exp and log, the adjoint Ad(T) and its algebra form ad(xi) (the "curly hat"), the odot
/// operator of homogeneous points (xi^ s = s^odot xi), and the left and right Jacobians with their
/// inverses. Conventions and formulas follow Barfoot, "State Estimation for Robotics", sec. 7.1;
/// docs/derivations/stereo_imu_se3.md states each one and how the tests check it.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "sextant/core/so3.hpp"

namespace sextant::se3 {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

inline Eigen::Matrix3d rotation(const Eigen::Matrix4d& T) { return T.topLeftCorner<3, 3>(); }
inline Eigen::Vector3d translation(const Eigen::Matrix4d& T) { return T.topRightCorner<3, 1>(); }

/// [R p; 0 1].
inline Eigen::Matrix4d make(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = p;
  return T;
}

/// T^-1 = [R^T -R^T p; 0 1].
inline Eigen::Matrix4d inverse(const Eigen::Matrix4d& T) {
  const Eigen::Matrix3d Rt = rotation(T).transpose();
  return make(Rt, -Rt * translation(T));
}

/// xi^ = [phi^ rho; 0 0] (seed 004 eq. 14).
inline Eigen::Matrix4d hat(const Vector6d& xi) {
  Eigen::Matrix4d X = Eigen::Matrix4d::Zero();
  X.topLeftCorner<3, 3>() = so3::hat(xi.tail<3>());
  X.topRightCorner<3, 1>() = xi.head<3>();
  return X;
}

inline Vector6d vee(const Eigen::Matrix4d& X) {
  Vector6d xi;
  xi << X.topRightCorner<3, 1>(), so3::vee(X.topLeftCorner<3, 3>());
  return xi;
}

/// ad(xi) = [phi^ rho^; 0 phi^]: (xi1^ xi2^ - xi2^ xi1^) = (ad(xi1) xi2)^.
inline Matrix6d curly_hat(const Vector6d& xi) {
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = A.bottomRightCorner<3, 3>() = so3::hat(xi.tail<3>());
  A.topRightCorner<3, 3>() = so3::hat(xi.head<3>());
  return A;
}

/// Ad(T) = [R p^R; 0 R]: T exp(xi^) T^-1 = exp((Ad(T) xi)^).
inline Matrix6d adjoint(const Eigen::Matrix4d& T) {
  const Eigen::Matrix3d R = rotation(T);
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = A.bottomRightCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = so3::hat(translation(T)) * R;
  return A;
}

/// For a homogeneous point s = (e, eta): s^odot = [eta I  -e^; 0 0] (4x6), so that xi^ s = s^odot xi
/// (seed 004 eq. 41 uses it for the pose Jacobian of a projected landmark).
inline Eigen::Matrix<double, 4, 6> odot(const Eigen::Vector4d& s) {
  Eigen::Matrix<double, 4, 6> out = Eigen::Matrix<double, 4, 6>::Zero();
  out.topLeftCorner<3, 3>() = s(3) * Eigen::Matrix3d::Identity();
  out.topRightCorner<3, 3>() = -so3::hat(s.head<3>());
  return out;
}

namespace detail {
/// Q(rho, phi) of the SE(3) left Jacobian (Barfoot eq. 7.86). Its coefficients cancel
/// catastrophically for small angles (2 cos t - 2 + t^2 ~ t^4/12), so below 1e-2 rad they come
/// from their series to t^4 (truncation ~1e-19).
inline Eigen::Matrix3d left_jacobian_q(const Vector6d& xi) {
  const Eigen::Matrix3d P = so3::hat(xi.head<3>()), F = so3::hat(xi.tail<3>());
  const double t = xi.tail<3>().norm(), t2 = t * t, t4 = t2 * t2;
  double c1, c2, c3;  // coefficients of (F P + P F + F P F), (F F P + P F F - 3 F P F), (F P F F + F F P F)
  if (t < 1e-2) {
    c1 = 1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0;
    c2 = 1.0 / 24.0 - t2 / 720.0 + t4 / 40320.0;
    c3 = 1.0 / 120.0 - t2 / 2520.0 + t4 / 120960.0;
  } else {
    const double s = std::sin(t), c = std::cos(t);
    c1 = (t - s) / (t2 * t);
    c2 = (t2 + 2.0 * c - 2.0) / (2.0 * t4);
    c3 = (2.0 * t - 3.0 * s + t * c) / (2.0 * t4 * t);
  }
  return 0.5 * P + c1 * (F * P + P * F + F * P * F) + c2 * (F * F * P + P * F * F - 3.0 * F * P * F) +
         c3 * (F * P * F * F + F * F * P * F);
}
}  // namespace detail

/// exp(xi^) = [Exp(phi)  J_l(phi) rho; 0 1].
inline Eigen::Matrix4d exp(const Vector6d& xi) {
  return make(so3::exp(xi.tail<3>()), so3::left_jacobian(xi.tail<3>()) * xi.head<3>());
}

/// log(T)^vee with |phi| in [0, pi]: phi = Log(R), rho = J_l(phi)^-1 p.
inline Vector6d log(const Eigen::Matrix4d& T) {
  Vector6d xi;
  xi.tail<3>() = so3::log(rotation(T));
  xi.head<3>() = so3::left_jacobian_inverse(xi.tail<3>()) * translation(T);
  return xi;
}

/// J_l(xi) = [J_l(phi) Q; 0 J_l(phi)]: exp((xi + d)^) ~ exp((J_l(xi) d)^) exp(xi^).
inline Matrix6d left_jacobian(const Vector6d& xi) {
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = J.bottomRightCorner<3, 3>() = so3::left_jacobian(xi.tail<3>());
  J.topRightCorner<3, 3>() = detail::left_jacobian_q(xi);
  return J;
}

/// J_l(xi)^-1 = [J^-1  -J^-1 Q J^-1; 0 J^-1].
inline Matrix6d left_jacobian_inverse(const Vector6d& xi) {
  const Eigen::Matrix3d Ji = so3::left_jacobian_inverse(xi.tail<3>());
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = J.bottomRightCorner<3, 3>() = Ji;
  J.topRightCorner<3, 3>() = -Ji * detail::left_jacobian_q(xi) * Ji;
  return J;
}

/// J_r(xi) = J_l(-xi): exp((xi + d)^) ~ exp(xi^) exp((J_r(xi) d)^).
inline Matrix6d right_jacobian(const Vector6d& xi) { return left_jacobian(-xi); }
inline Matrix6d right_jacobian_inverse(const Vector6d& xi) { return left_jacobian_inverse(-xi); }

/// R re-orthonormalized (through the nearest unit quaternion), so that products of many motions
/// stay on the group.
inline Eigen::Matrix4d normalized(const Eigen::Matrix4d& T) {
  return make(Eigen::Quaterniond(rotation(T)).normalized().toRotationMatrix(), translation(T));
}

}  // namespace sextant::se3
