#pragma once
/// \file The vertex and edge types of a pose graph on SE(2) and SE(3), with the errors g2o defines
/// for them (so that chi2 means the same number in sextant, g2o, MRPT and a g2o file's
/// information matrices), and their analytic Jacobians (checked against central differences in
/// tests/backends/pose_graph_edges_test.cpp; derivation in docs/derivations/pose_graph_edges.md).
///   between (EDGE_SE2, EDGE_SE3:QUAT):  D = Z^-1 (X_i^-1 X_j),  e = (t(D), rot(D));
///   point   (EDGE_SE2_XY, EDGE_SE3_TRACKXYZ):  e = (X_i O)^-1 l - z, O the sensor offset (3D);
///   prior:  D = Z^-1 X,  e = (t(D), rot(D)).
/// rot(D) is the angle on SE(2) and the vector part of D's unit quaternion with w >= 0 on SE(3)
/// (g2o's EdgeSE3 error, about half the rotation vector).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "sextant/core/se3.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant {

/// Poses (x, y, theta) of a planar pose graph; points (x, y). A step moves x, y and theta by
/// addition (theta wrapped), as g2o's VertexSE2.
struct PlanarPoses {
  static constexpr int kDim = 3;        ///< tangent of a pose
  static constexpr int kPointDim = 2;
  static constexpr int kEdgeDim = 3;    ///< error of a between edge
  static constexpr const char* name = "SE(2)";
  using Pose = Eigen::Vector3d;
  using Tangent = Eigen::Vector3d;
  using Point = Eigen::Vector2d;
  using Jacobian = Eigen::Matrix3d;
  using PointJacobian = Eigen::Matrix<double, 2, 3>;

  static Pose identity() { return Pose::Zero(); }
  static Pose plus(const Pose& x, const Tangent& d) { return {x(0) + d(0), x(1) + d(1), wrap_angle(x(2) + d(2))}; }
  static bool is_finite(const Pose& x) { return x.allFinite(); }
  static Eigen::Matrix2d rotation(double theta) {
    const double c = std::cos(theta), s = std::sin(theta);
    return (Eigen::Matrix2d() << c, -s, s, c).finished();
  }
  /// d R(theta)^T / d theta.
  static Eigen::Matrix2d rotation_transposed_derivative(double theta) {
    const double c = std::cos(theta), s = std::sin(theta);
    return (Eigen::Matrix2d() << -s, c, -c, -s).finished();
  }
  /// a b: b's coordinates in a's frame carried to the world.
  static Pose compose(const Pose& a, const Pose& b) {
    const Eigen::Vector2d t = a.head<2>() + rotation(a(2)) * b.head<2>();
    return {t(0), t(1), wrap_angle(a(2) + b(2))};
  }
  /// a^-1 b: b in a's frame.
  static Pose between(const Pose& a, const Pose& b) {
    const Eigen::Vector2d t = rotation(a(2)).transpose() * (b.head<2>() - a.head<2>());
    return {t(0), t(1), wrap_angle(b(2) - a(2))};
  }
  static Pose inverse(const Pose& a) { return between(a, identity()); }
  /// The pose as a rotation matrix and a translation, and back (chordal initialization).
  static constexpr int kSpaceDim = 2;
  static Eigen::Matrix2d rotation_of(const Pose& x) { return rotation(x(2)); }
  static Eigen::Vector2d translation_of(const Pose& x) { return x.head<2>(); }
  static Pose make(const Eigen::Matrix2d& R, const Eigen::Vector2d& t) { return {t(0), t(1), std::atan2(R(1, 0), R(0, 0))}; }

  /// e = t2v(Z^-1 X_i^-1 X_j) and its Jacobians in the additive steps of X_i and X_j.
  struct BetweenLinearization {
    Tangent error;
    Jacobian J_from, J_to;
  };
  static Tangent between_error(const Pose& from, const Pose& to, const Pose& z) { return between(z, between(from, to)); }
  static BetweenLinearization linearize_between(const Pose& from, const Pose& to, const Pose& z) {
    const Eigen::Matrix2d Rz_T = rotation(z(2)).transpose(), Ri_T = rotation(from(2)).transpose();
    const Eigen::Vector2d dt = to.head<2>() - from.head<2>();
    BetweenLinearization out;
    out.error = between_error(from, to, z);
    out.J_to.setZero();
    out.J_to.topLeftCorner<2, 2>() = Rz_T * Ri_T;
    out.J_to(2, 2) = 1.0;
    out.J_from.setZero();
    out.J_from.topLeftCorner<2, 2>() = -out.J_to.topLeftCorner<2, 2>();
    out.J_from.topRightCorner<2, 1>() = Rz_T * rotation_transposed_derivative(from(2)) * dt;
    out.J_from(2, 2) = -1.0;
    return out;
  }

