#pragma once
/// \file Poses on SE(3), world_T_body as 4x4 matrices, d = (rho, phi), with either perturbation:
///  - world (the default of the visual-inertial models): plus(T, d) = exp(d^) T, minus(A, B) = log(A B^-1);
///  - body: plus(T, d) = T exp(d^), minus(A, B) = log(B^-1 A). Seed 004 keeps the inverse pose
///    U = T^-1 and perturbs it on the left, exp(d^) U: that is T exp(-d^), the body perturbation
///    with the sign flipped (docs/derivations/stereo_imu_se3.md).
/// Why world is the default: a filter linearized in world-frame errors keeps the unobservable
/// translation of visual-inertial SLAM unobservable and its pose ANEES inside the chi-square bounds
/// where the body form is overconfident (docs/results/vislam.md).

#include <Eigen/Core>

#include "sextant/core/se3.hpp"

namespace sextant {

enum class Se3Perturbation { world, body };

template <Se3Perturbation P>
struct Se3SpaceOf {
  static constexpr int kDim = 6;
  static constexpr Se3Perturbation perturbation = P;
  using Point = Eigen::Matrix4d;
  using Tangent = se3::Vector6d;

  /// exp(d^) T or T exp(d^), its rotation re-orthonormalized so that many updates keep it on the group.
  static Point plus(const Point& T, const Tangent& delta) {
    if constexpr (P == Se3Perturbation::world)
      return se3::normalized(se3::exp(delta) * T);
    else
      return se3::normalized(T * se3::exp(delta));
  }
  static Tangent minus(const Point& a, const Point& b) {
    if constexpr (P == Se3Perturbation::world)
      return se3::log(a * se3::inverse(b));
    else
      return se3::log(se3::inverse(b) * a);
  }
  static bool is_finite(const Point& T) { return T.allFinite(); }

  /// The Jacobians of minus and plus (docs/derivations/state_space_jacobians.md), r = minus(a, b):
  /// d minus(plus(a, e), b) / de at e = 0: world J_l^-1(r), body J_r^-1(r);
  static se3::Matrix6d minus_jacobian_first(const Point& a, const Point& b) {
    const Tangent r = minus(a, b);
    return P == Se3Perturbation::world ? se3::left_jacobian_inverse(r) : se3::right_jacobian_inverse(r);
  }
  /// d minus(a, plus(b, e)) / de at e = 0: world -J_r^-1(r), body -J_l^-1(r);
  static se3::Matrix6d minus_jacobian_second(const Point& a, const Point& b) {
    const Tangent r = minus(a, b);
    return P == Se3Perturbation::world ? se3::Matrix6d(-se3::right_jacobian_inverse(r))
                                       : se3::Matrix6d(-se3::left_jacobian_inverse(r));
  }
  /// G with plus(x, d + e) = plus(plus(x, d), G e) to first order in e: world J_l(d), body J_r(d).
  static se3::Matrix6d plus_jacobian(const Point&, const Tangent& d) {
    return P == Se3Perturbation::world ? se3::left_jacobian(d) : se3::right_jacobian(d);
  }
};

using Se3Space = Se3SpaceOf<Se3Perturbation::world>;
using Se3BodySpace = Se3SpaceOf<Se3Perturbation::body>;

}  // namespace sextant
