#include "sextant/models/euler_camera_12d.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <numbers>
#include <random>

#include "sextant/core/observability_constraints.hpp"
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

/// The camera claiming psi as well (a wrong claim the check must see).
struct ClaimingPsi : EulerCamera12D {
  static constexpr int kConditionallyLinearDims = 7;
};

TEST(EulerCamera12D, VelocityAndRateAreAConditionallyLinearTailNoMeasurementSees) {
  static_assert(conditionally_linear_dims_v<EulerCamera12D> == 6);
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  EulerCamera12D model;
  model.gamma << 0.9, 0.95, 1.0;
  model.lambda << 0.8, 1.0, 0.7;
  PointInCamera3D sensor;
  for (double phi : {0.0, 0.4, -1.2})
    for (int trial = 0; trial < 10; ++trial) {
      const Vector12d x = random_state(rng, phi);
      const Eigen::Vector3d in_camera(0.3 * u(rng), 0.3 * u(rng), 0.5 + 0.5 * std::abs(u(rng)));
      const Eigen::Vector3d m = x.head<3>() + euler_yxz::rotation(x.segment<3>(3)) * in_camera;
      const auto check = testing::check_conditionally_linear_tail(model, sensor, x, {}, 0.05, m, 0.05);
      EXPECT_TRUE(check) << "phi " << phi << "\n" << check.report;
    }
  // The check sees a wrong claim: psi, the 7th entry from the end, turns the position's step R v dt.
  const Vector12d x = random_state(rng, 0.4);
  const Eigen::Vector3d m = x.head<3>() + euler_yxz::rotation(x.segment<3>(3)) * Eigen::Vector3d(0.1, 0.0, 0.6);
  EXPECT_FALSE(testing::check_conditionally_linear_tail(ClaimingPsi{}, sensor, x, {}, 0.05, m, 0.05));
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
  // A disparity measured with its own noise: the same propagation from (u_left, v_left, d), whose
  // errors are independent, and the depth std z^2 sigma_d / (f b).
  StereoPointNoise measured = noise;
  measured.disparity_sigma = 0.1;
  auto from_disparity = [&](const Eigen::Vector3d& uvd) { return triangulate(Eigen::Vector3d(uvd(0), uvd(1), uvd(0) - uvd(2))); };
  const Eigen::Vector3d uvd(pixels(0), pixels(1), pixels(0) - pixels(2));
  Eigen::Matrix3d B;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d h = Eigen::Vector3d::Zero();
    h(i) = 1e-4;
    B.col(i) = (from_disparity(uvd + h) - from_disparity(uvd - h)) / 2e-4;
  }
  const Eigen::Vector3d variances(noise.pixel_sigma * noise.pixel_sigma, noise.pixel_sigma * noise.pixel_sigma, 0.01);
  EXPECT_TRUE(measured.covariance(q).isApprox(B * variances.asDiagonal() * B.transpose(), 1e-6));
  EXPECT_NEAR(std::sqrt(measured.covariance(q)(2, 2)), q.z() * q.z() * 0.1 / (noise.focal_px * noise.baseline), 1e-12);
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

