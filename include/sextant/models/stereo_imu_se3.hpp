#pragma once
/// \file Visual-inertial models on SE(3), after seed 004: an IMU pose driven by measured linear and
/// angular velocity (eqs. 13, 37-38), and a rectified stereo camera that measures a 3D point as its
/// pixel pair (uL, vL, uR, vR) = M pi(cam_T_imu T^-1 m) (eqs. 7, 24-26, 31, 41). The pose is
/// world_T_imu, perturbed in the world frame by default (ImuVelocitySe3, StereoPixelsSe3) or in the
/// body frame (the ...Body aliases; core/se3_space.hpp); the seed's inverse pose U = T^-1 with a
/// left perturbation is the body form with the tangent's sign flipped.
/// Derivations: docs/derivations/stereo_imu_se3.md.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/core/model_results.hpp"
#include "sextant/core/se3.hpp"
#include "sextant/core/se3_space.hpp"

namespace sextant {

/// T' = T exp(tau u^), u = (v, omega) in the IMU frame (eq. 13 for T = U^-1). With the velocity
/// noise w ~ N(0, W) held over the step, T' = T exp(tau (u + w)^) ~ T exp(tau u^) exp(tau J_r(tau u) w).
/// Body perturbation (T exp(d^)): d' = Ad(exp(-tau u^)) d + tau J_r w, so G = Ad(exp(-tau u^))
/// (eq. 38's exp(-tau u^) in adjoint form) and R = tau^2 J_r W J_r^T.
/// World perturbation (exp(d^) T): d' = d + Ad(T') tau J_r w, so G = I and
/// R = Ad(T') tau^2 J_r W J_r^T Ad(T')^T: the error of the pose does not depend on the estimate.
template <Se3Perturbation P>
struct ImuVelocitySe3Of {
  using State = Eigen::Matrix4d;
  using Control = se3::Vector6d;  ///< (v [m/s], omega [rad/s]) in the IMU frame
  using Space = Se3SpaceOf<P>;
  static constexpr int kDim = 6;

  se3::Matrix6d W = se3::Matrix6d::Identity();  ///< covariance of the velocity noise (per sample)

  MotionPrediction<State, 6> predict(const State& x, const Control& u, double dt) const {
    const se3::Vector6d step = dt * u;
    const Eigen::Matrix4d increment = se3::exp(step);
    const se3::Matrix6d Jr = se3::right_jacobian(step);
    MotionPrediction<State, 6> out;
    out.x = se3::normalized(x * increment);
    const se3::Matrix6d R_body = dt * dt * Jr * W * Jr.transpose();
    if constexpr (P == Se3Perturbation::world) {
      const se3::Matrix6d Ad = se3::adjoint(out.x);
      out.J_x_x.setIdentity();
      out.R = Ad * R_body * Ad.transpose();
    } else {
      out.J_x_x = se3::adjoint(se3::inverse(increment));
      out.R = R_body;
    }
    out.R = (0.5 * (out.R + out.R.transpose())).eval();
    return out;
  }

  /// r = log(exp(tau u^)^-1 T_from^-1 T_to): zero when T_to = predict(T_from, u); cov = tau^2 J_r W
  /// J_r^T at the control. Body: J_to = J_r^-1(r), J_from = -J_r^-1(r) Ad(T_to^-1 T_from).
  /// World: J_to = J_r^-1(r) Ad(T_to^-1) = -J_from.
  BetweenFactor<6> between(const State& from, const State& to, const Control& u, double dt) const {
    const se3::Vector6d step = dt * u;
    const Eigen::Matrix4d relative = se3::inverse(from) * to;
    const se3::Matrix6d Jr = se3::right_jacobian(step);
    BetweenFactor<6> out;
    out.r = se3::log(se3::inverse(se3::exp(step)) * relative);
    const se3::Matrix6d Jr_inv = se3::right_jacobian_inverse(out.r);
    if constexpr (P == Se3Perturbation::world) {
      out.J_to = Jr_inv * se3::adjoint(se3::inverse(to));
      out.J_from = -out.J_to;
    } else {
      out.J_to = Jr_inv;
      out.J_from = -Jr_inv * se3::adjoint(se3::inverse(relative));
    }
    out.cov = dt * dt * Jr * W * Jr.transpose();
    out.cov = (0.5 * (out.cov + out.cov.transpose())).eval();
    return out;
  }
};

using ImuVelocitySe3 = ImuVelocitySe3Of<Se3Perturbation::world>;
using ImuVelocitySe3Body = ImuVelocitySe3Of<Se3Perturbation::body>;

/// Intrinsics of a rectified stereo pair: both cameras share K, the right one sits `baseline`
/// metres along the left camera's x axis.
struct StereoCalibration {
  double fx = 1.0, fy = 1.0, cx = 0.0, cy = 0.0;
  double baseline = 1.0;  ///< [m]

