#pragma once
/// \file 6D poses (x, y, z, yaw, pitch, roll) as MRPT's CPose3D writes them: R = Rz(yaw) Ry(pitch)
/// Rx(roll). plus and minus act component-wise with the three angles wrapped; composition and
/// relative pose are templated on the scalar so models differentiate them automatically.

#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "sextant/core/autodiff.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant {

template <class Scalar>
using Pose3Euler = Eigen::Matrix<Scalar, 6, 1>;

/// R = Rz(yaw) Ry(pitch) Rx(roll).
template <class Scalar>
Eigen::Matrix<Scalar, 3, 3> rotation_from_ypr(const Scalar& yaw, const Scalar& pitch, const Scalar& roll) {
  using std::cos;
  using std::sin;
  const Scalar cy = cos(yaw), sy = sin(yaw), cp = cos(pitch), sp = sin(pitch), cr = cos(roll), sr = sin(roll);
  Eigen::Matrix<Scalar, 3, 3> R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return R;
}

/// (yaw, pitch, roll) of R, pitch in [-pi/2, pi/2] (singular at |pitch| = pi/2).
template <class Scalar>
Eigen::Matrix<Scalar, 3, 1> ypr_from_rotation(const Eigen::Matrix<Scalar, 3, 3>& R) {
  using std::atan2;
  using std::sqrt;
  Eigen::Matrix<Scalar, 3, 1> ypr;
  ypr << atan2(R(1, 0), R(0, 0)), atan2(Scalar(-R(2, 0)), Scalar(sqrt(R(0, 0) * R(0, 0) + R(1, 0) * R(1, 0)))),
      atan2(R(2, 1), R(2, 2));
  return ypr;
}

template <class Scalar>
Eigen::Matrix<Scalar, 3, 3> rotation_of(const Pose3Euler<Scalar>& pose) {
  return rotation_from_ypr<Scalar>(pose(3), pose(4), pose(5));
}

/// a (+) b: the pose b, given in the frame of a, in the frame a is given in.
template <class Scalar>
Pose3Euler<Scalar> compose(const Pose3Euler<Scalar>& a, const Pose3Euler<Scalar>& b) {
  const Eigen::Matrix<Scalar, 3, 3> Ra = rotation_of(a);
  Pose3Euler<Scalar> out;
  out.template head<3>() = a.template head<3>() + Ra * b.template head<3>();
  out.template tail<3>() = ypr_from_rotation<Scalar>(Ra * rotation_of(b));
  return out;
}

/// The point p (world frame) in the frame of pose a: Ra^T (p - ta).
template <class Scalar>
Eigen::Matrix<Scalar, 3, 1> point_in_frame(const Pose3Euler<Scalar>& a, const Eigen::Matrix<Scalar, 3, 1>& p) {
  return rotation_of(a).transpose() * (p - a.template head<3>());
}

/// (-)a (+) b: the pose b in the frame of a.
template <class Scalar>
Pose3Euler<Scalar> relative_pose(const Pose3Euler<Scalar>& a, const Pose3Euler<Scalar>& b) {
  const Eigen::Matrix<Scalar, 3, 3> Rat = rotation_of(a).transpose();
  Pose3Euler<Scalar> out;
  out.template head<3>() = Rat * (b.template head<3>() - a.template head<3>());
  out.template tail<3>() = ypr_from_rotation<Scalar>(Eigen::Matrix<Scalar, 3, 3>(Rat * rotation_of(b)));
  return out;
}

/// Component-wise difference with the angles wrapped (the tangent of Pose3EulerSpace).
template <class Scalar>
Pose3Euler<Scalar> euler_difference(const Pose3Euler<Scalar>& a, const Pose3Euler<Scalar>& b) {
  Pose3Euler<Scalar> out = a - b;
  for (int i = 3; i < 6; ++i) out(i) = wrap_angle_generic(out(i));
  return out;
}

struct Pose3EulerSpace {
  static constexpr int kDim = 6;
  using Point = Eigen::Matrix<double, 6, 1>;
  using Tangent = Eigen::Matrix<double, 6, 1>;

  static Point plus(const Point& x, const Tangent& delta) {
    Point out = x + delta;
    for (int i = 3; i < 6; ++i) out(i) = wrap_angle_generic(out(i));
    return out;
  }
  static Tangent minus(const Point& a, const Point& b) { return euler_difference<double>(a, b); }
  static bool is_finite(const Point& x) { return x.allFinite(); }

  /// The pose with its rotation named as ypr_from_rotation names it, pitch in [-pi/2, pi/2]:
  /// (yaw + pi, +-pi - pitch, roll + pi) is the same rotation, and a step of this additive chart (a
  /// Gauss-Newton step, a filter's update) can carry pitch past pi/2, where minus() would see a turn
  /// of ~pi that is not there (docs/results/simul_landmarks.md, "A robot that pitches past 90°").
  static Point canonical(const Point& x) {
    if (!euler_middle_angle_past_right_angle(x(4))) return x;
    Point out = x;
    out(3) = wrap_angle_generic(x(3) + std::numbers::pi);
    out(4) = mirrored_euler_middle_angle(x(4));
    out(5) = wrap_angle_generic(x(5) + std::numbers::pi);
    return out;
  }
  /// J with canonical(plus(x, e)) = plus(canonical(x), J e) to first order: pitch's sign flips
  /// where canonical() renames the rotation.
  static Eigen::Matrix<double, 6, 6> canonical_jacobian(const Point& x) {
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Identity();
    if (euler_middle_angle_past_right_angle(x(4))) J(4, 4) = -1.0;
    return J;
  }
};

}  // namespace sextant
