#include "sextant/models/euler_camera_12d.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <numbers>
#include <random>

#include "sextant/testing/model_checks.hpp"

namespace sextant {
namespace {

constexpr double kPi = std::numbers::pi;
static_assert(MotionModel<EulerCamera12D>);
static_assert(MeasurementModelFor<PointInCamera3D, EulerCamera12D>);

/// A random camera state: position within a metre, phi in (-pi/2, pi/2), theta and psi anywhere,
/// velocities of a handheld camera.
Vector12d random_state(std::mt19937_64& rng, double phi) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector12d x;
  x << u(rng), u(rng), u(rng), phi, kPi * u(rng), kPi * u(rng), 0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng), u(rng), u(rng),
      u(rng);
  return x;
}

std::vector<double> test_phis() {
  const double near = kPi / 2 - 1e-3;  // within 1e-3 rad of the gimbal singularity
  return {0.0, 0.4, -1.2, near, -near};
}

TEST(EulerCamera12D, MotionJacobianMatchesCentralDifferencesIncludingNearTheSingularity) {
  std::mt19937_64 rng(7);
  EulerCamera12D model;
  model.gamma << 0.9, 0.95, 1.0;
  model.lambda << 0.8, 1.0, 0.7;
  for (double phi : test_phis())
    for (int trial = 0; trial < 20; ++trial) {
      const Vector12d x = random_state(rng, phi);
      // Near the singularity J(eta) grows as 1/cos(phi): a step of 1e-6 rad would cross 1e-3 of the
      // way to it, so the difference step shrinks with the distance (the check itself is unchanged).
      const double step = std::min(1e-6, 1e-4 * std::cos(phi));
      const auto check = testing::check_motion_jacobians(model, x, {}, 0.05, {.step = step, .tolerance = 1e-5});
      EXPECT_TRUE(check) << "phi " << phi << "\n" << check.report;
    }
}

TEST(EulerCamera12D, MeasurementAndInverseJacobiansMatchCentralDifferences) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PointInCamera3D sensor;
  for (double phi : test_phis())
    for (int trial = 0; trial < 20; ++trial) {
      const Vector12d x = random_state(rng, phi);
      // A landmark in front of the camera, so that the stereo noise is that of a real point.
      const Eigen::Vector3d in_camera(0.3 * u(rng), 0.3 * u(rng), 0.5 + 0.5 * std::abs(u(rng)));
      const Eigen::Vector3d m = x.head<3>() + euler_yxz::rotation(x.segment<3>(3)) * in_camera;
      const auto check = testing::check_measurement_jacobians<EulerCamera12D>(sensor, x, m);
      EXPECT_TRUE(check) << "phi " << phi << "\n" << check.report;
    }
}

TEST(EulerCamera12D, MotionThrowsAtTheGimbalSingularity) {
  Vector12d x = Vector12d::Zero();
  x(3) = kPi / 2;
  x(11) = 0.5;
  EXPECT_THROW(EulerCamera12D{}.predict(x, {}, 0.1), numerical_error);
}