  /// The seed's M (eq. 7): (uL, vL, uR, vR) = M (x, y, z, 1) / z for a point in the left camera.
  Eigen::Matrix4d stereo_matrix() const {
    Eigen::Matrix4d M;
    M << fx, 0, cx, 0,  //
        0, fy, cy, 0,   //
        fx, 0, cx, -fx * baseline, 0, fy, cy, 0;
    return M;
  }
};

/// z = (uL, vL, uR, vR) = M pi(cam_T_imu T^-1 m), pi(q) = q / q_3 (eqs. 24-25), pixel noise
/// sigma on each coordinate. A point outside the viewing frustum (at, behind or too near the
/// camera, or at a bearing beyond max_bearing_tan) cannot be predicted; a pixel pair with
/// disparity uL - uR <= 0 cannot be triangulated: both throw unobservable_error naming the problem
/// (never a NaN), and the back-ends skip that observation alone and list it in UpdateResult::unusable.
template <Se3Perturbation P>
struct StereoPixelsSe3Of {
  using Landmark = Eigen::Vector3d;
  using Measurement = Eigen::Vector4d;

  StereoCalibration calibration;
  Eigen::Matrix4d cam_T_imu = Eigen::Matrix4d::Identity();  ///< maps IMU-frame points into the left camera
  double pixel_sigma = 1.0;                                 ///< [px], each of uL, vL, uR, vR
  /// [m] the nearest depth a stereo pair is matched at; 0: one baseline. A point one baseline away
  /// has a disparity of fx pixels, beyond what a rig with a typical field of view can match; an
  /// estimate nearer than that is a wrong one, and its Jacobian (~fx x / depth^2) would swamp S in
  /// rounding (docs/vislam_singular_innovation.md).
  double min_depth = 0.0;
  /// The widest bearing, |q1| / q3 and |q2| / q3, an estimate is predicted at (default: 63 degrees
  /// off the optical axis, beyond any rectified pinhole image). An estimate out there while the
  /// point is seen in the image is a wrong one: H grows like fx (q1 / q3)^2 and so does the
  /// predicted spread, which lets a gate pass any residual into a meaningless linearization.
  double max_bearing_tan = 2.0;
  /// [px] the smallest disparity uL - uR a new landmark is triangulated from. The depth's relative
  /// error is about sqrt(2) pixel_sigma / disparity; far beyond ~10% the linearized triangulation
  /// misstates the depth's distribution, so such points are left unusable as new landmarks.
  /// 0: every positive disparity.
  double min_disparity = 0.0;

  double near_depth() const { return min_depth > 0.0 ? min_depth : calibration.baseline; }

  /// Whether a point q in the left camera's frame lies in the viewing frustum: beyond the near
  /// plane and within the widest bearing. predict() throws for a point outside it; the simulator
  /// does not observe one.
  bool sees(const Eigen::Vector3d& q) const { return q.z() > near_depth() && bearing_tangent(q) <= max_bearing_tan; }

  static double bearing_tangent(const Eigen::Vector3d& q) { return std::max(std::abs(q.x()), std::abs(q.y())) / q.z(); }

  /// What keeps q out of the frustum, for the unobservable_error.
  std::string why_unseen(const Eigen::Vector3d& q) const {
    if (!(q.z() > near_depth()))
      return "stereo camera: the landmark is behind or too near the camera (depth " + std::to_string(q.z()) +
             " m, nearest " + std::to_string(near_depth()) + " m)";
    return "stereo camera: the landmark is outside the field of view (bearing tangent " +
           std::to_string(bearing_tangent(q)) + ", widest " + std::to_string(max_bearing_tan) + ")";
  }

