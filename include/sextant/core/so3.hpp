#pragma once
/// \file Rotations as 3x3 matrices: hat and vee, the exponential and logarithm maps, the inverse
/// of the right Jacobian (d log(R Exp(d)) / d d at d = 0 is J_r^-1(log R)) and the left Jacobian.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace sextant::so3 {

inline Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  return (Eigen::Matrix3d() << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0).finished();
}

inline Eigen::Vector3d vee(const Eigen::Matrix3d& W) { return {W(2, 1), W(0, 2), W(1, 0)}; }

/// Exp(w) by Rodrigues' formula (series below 1e-8 rad).
inline Eigen::Matrix3d exp(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = hat(w);
  if (theta < 1e-8) return Eigen::Matrix3d::Identity() + W + 0.5 * W * W;
  return Eigen::Matrix3d::Identity() + std::sin(theta) / theta * W + (1 - std::cos(theta)) / (theta * theta) * W * W;
}

/// Log(R) as a rotation vector of norm in [0, pi]; accurate near 0 and near pi.
inline Eigen::Vector3d log(const Eigen::Matrix3d& R) {
  const double cos_theta = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const Eigen::Vector3d axis_sin = 0.5 * vee(R - R.transpose());  // sin(theta) * axis
  const double theta = std::atan2(axis_sin.norm(), cos_theta);      // accurate near 0 and pi, unlike acos
  if (theta < 1e-6) return axis_sin;                               // sin(theta) ~ theta
  if (theta < 3.14) return theta / std::sin(theta) * axis_sin;
  // Near pi: the axis from the symmetric part, R + I = 2 a a^T (1 - cos) + ..., sign from axis_sin.
  const Eigen::Matrix3d B = 0.5 * (R + R.transpose()) - cos_theta * Eigen::Matrix3d::Identity();
  Eigen::Index k;
  B.diagonal().maxCoeff(&k);
  Eigen::Vector3d axis = B.col(k) / std::sqrt(std::max(B(k, k), 1e-300));
  axis.normalize();
  if (axis.dot(axis_sin) < 0) axis = -axis;
  return theta * axis;
}

/// J_r^-1(w) = I + W/2 + (1/theta^2 - (1 + cos theta) / (2 theta sin theta)) W^2.
inline Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = hat(w);
  const double c = theta < 1e-4 ? 1.0 / 12.0 + theta * theta / 720.0
                                 : 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * W + c * W * W;
}

/// J_l(w) = I + (1 - cos theta) / theta^2 W + (theta - sin theta) / theta^3 W^2:
/// Exp(w + d) ~ Exp(J_l(w) d) Exp(w). J_r(w) = J_l(-w).
inline Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& w) {
  const double theta = w.norm(), t2 = theta * theta, t4 = t2 * t2;
  const Eigen::Matrix3d W = hat(w);
  const bool series = theta < 1e-2;  // the closed forms cancel for small angles
  const double a = series ? 0.5 - t2 / 24.0 + t4 / 720.0 : (1.0 - std::cos(theta)) / t2;
  const double b = series ? 1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0 : (theta - std::sin(theta)) / (t2 * theta);
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

/// J_l(w)^-1 = J_r(-w)^-1.
inline Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& w) { return right_jacobian_inverse(-w); }

}  // namespace sextant::so3