TEST(EulerYxz, RotationIsRyRxRzAndRateMatrixInvertsTheBodyJacobian) {
  const Eigen::Vector3d eta(0.3, -2.0, 1.1);
  const Eigen::Matrix3d R = euler_yxz::rotation(eta);
  EXPECT_TRUE(R.isApprox(Eigen::AngleAxisd(eta(1), Eigen::Vector3d::UnitY()).toRotationMatrix() *
                             Eigen::AngleAxisd(eta(0), Eigen::Vector3d::UnitX()).toRotationMatrix() *
                             Eigen::AngleAxisd(eta(2), Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                         1e-14));
  EXPECT_TRUE((euler_yxz::rate_matrix(eta) * euler_yxz::body_jacobian(eta)).isIdentity(1e-12));
}

TEST(EulerYxz, AngleRatesIntegrateTheBodyRate) {
  // R(eta + J(eta) omega dt) = R(eta) Exp(omega dt) + O(dt^2): halving dt quarters the error.
  const Eigen::Vector3d eta(-0.7, 2.5, -0.4), omega(0.3, -1.1, 0.6);
  auto error = [&](double dt) {
    const Eigen::Matrix3d expected = euler_yxz::rotation(eta) * so3::exp(omega * dt);
    return (euler_yxz::rotation(eta + euler_yxz::rate_matrix(eta) * omega * dt) - expected).norm();
  };
  EXPECT_NEAR(error(1e-3) / error(5e-4), 4.0, 0.05);
  EXPECT_LT(error(1e-3), 1e-5);
}

TEST(EulerYxz, CanonicalAnglesGiveTheSameRotationWithPhiInRange) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d eta(u(rng), u(rng), u(rng));
    const Eigen::Vector3d c = euler_yxz::canonical(eta);
    EXPECT_LE(std::abs(c(0)), kPi / 2);
    EXPECT_LE(std::abs(c(1)), kPi);
    EXPECT_LE(std::abs(c(2)), kPi);
    EXPECT_TRUE(euler_yxz::rotation(c).isApprox(euler_yxz::rotation(eta), 1e-12)) << eta.transpose();
  }
  // plus keeps the state canonical.
  Vector12d x = Vector12d::Zero();
  x(3) = kPi / 2 - 0.01;
  Vector12d delta = Vector12d::Zero();
  delta(3) = 0.03;
  const Vector12d y = EulerCamera12Space::plus(x, delta);
  EXPECT_NEAR(y(3), kPi / 2 - 0.02, 1e-12);
  EXPECT_NEAR(std::abs(y(4)), kPi, 1e-12);
}

TEST(StereoPointNoise, IsTheFirstOrderPropagationOfPixelNoiseThroughTriangulation) {
  const StereoPointNoise noise{.focal_px = 500.0, .baseline = 0.12, .pixel_sigma = 0.7};
  const Eigen::Vector3d q(0.1, -0.05, 0.8);
  // Triangulation from (u_left, v_left, u_right), principal point at 0.
  auto triangulate = [&](const Eigen::Vector3d& pixels) -> Eigen::Vector3d {
    const double d = pixels(0) - pixels(2);
    return Eigen::Vector3d(pixels(0), pixels(1), noise.focal_px) * noise.baseline / d;
  };
  const Eigen::Vector3d pixels(noise.focal_px * q.x() / q.z(), noise.focal_px * q.y() / q.z(),
                               noise.focal_px * (q.x() - noise.baseline) / q.z());
  ASSERT_TRUE(triangulate(pixels).isApprox(q, 1e-12));
  Eigen::Matrix3d A;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d h = Eigen::Vector3d::Zero();
    h(i) = 1e-4;
    A.col(i) = (triangulate(pixels + h) - triangulate(pixels - h)) / 2e-4;
  }
  const Eigen::Matrix3d expected = noise.pixel_sigma * noise.pixel_sigma * A * A.transpose();
  EXPECT_TRUE(noise.covariance(q).isApprox(expected, 1e-6));
  // Depth std sqrt(2) z^2 sigma / (f b).
  EXPECT_NEAR(std::sqrt(noise.covariance(q)(2, 2)),
              std::sqrt(2.0) * q.z() * q.z() * noise.pixel_sigma / (noise.focal_px * noise.baseline), 1e-12);
}

TEST(PointInCamera3D, MeasuresThePointInTheCameraFrameAndInvertsIt) {
  PointInCamera3D sensor;
  Vector12d x = Vector12d::Zero();
  x.head<3>() << 1.0, 2.0, 3.0;
  x(4) = kPi / 2;  // theta: the camera's optical axis (z) turns to world +x
  const auto prediction = sensor.predict(x, Eigen::Vector3d(3.0, 2.0, 3.0));
  EXPECT_TRUE(prediction.z.isApprox(Eigen::Vector3d(0.0, 0.0, 2.0), 1e-12)) << prediction.z.transpose();
  EXPECT_TRUE(sensor.initialize(x, prediction.z).m.isApprox(Eigen::Vector3d(3.0, 2.0, 3.0), 1e-12));
  // Depth noise exceeds the lateral noise: the covariance is anisotropic.
  EXPECT_GT(prediction.Q(2, 2), 10.0 * prediction.Q(0, 0));
}

}  // namespace
}  // namespace sextant
