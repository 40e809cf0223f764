#include <gtest/gtest.h>

#include <numbers>

#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/testing/model_checks.hpp"

namespace sextant {
namespace {

static_assert(MotionModel<Se2Odometry>);
static_assert(MeasurementModelFor<PointInRobotFrame2D, Se2Odometry>);

TEST(Se2Odometry, JacobianMatchesCentralDifferencesAcrossHeadings) {
  OdometryIncrement2D u{{1.2, -0.3, 0.4}, Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal()};
  for (double h : {-3.1, -1.0, 0.0, 0.7, 3.1}) {
    const auto check = testing::check_motion_jacobians(Se2Odometry{}, Eigen::Vector3d(2.0, -1.0, h), u, 1.0);
    EXPECT_TRUE(check) << check.report;
  }
}

TEST(Se2Odometry, BetweenFactorJacobiansMatchCentralDifferences) {
  static_assert(HasBetweenFactor<Se2Odometry>);
  const OdometryIncrement2D u{{0.8, 0.1, -0.3}, Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal()};
  for (double h : {-3.0, 0.0, 2.0}) {
    const Eigen::Vector3d from(1.0, -2.0, h), to(1.5, -1.2, h + 3.0);
    const auto check = testing::check_between_jacobians(Se2Odometry{}, from, to, u, 1.0);
    EXPECT_TRUE(check) << check.report;
  }
}

TEST(Se2Odometry, ComposesInTheRobotFrameAndRotatesTheNoise) {
  const OdometryIncrement2D u{{1.0, 0.0, std::numbers::pi / 2}, Eigen::Vector3d(4.0, 1.0, 0.1).asDiagonal()};
  const auto p = Se2Odometry{}.predict(Eigen::Vector3d(1.0, 1.0, std::numbers::pi / 2), u, 1.0);
  EXPECT_TRUE(p.x.isApprox(Eigen::Vector3d(1.0, 2.0, std::numbers::pi), 1e-12));
  EXPECT_NEAR(p.R(0, 0), 1.0, 1e-12);  // forward noise (4) now along y
  EXPECT_NEAR(p.R(1, 1), 4.0, 1e-12);
}

TEST(PointInRobotFrame2D, JacobiansAndInverseModelMatchCentralDifferences) {
  for (double h : {-2.5, 0.0, 1.3}) {
    const auto check = testing::check_measurement_jacobians<Se2Odometry>(
        PointInRobotFrame2D{}, Eigen::Vector3d(1.0, 2.0, h), Eigen::Vector2d(4.0, -3.0));
    EXPECT_TRUE(check) << check.report;
  }
  const auto z = PointInRobotFrame2D{}.predict(Eigen::Vector3d(1.0, 1.0, std::numbers::pi / 2), Eigen::Vector2d(1.0, 3.0));
  EXPECT_TRUE(z.z.isApprox(Eigen::Vector2d(2.0, 0.0), 1e-12));  // straight ahead
}

}  // namespace
}  // namespace sextant
