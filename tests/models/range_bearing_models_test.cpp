#include <gtest/gtest.h>

#include <numbers>

#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/range_bearing_3d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/models/se3_odometry.hpp"
#include "sextant/testing/model_checks.hpp"

namespace sextant {
namespace {

constexpr double kPi = std::numbers::pi;

static_assert(MeasurementModelFor<RangeBearing2D, Se2Odometry>);
static_assert(MotionModel<Se3Odometry>);
static_assert(HasBetweenFactor<Se3Odometry>);
static_assert(MeasurementModelFor<RangeBearing3D, Se3Odometry>);

Vector6d pose6(double x, double y, double z, double yaw, double pitch, double roll) {
  return (Vector6d() << x, y, z, yaw, pitch, roll).finished();
}

TEST(RangeBearing2D, JacobiansAndInverseModelMatchCentralDifferencesWithSensorOffset) {
  RangeBearing2D sensor;
  for (const Eigen::Vector3d& mount : {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(0.3, -0.2, 0.5)}) {
    sensor.sensor_pose = mount;
    for (double h : {-3.1, -1.0, 0.0, 0.7, 3.1}) {
      const auto check = testing::check_measurement_jacobians<Se2Odometry>(sensor, Eigen::Vector3d(1.0, 2.0, h),
                                                                           Eigen::Vector2d(-3.0, 5.0));
      EXPECT_TRUE(check) << check.report;
    }
  }
}

TEST(RangeBearing2D, MeasuresRangeAndBearingFromTheSensor) {
  RangeBearing2D sensor;
  sensor.sensor_pose << 1.0, 0.0, kPi / 2;  // 1 m ahead, looking left
  const auto p = sensor.predict(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector2d(1.0, 2.0));
  EXPECT_NEAR(p.z(0), 2.0, 1e-12);
  EXPECT_NEAR(p.z(1), 0.0, 1e-12);
  // The bearing residual wraps across +-pi.
  EXPECT_NEAR(sensor.residual(Eigen::Vector2d(1.0, kPi - 0.01), Eigen::Vector2d(1.0, -kPi + 0.01))(1), -0.02, 1e-12);
}

TEST(Pose3Euler, ComposeAndRelativePoseAreInverse) {
  const Vector6d a = pose6(1.0, -2.0, 0.5, 2.5, 0.4, -0.3), b = pose6(0.3, 0.2, -0.1, -1.0, 0.2, 2.8);
  const Vector6d ab = compose<double>(a, b);
  EXPECT_LT(Pose3EulerSpace::minus(relative_pose<double>(a, ab), b).norm(), 1e-12);
  EXPECT_TRUE(rotation_of<double>(ab).isApprox(rotation_of<double>(a) * rotation_of<double>(b), 1e-12));
  // Rz(yaw) first: a 90 degree yaw turns the x axis into y.
  EXPECT_TRUE((rotation_from_ypr(kPi / 2, 0.0, 0.0) * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
}

TEST(Se3Odometry, JacobiansMatchCentralDifferences) {
  OdometryIncrement3D u;
  u.delta = pose6(0.3, -0.1, 0.05, 0.2, -0.1, 0.15);
  u.cov = (Vector6d() << 0.01, 0.02, 0.03, 0.001, 0.002, 0.003).finished().asDiagonal();
  for (double yaw : {-3.0, 0.0, 1.4, 3.1}) {
    const Vector6d x = pose6(1.0, 2.0, -0.5, yaw, 0.3, -0.6);
    const auto motion = testing::check_motion_jacobians(Se3Odometry{}, x, u, 1.0);
    EXPECT_TRUE(motion) << motion.report;
    const Vector6d to = Se3Odometry{}.predict(x, u, 1.0).x + pose6(0.01, 0.02, -0.01, 0.02, 0.01, -0.02);
    const auto between = testing::check_between_jacobians(Se3Odometry{}, x, to, u, 1.0);
    EXPECT_TRUE(between) << between.report;
    EXPECT_LT(Se3Odometry{}.between(x, Se3Odometry{}.predict(x, u, 1.0).x, u, 1.0).r.norm(), 1e-12);
  }
}

TEST(Se3Odometry, PlanarMotionAgreesWithSe2Odometry) {
  OdometryIncrement3D u3;
  u3.delta = pose6(0.4, 0.1, 0.0, 0.3, 0.0, 0.0);
  u3.cov.setZero();
  u3.cov.diagonal() << 0.01, 0.02, 0.0, 0.003, 0.0, 0.0;
  const OdometryIncrement2D u2{{0.4, 0.1, 0.3}, Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal()};
  const auto p3 = Se3Odometry{}.predict(pose6(1.0, 2.0, 0.0, 2.0, 0.0, 0.0), u3, 1.0);
  const auto p2 = Se2Odometry{}.predict(Eigen::Vector3d(1.0, 2.0, 2.0), u2, 1.0);
  const std::array<int, 3> planar{0, 1, 3};
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(p3.x(planar[r]), p2.x(r), 1e-12);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(p3.J_x_x(planar[r], planar[c]), p2.J_x_x(r, c), 1e-12);
      EXPECT_NEAR(p3.R(planar[r], planar[c]), p2.R(r, c), 1e-12);
    }
  }
}

TEST(RangeBearing3D, JacobiansAndInverseModelMatchCentralDifferences) {
  RangeBearing3D sensor;
  for (const Vector6d& mount : {Vector6d::Zero().eval(), pose6(0.5, 0.2, 0.1, 80.0 * kPi / 180, -20.0 * kPi / 180, 10.0 * kPi / 180)}) {
    sensor.sensor_pose = mount;
    for (double yaw : {-2.0, 0.0, 1.0}) {
      const auto check = testing::check_measurement_jacobians<Se3Odometry>(
          sensor, pose6(1.0, -1.0, 0.2, yaw, 0.1, -0.2), Eigen::Vector3d(4.0, 3.0, 1.5));
      EXPECT_TRUE(check) << check.report;
    }
  }
}

TEST(RangeBearing3D, PitchIsMinusTheElevationAsInMrpt) {
  const RangeBearing3D sensor;
  const auto p = sensor.predict(Vector6d::Zero(), Eigen::Vector3d(1.0, 1.0, std::sqrt(2.0)));
  EXPECT_NEAR(p.z(0), 2.0, 1e-12);
  EXPECT_NEAR(p.z(1), kPi / 4, 1e-12);
  EXPECT_NEAR(p.z(2), -kPi / 4, 1e-12);  // above the sensor: negative pitch
}

}  // namespace
}  // namespace sextant
