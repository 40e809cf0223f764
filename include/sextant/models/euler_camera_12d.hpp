#pragma once
/// \file The thesis's visual SLAM camera (seed 000, §4.2.2): a 12D state x = (p, eta, v, omega)
/// (eq. 100) with eta = (phi, theta, psi) the yxz Euler angles, R(eta) = Ry(theta) Rx(phi) Rz(psi)
/// the camera-to-world rotation, v and omega the linear and angular velocity in the camera frame.
/// A constant-velocity motion model (eqs. 101-102) and a 3D point measurement in the camera frame
/// (eq. 106) with the noise of a rectified stereo pair. The printed Jacobians (eqs. 102-105, 107)
/// have typos and mix parametrizations; these are derived in docs/derivations/euler_camera_12d.md.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/core/model_results.hpp"
#include "sextant/core/so3.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

namespace euler_yxz {

/// Below this |cos(phi)| the yxz angles are at their gimbal singularity (theta and psi turn about
/// the same axis and J(eta) has 1/cos(phi)): the motion model throws there instead of returning
/// angle rates of 1e16.
inline constexpr double kMinCosPhi = 1e-9;

inline Eigen::Matrix3d rotation_x(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix3d() << 1, 0, 0, 0, c, -s, 0, s, c).finished();
}
inline Eigen::Matrix3d rotation_y(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix3d() << c, 0, s, 0, 1, 0, -s, 0, c).finished();
}
inline Eigen::Matrix3d rotation_z(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix3d() << c, -s, 0, s, c, 0, 0, 0, 1).finished();
}
/// R(eta) = Ry(theta) Rx(phi) Rz(psi), eta = (phi, theta, psi): camera frame to world.
inline Eigen::Matrix3d rotation(const Eigen::Vector3d& eta) {
  return rotation_y(eta(1)) * rotation_x(eta(0)) * rotation_z(eta(2));
}

/// dR/dphi, dR/dtheta, dR/dpsi: each factor R_a(angle) differentiates to R_a(angle) [e_a]x.
inline std::array<Eigen::Matrix3d, 3> rotation_derivatives(const Eigen::Vector3d& eta) {
  const Eigen::Matrix3d Ry = rotation_y(eta(1)), Rx = rotation_x(eta(0)), Rz = rotation_z(eta(2));
  return {Ry * Rx * so3::hat(Eigen::Vector3d::UnitX()) * Rz, Ry * so3::hat(Eigen::Vector3d::UnitY()) * Rx * Rz,
          Ry * Rx * Rz * so3::hat(Eigen::Vector3d::UnitZ())};
}

/// E(eta) with R(eta + d) = R(eta) Exp(E d) + O(d^2): column i is vee(R^T dR/deta_i), the
/// body-frame axis each angle turns about (the inverse of J: E = J^-1).
inline Eigen::Matrix3d body_jacobian(const Eigen::Vector3d& eta) {
  const Eigen::Matrix3d R = rotation(eta);
  const auto dR = rotation_derivatives(eta);
  Eigen::Matrix3d E;
  for (int i = 0; i < 3; ++i) E.col(i) = so3::vee(R.transpose() * dR[i]);
  return E;
}

/// J(eta) with d(eta)/dt = J(eta) omega, omega in the camera frame (eq. 102 with its typos fixed):
/// [c_psi, -s_psi, 0; s_psi / c_phi, c_psi / c_phi, 0; t_phi s_psi, t_phi c_psi, 1].
inline Eigen::Matrix3d rate_matrix(const Eigen::Vector3d& eta) {
  const double cf = std::cos(eta(0)), tf = std::tan(eta(0)), cp = std::cos(eta(2)), sp = std::sin(eta(2));
  return (Eigen::Matrix3d() << cp, -sp, 0, sp / cf, cp / cf, 0, tf * sp, tf * cp, 1).finished();
}

/// d(J(eta) omega)/d(eta) (the corrected eq. 104 without the identity and the step).
inline Eigen::Matrix3d rate_derivative(const Eigen::Vector3d& eta, const Eigen::Vector3d& omega) {
  const double cf = std::cos(eta(0)), sf = std::sin(eta(0)), tf = std::tan(eta(0));
  const double cp = std::cos(eta(2)), sp = std::sin(eta(2));
  const double a = sp * omega.x() + cp * omega.y();  // d/dpsi a = b
  const double b = cp * omega.x() - sp * omega.y();  // d/dpsi b = -a
  return (Eigen::Matrix3d() << 0, 0, -a,           //
          a * sf / (cf * cf), 0, b / cf,           //
          a / (cf * cf), 0, tf * b)
      .finished();
}

