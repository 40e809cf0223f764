#include "sextant/models/se2_world_frame.hpp"

#include <gtest/gtest.h>

#include <random>

#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/models/unicycle.hpp"
#include "sextant/testing/model_checks.hpp"

namespace sextant {
namespace {

using WorldUnicycle = InWorldFrame<Unicycle>;
using WorldRangeBearing = SeenInWorldFrame<RangeBearing2D>;
static_assert(HasBetweenFactor<WorldUnicycle>);
static_assert(MeasurementModelFor<WorldRangeBearing, WorldUnicycle>);
// The iSAM text files' pair (sextant-run's [isam] filters_in_world_frame).
using WorldOdometry = InWorldFrame<Se2Odometry>;
using WorldPoint = SeenInWorldFrame<PointInRobotFrame2D>;
static_assert(HasBetweenFactor<WorldOdometry>);
static_assert(MeasurementModelFor<WorldPoint, WorldOdometry>);

/// Random poses far from the origin (the world chart's lever arm) and landmarks around them.
std::vector<Eigen::Vector3d> random_poses(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> position(-20.0, 20.0), heading(-3.1, 3.1);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 20; ++i) out.emplace_back(position(rng), position(rng), heading(rng));
  return out;
}

TEST(Se2WorldFrame, ChartIsConsistentAndItsDerivativeIsToAdditive) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> unit(0.0, 0.3);
  for (const auto& x : random_poses(rng)) {
    const Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
    EXPECT_LT((Se2WorldSpace::minus(Se2WorldSpace::plus(x, d), x) - d).norm(), 1e-12);
    // d plus(x, d)/dd at 0, by central differences in the additive chart.
    Eigen::Matrix3d numeric;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d h = 1e-6 * Eigen::Vector3d::Unit(i);
      numeric.col(i) = Se2Space::minus(Se2WorldSpace::plus(x, h), Se2WorldSpace::plus(x, -h)) / 2e-6;
    }
    EXPECT_LT((numeric - Se2WorldSpace::to_additive(x)).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_TRUE((Se2WorldSpace::to_additive(x) * Se2WorldSpace::from_additive(x)).isIdentity(1e-12));
    EXPECT_EQ(Se2WorldSpace::position_error(x, Eigen::Vector3d(0, 0, 0)), x.head<2>());
  }
}

TEST(Se2WorldFrame, JacobiansMatchCentralDifferencesInTheWorldChart) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> offset(-6.0, 6.0);
  for (const auto& x : random_poses(rng)) {
    for (double w : {-0.8, 0.0, 1.1}) {
      const auto motion = testing::check_motion_jacobians(WorldUnicycle{}, x, {0.6, w}, 0.25);
      EXPECT_TRUE(motion) << motion.report;
      const Eigen::Vector3d to = WorldUnicycle{}.predict(x, {0.6, w}, 0.25).x + Eigen::Vector3d(0.02, -0.01, 0.03);
      const auto between = testing::check_between_jacobians(WorldUnicycle{}, x, to, {0.6, w}, 0.25);
      EXPECT_TRUE(between) << between.report;
    }
    WorldRangeBearing sensor;
    sensor.sensor_pose << 0.1, -0.05, 0.2;  // an offset sensor: its lever arm enters H
    const Eigen::Vector2d m = x.head<2>() + Eigen::Vector2d(offset(rng), offset(rng));
    const auto measurement = testing::check_measurement_jacobians<WorldUnicycle>(sensor, x, m);
    EXPECT_TRUE(measurement) << measurement.report;
  }
}

TEST(Se2WorldFrame, OdometryAndPointJacobiansMatchCentralDifferencesInTheWorldChart) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> offset(-6.0, 6.0);
  Eigen::Matrix3d cov;
  cov << 0.04, 0.01, 0.002, 0.01, 0.09, -0.003, 0.002, -0.003, 0.01;  // correlated, as the files' records
  for (const auto& x : random_poses(rng)) {
    for (const Eigen::Vector3d& delta : {Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.7, -0.2, 0.4)}) {
      const OdometryIncrement2D u{delta, cov};
      const auto motion = testing::check_motion_jacobians(WorldOdometry{}, x, u, 1.0);
      EXPECT_TRUE(motion) << motion.report;
      const Eigen::Vector3d to = WorldOdometry{}.predict(x, u, 1.0).x + Eigen::Vector3d(0.02, -0.01, 0.03);
      const auto between = testing::check_between_jacobians(WorldOdometry{}, x, to, u, 1.0);
      EXPECT_TRUE(between) << between.report;
    }
    const Eigen::Vector2d m = x.head<2>() + Eigen::Vector2d(offset(rng), offset(rng));
    const auto measurement = testing::check_measurement_jacobians<WorldOdometry>(WorldPoint{}, x, m);
    EXPECT_TRUE(measurement) << measurement.report;
  }
}

/// The properties the filter relies on: a body-frame motion has the Jacobian I in this chart, and a
/// measurement Jacobian annihilates the global translation and rotation (rho, phi) that moves the
/// pose by (rho, phi) and the landmark by rho + phi J m, whatever the robot's estimate.
TEST(Se2WorldFrame, MotionJacobianIsIdentityAndMeasurementsSeeNoGlobalMotion) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> offset(-6.0, 6.0);
  WorldRangeBearing sensor;
  sensor.sensor_pose << 0.1, -0.05, 0.2;
  Eigen::Matrix2d J;
  J << 0, -1, 1, 0;
  auto expect_no_global_motion_seen = [&J](const auto& prediction, const Eigen::Vector2d& m, const char* sensor_name) {
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d robot = Eigen::Vector3d::Unit(i);
      const Eigen::Vector2d landmark = robot.head<2>() + robot(2) * J * m;
      EXPECT_LT((prediction.J_z_x * robot + prediction.J_z_m * landmark).norm(), 1e-12) << sensor_name << ", direction " << i;
    }
  };
  for (const auto& x : random_poses(rng)) {
    EXPECT_TRUE(WorldUnicycle{}.predict(x, {0.9, -0.7}, 0.3).J_x_x.isIdentity(1e-12));
    const Eigen::Vector2d m = x.head<2>() + Eigen::Vector2d(offset(rng), offset(rng));
    expect_no_global_motion_seen(sensor.predict(x, m), m, "range-bearing");
    // The same for the iSAM files' odometry and points seen in the robot frame.
    EXPECT_TRUE(WorldOdometry{}.predict(x, {Eigen::Vector3d(0.8, 0.1, -0.3), Eigen::Matrix3d::Identity()}, 1.0)
                    .J_x_x.isIdentity(1e-12));
    expect_no_global_motion_seen(WorldPoint{}.predict(x, m), m, "point in the robot frame");
  }
}

}  // namespace
}  // namespace sextant
