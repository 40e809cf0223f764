#pragma once
/// \file Poses on SE(3), world_T_body as 4x4 matrices, perturbed on the right (in the body frame):
/// plus(T, d) = T exp(d^), minus(A, B) = log(B^-1 A), d = (rho, phi). Seed 004 keeps the inverse
/// pose U = T^-1 and perturbs it on the left, exp(d^) U; that is T exp(-d^): the same tangent
/// space with the sign flipped (docs/derivations/stereo_imu_se3.md).

#include <Eigen/Core>

#include "sextant/core/se3.hpp"

namespace sextant {

struct Se3Space {
  static constexpr int kDim = 6;
  using Point = Eigen::Matrix4d;
  using Tangent = se3::Vector6d;

  /// T exp(d^), its rotation re-orthonormalized so that many updates keep it on the group.
  static Point plus(const Point& T, const Tangent& delta) { return se3::normalized(T * se3::exp(delta)); }
  static Tangent minus(const Point& a, const Point& b) { return se3::log(se3::inverse(b) * a); }
  static bool is_finite(const Point& T) { return T.allFinite(); }
};

}  // namespace sextant