/// Whether canonical() mirrors phi (|phi| past pi/2 after wrapping): then d canonical / d eta is
/// diag(-1, 1, 1), which a Jacobian through canonical() must apply.
inline bool mirrors_phi(const Eigen::Vector3d& eta) { return euler_middle_angle_past_right_angle(eta(0)); }

/// The same rotation with phi in [-pi/2, pi/2] and theta, psi in (-pi, pi]: (phi, theta, psi) and
/// (pi - phi, theta + pi, psi + pi) give the same R.
inline Eigen::Vector3d canonical(Eigen::Vector3d eta) {
  if (mirrors_phi(eta)) {
    eta(0) = mirrored_euler_middle_angle(eta(0));
    eta(1) += std::numbers::pi;
    eta(2) += std::numbers::pi;
  }
  for (int i = 0; i < 3; ++i) eta(i) = wrap_angle(eta(i));
  return eta;
}

}  // namespace euler_yxz

/// (p, eta, v, omega) with eta kept canonical (euler_yxz::canonical) by plus; minus subtracts
/// component-wise with the angle differences wrapped. Near phi = +-pi/2 the Euler angles stop being
/// a chart: theta and psi turn about the same axis, two canonical triples of nearly the same
/// rotation differ by pi in theta and psi, and a step that crosses |phi| = pi/2 mirrors phi (the
/// motion model's Jacobian follows the mirror; a covariance held by a back-end cannot). The motion
/// model throws within kMinCosPhi of it; see docs/derivations/euler_camera_12d.md.
struct EulerCamera12Space {
  static constexpr int kDim = 12;
  using Point = Vector12d;
  using Tangent = Vector12d;

  static Point plus(const Point& x, const Tangent& delta) {
    Point out = x + delta;
    out.segment<3>(3) = euler_yxz::canonical(out.segment<3>(3));
    return out;
  }
  static Tangent minus(const Point& a, const Point& b) {
    Tangent out = a - b;
    for (int i = 3; i < 6; ++i) out(i) = wrap_angle(out(i));
    return out;
  }
  static bool is_finite(const Point& x) { return x.allFinite(); }
  /// The world's rigid motions at x (core/observability_constraints.hpp), columns translation then
  /// rotation about the world's axes: a motion (t, w) moves p by t + w x p and turns R(eta) into
  /// Exp(w) R(eta), i.e. eta by J(eta) R(eta)^T w; v and omega, in the camera frame, stay.
  static Eigen::Matrix<double, 12, 6> world_motion_directions(const Point& x) {
    Eigen::Matrix<double, 12, 6> N = Eigen::Matrix<double, 12, 6>::Zero();
    const Eigen::Vector3d eta = x.segment<3>(3);
    N.block<3, 3>(0, 0).setIdentity();
    N.block<3, 3>(0, 3) = -so3::hat(x.head<3>());
    N.block<3, 3>(3, 3) = euler_yxz::rate_matrix(eta) * euler_yxz::rotation(eta).transpose();
    return N;
  }
};

/// Constant-velocity camera (eq. 101): p' = p + R(eta) v dt, eta' = eta + J(eta) omega dt,
/// v' = Gamma v, omega' = Lambda omega. The process noise is the thesis's noise on v and omega as
/// white accelerations (spectral densities sigma_velocity^2 and sigma_rate^2) integrated over the
/// step, the discretized white-noise acceleration model: each velocity gains sigma^2 dt, and its
/// position or angles gain sigma^2 dt^3 / 3 with cross-covariance sigma^2 dt^2 / 2, mapped by R(eta)
/// and J(eta). R is then positive definite, as the information-form back-ends need, and a
/// correction of the position also corrects the velocity (which FastSLAM's proposal relies on).
struct EulerCamera12D {
  using State = Vector12d;
  using Control = Eigen::Matrix<double, 0, 1>;  ///< no control: the camera is handheld
  using Space = EulerCamera12Space;
  static constexpr int kDim = 12;
  /// v and omega enter g linearly once p and eta are fixed, R depends on eta alone, and the point
  /// measurement does not see them: FastSLAM keeps them as a Kalman filter per particle
  /// (core/conditionally_linear.hpp).
  static constexpr int kConditionallyLinearDims = 6;