  /// e = X_i^-1 l - z (EDGE_SE2_XY) and its Jacobians in the pose's step and the point's.
  struct PointLinearization {
    Point error;
    PointJacobian J_pose;
    Eigen::Matrix2d J_point;
  };
  static Point point_error(const Pose& x, const Point& l, const Point& z) {
    return rotation(x(2)).transpose() * (l - x.head<2>()) - z;
  }
  static PointLinearization linearize_point(const Pose& x, const Point& l, const Point& z) {
    PointLinearization out;
    out.error = point_error(x, l, z);
    out.J_point = rotation(x(2)).transpose();
    out.J_pose.leftCols<2>() = -out.J_point;
    out.J_pose.col(2) = rotation_transposed_derivative(x(2)) * (l - x.head<2>());
    return out;
  }
};

/// Poses T = [R t; 0 1] of a spatial pose graph; points (x, y, z). A step is T exp(d^), d = (rho, phi)
/// (the body perturbation of core/se3.hpp).
struct SpatialPoses {
  static constexpr int kDim = 6;
  static constexpr int kPointDim = 3;
  static constexpr int kEdgeDim = 6;
  static constexpr const char* name = "SE(3)";
  using Pose = Eigen::Matrix4d;
  using Tangent = se3::Vector6d;
  using Point = Eigen::Vector3d;
  using Jacobian = se3::Matrix6d;
  using PointJacobian = Eigen::Matrix<double, 3, 6>;

  static Pose identity() { return Pose::Identity(); }
  static Pose plus(const Pose& T, const Tangent& d) { return se3::normalized(T * se3::exp(d)); }
  static bool is_finite(const Pose& T) { return T.allFinite(); }
  static Pose compose(const Pose& a, const Pose& b) { return se3::normalized(a * b); }
  static Pose between(const Pose& a, const Pose& b) { return se3::normalized(se3::inverse(a) * b); }
  static Pose inverse(const Pose& a) { return se3::inverse(a); }
  static constexpr int kSpaceDim = 3;
  static Eigen::Matrix3d rotation_of(const Pose& x) { return se3::rotation(x); }
  static Eigen::Vector3d translation_of(const Pose& x) { return se3::translation(x); }
  static Pose make(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) { return se3::make(R, t); }

  /// (t, q_vec) of T with the quaternion's w >= 0: g2o's minimal vector of a pose difference.
  static Tangent minimal_vector(const Pose& T) {
    Eigen::Quaterniond q(se3::rotation(T));
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    Tangent out;
    out << se3::translation(T), q.vec();
    return out;
  }
  /// d minimal_vector(D exp(xi^)) / d xi at xi = 0: [R_D 0; 0 (w I + [v]x) / 2].
  static Jacobian minimal_vector_right_jacobian(const Pose& D) {
    Eigen::Quaterniond q(se3::rotation(D));
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    Jacobian J = Jacobian::Zero();
    J.topLeftCorner<3, 3>() = se3::rotation(D);
    J.bottomRightCorner<3, 3>() = 0.5 * (q.w() * Eigen::Matrix3d::Identity() + so3::hat(q.vec()));
    return J;
  }

  struct BetweenLinearization {
    Tangent error;
    Jacobian J_from, J_to;
  };
  static Tangent between_error(const Pose& from, const Pose& to, const Pose& z) {
    return minimal_vector(se3::inverse(z) * se3::inverse(from) * to);
  }
  /// With A = X_i^-1 X_j and D = Z^-1 A: X_j exp(xi) gives D exp(xi); X_i exp(xi) gives
  /// D exp(-Ad(A^-1) xi). So J_to = J_D, J_from = -J_D Ad(A^-1).
  static BetweenLinearization linearize_between(const Pose& from, const Pose& to, const Pose& z) {
    const Pose A = se3::inverse(from) * to;
    const Pose D = se3::inverse(z) * A;
    BetweenLinearization out;
    out.error = minimal_vector(D);
    out.J_to = minimal_vector_right_jacobian(D);
    out.J_from = -out.J_to * se3::adjoint(se3::inverse(A));
    return out;
  }

  struct PointLinearization {
    Point error;
    PointJacobian J_pose;
    Eigen::Matrix3d J_point;
  };
  /// e = O^-1 X^-1 l - z: l seen from the sensor at offset O on the pose X (g2o's EDGE_SE3_TRACKXYZ).
  static Point point_error(const Pose& x, const Point& l, const Point& z, const Pose& offset = Pose::Identity()) {
    const Eigen::Vector3d p = se3::rotation(x).transpose() * (l - se3::translation(x));
    return se3::rotation(offset).transpose() * (p - se3::translation(offset)) - z;
  }
  /// X exp(xi) moves p = X^-1 l to exp(-xi) p = p - rho + [p]x phi to first order.
  static PointLinearization linearize_point(const Pose& x, const Point& l, const Point& z,
                                            const Pose& offset = Pose::Identity()) {
    const Eigen::Matrix3d Ro_T = se3::rotation(offset).transpose(), Rx_T = se3::rotation(x).transpose();
    const Eigen::Vector3d p = Rx_T * (l - se3::translation(x));
    PointLinearization out;
    out.error = Ro_T * (p - se3::translation(offset)) - z;
    out.J_pose.leftCols<3>() = -Ro_T;
    out.J_pose.rightCols<3>() = Ro_T * so3::hat(p);
    out.J_point = Ro_T * Rx_T;
    return out;
  }
};

}  // namespace sextant