  /// H_m = M dpi/dq(q) cam_T_imu T^-1 P^T (eq. 31). H_x = M dpi/dq(q) cam_T_imu d(T^-1 m)/dd with
  /// d(T^-1 m)/dd = -(T^-1 m)^odot for the body perturbation (eq. 41 with its sign) and
  /// -T^-1 m^odot for the world perturbation.
  MeasurementPrediction<4, 6, 3> predict(const Eigen::Matrix4d& x, const Landmark& m) const {
    const Eigen::Matrix4d x_inv = se3::inverse(x);
    const Eigen::Vector4d s = x_inv * m.homogeneous();  // the point in the IMU frame
    const Eigen::Vector4d q = cam_T_imu * s;
    if (!sees(q.head<3>())) throw unobservable_error(why_unseen(q.head<3>()));
    const Eigen::Matrix4d M = calibration.stereo_matrix();
    const Eigen::Matrix4d M_dpi = M * projection_jacobian(q);
    MeasurementPrediction<4, 6, 3> out;
    out.z = M * (q / q(2));
    out.J_z_m = M_dpi * (cam_T_imu * x_inv).leftCols<3>();
    if constexpr (P == Se3Perturbation::world)
      out.J_z_x = -M_dpi * cam_T_imu * x_inv * se3::odot(m.homogeneous());
    else
      out.J_z_x = -M_dpi * cam_T_imu * se3::odot(s);
    out.Q = pixel_sigma * pixel_sigma * Eigen::Matrix4d::Identity();
    return out;
  }

  Measurement residual(const Measurement& z, const Measurement& z_hat) const { return z - z_hat; }

  /// Stereo triangulation: depth fx b / (uL - uR), the row from the mean of vL and vR; then into
  /// the world through T imu_T_cam. J_m_z and J_m_x give the landmark's covariance.
  LandmarkInit<3, 6, 4> initialize(const Eigen::Matrix4d& x, const Measurement& z) const {
    const auto& c = calibration;
    const double disparity = z(0) - z(2);
    if (!(disparity > 0.0))
      throw unobservable_error("stereo camera: disparity uL - uR = " + std::to_string(disparity) +
                               " px, not positive: the point cannot be triangulated");
    if (disparity < min_disparity)
      throw unobservable_error("stereo camera: disparity uL - uR = " + std::to_string(disparity) + " px, below " +
                               std::to_string(min_disparity) + " px: too far to triangulate as a Gaussian");
    const double depth = c.fx * c.baseline / disparity;
    const double v = 0.5 * (z(1) + z(3));
    const Eigen::Vector3d q((z(0) - c.cx) * depth / c.fx, (v - c.cy) * depth / c.fy, depth);
    // dq/dz: depth depends on uL and uR through the disparity.
    const double dd_dd = -depth / disparity;  // d depth / d disparity
    Eigen::Matrix<double, 3, 4> dq_dz = Eigen::Matrix<double, 3, 4>::Zero();
    dq_dz(0, 0) = depth / c.fx + (z(0) - c.cx) / c.fx * dd_dd;
    dq_dz(0, 2) = -(z(0) - c.cx) / c.fx * dd_dd;
    dq_dz(1, 0) = (v - c.cy) / c.fy * dd_dd;
    dq_dz(1, 2) = -dq_dz(1, 0);
    dq_dz(1, 1) = dq_dz(1, 3) = 0.5 * depth / c.fy;
    dq_dz(2, 0) = dd_dd;
    dq_dz(2, 2) = -dd_dd;
    const Eigen::Matrix4d imu_T_cam = se3::inverse(cam_T_imu);
    const Eigen::Vector4d s = imu_T_cam * q.homogeneous();  // the point in the IMU frame
    const Eigen::Matrix4d world_T_cam = x * imu_T_cam;
    LandmarkInit<3, 6, 4> out;
    out.m = (x * s).head<3>();
    out.J_m_z = world_T_cam.topLeftCorner<3, 3>() * dq_dz;
    if constexpr (P == Se3Perturbation::world)
      out.J_m_x = se3::odot(x * s).topRows<3>();  // exp(d^) T s ~ T s + (T s)^odot d
    else
      out.J_m_x = (x * se3::odot(s)).topRows<3>();  // T exp(d^) s ~ T s + T s^odot d
    out.Q = pixel_sigma * pixel_sigma * Eigen::Matrix4d::Identity();
    return out;
  }

  /// dpi/dq for pi(q) = q / q_3 (eq. 26).
  static Eigen::Matrix4d projection_jacobian(const Eigen::Vector4d& q) {
    Eigen::Matrix4d J = Eigen::Matrix4d::Zero();
    J(0, 0) = J(1, 1) = J(3, 3) = 1.0;
    J(0, 2) = -q(0) / q(2);
    J(1, 2) = -q(1) / q(2);
    J(3, 2) = -q(3) / q(2);
    return J / q(2);
  }
};

using StereoPixelsSe3 = StereoPixelsSe3Of<Se3Perturbation::world>;
using StereoPixelsSe3Body = StereoPixelsSe3Of<Se3Perturbation::body>;

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_STEREO_IMU_SE3
#include "sextant/compiled/extern_instances.hpp"