  Eigen::Vector3d gamma = Eigen::Vector3d::Ones();   ///< diagonal of Gamma, in (0, 1]
  Eigen::Vector3d lambda = Eigen::Vector3d::Ones();  ///< diagonal of Lambda, in (0, 1]
  double sigma_velocity = 2e-4;  ///< m/s / sqrt(s): linear acceleration noise density
  double sigma_rate = 3e-4;      ///< rad/s / sqrt(s): angular acceleration noise density

  /// x' = g(x) (eq. 101), G = dg/dx (corrected eqs. 103-105) and R. Throws numerical_error at the
  /// gimbal singularity (|cos(phi)| < kMinCosPhi).
  MotionPrediction<State, 12> predict(const State& x, const Control& /*u*/, double dt) const {
    const Eigen::Vector3d eta = x.segment<3>(3), v = x.segment<3>(6), omega = x.segment<3>(9);
    if (!(std::abs(std::cos(eta(0))) >= euler_yxz::kMinCosPhi))
      throw numerical_error("EulerCamera12D: phi = " + std::to_string(eta(0)) +
                            " is at the gimbal singularity of the yxz angles (cos(phi) = 0)");
    const Eigen::Matrix3d R = euler_yxz::rotation(eta), J = euler_yxz::rate_matrix(eta);
    const auto dR = euler_yxz::rotation_derivatives(eta);
    MotionPrediction<State, 12> out;
    out.x.segment<3>(0) = x.segment<3>(0) + R * v * dt;
    const Eigen::Vector3d eta_next = eta + J * omega * dt;
    out.x.segment<3>(3) = euler_yxz::canonical(eta_next);
    out.x.segment<3>(6) = gamma.cwiseProduct(v);
    out.x.segment<3>(9) = lambda.cwiseProduct(omega);
    out.J_x_x.setZero();
    out.J_x_x.block<3, 3>(0, 0).setIdentity();
    for (int i = 0; i < 3; ++i) out.J_x_x.block<3, 1>(0, 3 + i) = dR[i] * v * dt;
    out.J_x_x.block<3, 3>(0, 6) = R * dt;
    out.J_x_x.block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() + euler_yxz::rate_derivative(eta, omega) * dt;
    out.J_x_x.block<3, 3>(3, 9) = J * dt;
    out.J_x_x.block<3, 3>(6, 6) = gamma.asDiagonal();
    out.J_x_x.block<3, 3>(9, 9) = lambda.asDiagonal();
    out.R = process_noise(R, J, dt);
    if (euler_yxz::mirrors_phi(eta_next)) {  // through canonical(): d phi' flips sign
      out.J_x_x.row(3) *= -1.0;
      out.R.row(3) *= -1.0;
      out.R.col(3) *= -1.0;
    }
    return out;
  }

  /// The integrated white-noise accelerations at rotation R and rate matrix J (see the struct).
  Matrix12d process_noise(const Eigen::Matrix3d& R, const Eigen::Matrix3d& J, double dt) const {
    const double qv = sigma_velocity * sigma_velocity, qw = sigma_rate * sigma_rate;
    const double dt2 = dt * dt / 2.0, dt3 = dt * dt * dt / 3.0;
    Matrix12d out = Matrix12d::Zero();
    out.block<3, 3>(0, 0) = qv * dt3 * Eigen::Matrix3d::Identity();  // R R^T = I
    out.block<3, 3>(0, 6) = qv * dt2 * R;
    out.block<3, 3>(6, 0) = qv * dt2 * R.transpose();
    out.block<3, 3>(6, 6) = qv * dt * Eigen::Matrix3d::Identity();
    out.block<3, 3>(3, 3) = qw * dt3 * J * J.transpose();
    out.block<3, 3>(3, 9) = qw * dt2 * J;
    out.block<3, 3>(9, 3) = qw * dt2 * J.transpose();
    out.block<3, 3>(9, 9) = qw * dt * Eigen::Matrix3d::Identity();
    return out;
  }
};