namespace sextant {
namespace {

/// The state after moving the world by translation t and rotation Exp(w) (exact, not linearized).
Vector12d moved_world(const Vector12d& x, const Eigen::Vector3d& t, const Eigen::Vector3d& w) {
  const Eigen::Matrix3d Rw = so3::exp(w);
  Vector12d out = x;
  out.head<3>() = Rw * x.head<3>() + t;
  // the Euler angles of Exp(w) R(eta): eta + d with R(eta + d) = Exp(w) R(eta), solved by Newton
  Eigen::Vector3d eta = x.segment<3>(3);
  const Eigen::Matrix3d target = Rw * euler_yxz::rotation(eta);
  for (int i = 0; i < 20; ++i)
    eta += euler_yxz::rate_matrix(eta) * so3::log(euler_yxz::rotation(eta).transpose() * target);
  out.segment<3>(3) = eta;
  return out;
}

TEST(EulerCamera12D, WorldMotionDirectionsAreTheDerivativeOfMovingTheWorldAndLeaveMeasurementsAlone) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PointInCamera3D sensor;
  EulerCamera12D motion;
  motion.gamma << 0.9, 0.95, 1.0;
  motion.lambda << 0.8, 1.0, 0.7;
  for (double phi : {0.0, 0.4, -1.2})
    for (int trial = 0; trial < 10; ++trial) {
      const Vector12d x = random_state(rng, phi);
      const Eigen::Vector3d l(2 + u(rng), u(rng), u(rng));
      const auto N = EulerCamera12Space::world_motion_directions(x);
      const auto N_l = point_world_motion_directions(l);
      constexpr double h = 1e-6;
      for (int k = 0; k < 6; ++k) {  // each column against the exact motion, by central differences
        Eigen::Matrix<double, 6, 1> e = Eigen::Matrix<double, 6, 1>::Unit(k);
        const Vector12d plus = moved_world(x, h * e.head<3>(), h * e.tail<3>());
        const Vector12d minus = moved_world(x, -h * e.head<3>(), -h * e.tail<3>());
        EXPECT_LT((EulerCamera12Space::minus(plus, minus) / (2 * h) - N.col(k)).norm(), 1e-6) << "column " << k;
      }
      // moving the world leaves the measurement of a moved landmark the same ...
      const Eigen::Vector3d t(u(rng), u(rng), u(rng)), w(0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng));
      const Vector12d x_moved = moved_world(x, t, w);
      const Eigen::Vector3d l_moved = so3::exp(w) * l + t;
      EXPECT_LT((sensor.predict(x_moved, l_moved).z - sensor.predict(x, l).z).norm(), 1e-9);
      // ... so H N = 0 at one linearization point; the motion maps N(x) onto N(g(x)) up to the
      // Euler-angle integration's O(dt^2) (eta' = eta + J(eta) omega dt is first order): halving dt
      // must divide the mismatch by about 4 (at least 3)
      const auto m = sensor.predict(x, l);
      EXPECT_LT((m.J_z_x * N + m.J_z_m * N_l).norm(), 1e-9);
      const auto mismatch = [&](double dt) {
        const auto g = motion.predict(x, {}, dt);
        return (g.J_x_x * N - EulerCamera12Space::world_motion_directions(g.x)).norm();
      };
      EXPECT_GT(mismatch(0.02) / mismatch(0.01), 3.0) << mismatch(0.02) << " against " << mismatch(0.01);
    }
}

TEST(ObservabilityConstraints, TheNearestJacobiansThatKeepTheWorldsMotionsUnobservable) {
  std::mt19937_64 rng(12);
  const Vector12d x_prev = random_state(rng, 0.3), x_next = random_state(rng, -0.2), x_far = random_state(rng, 0.5);
  const auto N_prev = EulerCamera12Space::world_motion_directions(x_prev);
  const auto N_next = EulerCamera12Space::world_motion_directions(x_next);
  const Matrix12d G = Matrix12d::Random();
  const Matrix12d G_star = constrained_transition<12, 6>(G, N_prev, N_next);
  EXPECT_LT((G_star * N_prev - N_next).norm(), 1e-10);
  // nearest: the change lies in the rows' span of N_prev^T (it is orthogonal to what N_prev does not reach)
  const Eigen::Matrix<double, 12, 6> basis = N_prev.householderQr().householderQ() * Eigen::Matrix<double, 12, 6>::Identity();
  const Matrix12d projector = basis * basis.transpose();
  EXPECT_LT(((G_star - G) * (Matrix12d::Identity() - projector)).norm(), 1e-10);
  EXPECT_LT((constrained_transition<12, 6>(G_star, N_prev, N_next) - G_star).norm(), 1e-10) << "idempotent";

  LinearizedObservation<3, 12, 3> lin{7, 12, Eigen::Matrix<double, 3, 12>::Random(), Eigen::Matrix3d::Random(),
                                      Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
  const Eigen::Vector3d l(3.0, -1.0, 0.5);
  const auto N_x = EulerCamera12Space::world_motion_directions(x_far);
  constrain_observation(lin, N_x, point_world_motion_directions(l));
  EXPECT_LT((lin.J_z_x * N_x + lin.J_z_m * point_world_motion_directions(l)).norm(), 1e-10);
  // an H that already has the null space is left as it is
  const auto exact = PointInCamera3D{}.predict(x_far, l);
  LinearizedObservation<3, 12, 3> same{7, 12, exact.J_z_x, exact.J_z_m, exact.Q, Eigen::Vector3d::Zero()};
  constrain_observation(same, N_x, point_world_motion_directions(l));
  EXPECT_LT((same.J_z_x - exact.J_z_x).norm() + (same.J_z_m - exact.J_z_m).norm(), 1e-9);
}

}  // namespace
}  // namespace sextant