/// The noise of a point triangulated by a rectified stereo pair (x right, y down, z along the
/// optical axis): pixel noise sigma in u_left, v_left and u_right, focal length f [px], baseline b.
/// With d = u_left - u_right = f b / z, the point is (u - c_x, v - c_y, f) b / d; its covariance to
/// first order is Q = A Sigma_(u, v, d) A^T with A = (z / f) [1 0 -x/b; 0 1 -y/b; 0 0 -z/b]:
/// lateral std z sigma / f, depth std sqrt(2) z^2 sigma / (f b). A disparity measured at the left
/// keypoint (vision/slanted_correlation.hpp) has its own noise sigma_d, independent of the keypoint's:
/// Sigma_(u, v, d) = diag(sigma^2, sigma^2, sigma_d^2), depth std z^2 sigma_d / (f b).
struct StereoPointNoise {
  double focal_px = 600.0;
  double baseline = 0.1;     ///< m
  double pixel_sigma = 0.5;  ///< px
  double min_depth = 0.05;   ///< m: Q of a point nearer than this (or behind) is Q at this depth
  /// px: sigma_d of a disparity measured at the left keypoint; 0: u_right detected with u_left's
  /// noise (d's variance 2 sigma^2, its error correlated with u_left's)
  double disparity_sigma = 0.0;

  Eigen::Matrix3d covariance(const Eigen::Vector3d& q) const {
    const double z = std::max(q.z(), min_depth), x = q.x(), y = q.y();
    Eigen::Matrix3d A;
    A << 1, 0, -x / baseline, 0, 1, -y / baseline, 0, 0, -z / baseline;
    A *= z / focal_px;
    const double s2 = pixel_sigma * pixel_sigma;
    Eigen::Matrix3d pixel;  // covariance of (u_left, v_left, d = u_left - u_right)
    if (disparity_sigma > 0.0)
      pixel << s2, 0, 0, 0, s2, 0, 0, 0, disparity_sigma * disparity_sigma;
    else
      pixel << s2, 0, s2, 0, s2, 0, s2, 0, 2 * s2;
    const Eigen::Matrix3d Q = A * pixel * A.transpose();
    return 0.5 * (Q + Q.transpose());
  }
};

/// A 3D point landmark seen in the camera frame (eq. 106): z = R(eta)^T (m - p), with the stereo
/// noise evaluated at the predicted point (predict) or the measured one (initialize).
struct PointInCamera3D {
  using Landmark = Eigen::Vector3d;
  using Measurement = Eigen::Vector3d;

  StereoPointNoise noise;

  /// z_hat and H = [-R^T, (dR/deta_i)^T (m - p), 0, 0 | R^T] (the corrected eq. 107).
  MeasurementPrediction<3, 12, 3> predict(const Vector12d& x, const Landmark& m) const {
    const Eigen::Vector3d eta = x.segment<3>(3), d = m - x.head<3>();
    const Eigen::Matrix3d R = euler_yxz::rotation(eta);
    const auto dR = euler_yxz::rotation_derivatives(eta);
    MeasurementPrediction<3, 12, 3> out;
    out.z = R.transpose() * d;
    out.J_z_x.setZero();
    out.J_z_x.block<3, 3>(0, 0) = -R.transpose();
    for (int i = 0; i < 3; ++i) out.J_z_x.col(3 + i) = dR[i].transpose() * d;
    out.J_z_m = R.transpose();
    out.Q = noise.covariance(out.z);
    return out;
  }

  Measurement residual(const Measurement& z, const Measurement& z_hat) const { return z - z_hat; }

  /// m = p + R(eta) z.
  LandmarkInit<3, 12, 3> initialize(const Vector12d& x, const Measurement& z) const {
    const Eigen::Vector3d eta = x.segment<3>(3);
    const Eigen::Matrix3d R = euler_yxz::rotation(eta);
    const auto dR = euler_yxz::rotation_derivatives(eta);
    LandmarkInit<3, 12, 3> out;
    out.m = x.head<3>() + R * z;
    out.J_m_x.setZero();
    out.J_m_x.block<3, 3>(0, 0).setIdentity();
    for (int i = 0; i < 3; ++i) out.J_m_x.col(3 + i) = dR[i] * z;
    out.J_m_z = R;
    out.Q = noise.covariance(z);
    return out;
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_EULER_CAMERA_12D
#include "sextant/compiled/extern_instances.hpp"
