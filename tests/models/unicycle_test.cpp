#include <gtest/gtest.h>

#include <numbers>

#include "sextant/models/unicycle.hpp"
#include "sextant/testing/model_checks.hpp"

namespace sextant {
namespace {

static_assert(MotionModel<Unicycle>);
static_assert(HasBetweenFactor<Unicycle>);

TEST(Unicycle, JacobiansMatchCentralDifferencesIncludingStraightMotion) {
  for (double w : {-1.3, -1e-7, 0.0, 1e-5, 0.4, 3.0})
    for (double h : {-3.1, 0.0, 2.0}) {
      const auto check = testing::check_motion_jacobians(Unicycle{}, Eigen::Vector3d(1.0, -2.0, h), {0.7, w}, 0.3);
      EXPECT_TRUE(check) << "w " << w << " h " << h << ": " << check.report;
      const auto between =
          testing::check_between_jacobians(Unicycle{}, Eigen::Vector3d(1.0, -2.0, h), Eigen::Vector3d(1.2, -1.9, h + 0.2),
                                           {0.7, w}, 0.3);
      EXPECT_TRUE(between) << "w " << w << " h " << h << ": " << between.report;
    }
}

TEST(Unicycle, QuarterCircleEndsOnTheCircleAndStraightLineIsTheLimit) {
  const double w = std::numbers::pi / 2, r = 1.0 / w;  // v = 1: radius v / w
  const auto arc = Unicycle{}.predict(Eigen::Vector3d(1.0, 1.0, 0.0), {1.0, w}, 1.0);
  EXPECT_TRUE(arc.x.isApprox(Eigen::Vector3d(1.0 + r, 1.0 + r, w), 1e-12)) << arc.x.transpose();
  const auto straight = Unicycle{}.predict(Eigen::Vector3d(0.0, 0.0, std::numbers::pi / 2), {2.0, 0.0}, 1.5);
  EXPECT_NEAR(straight.x(0), 0.0, 1e-12);
  EXPECT_NEAR(straight.x(1), 3.0, 1e-12);
  const auto almost = Unicycle{}.predict(Eigen::Vector3d(0.0, 0.0, std::numbers::pi / 2), {2.0, 1e-9}, 1.5);
  EXPECT_LT((almost.x - straight.x).norm(), 1e-8);
}

/// The increment's covariance is V M V^T with V the derivative of the increment with respect to
/// (v, w): checked against V by central differences, with the floor and the final rotation off.
TEST(Unicycle, IncrementCovarianceIsTheControlNoisePropagatedThroughTheArc) {
  Unicycle model;
  model.alpha = {0.2, 0.03, 0.05, 0.3, 0.0, 0.0};
  model.floor_rate.setZero();
  for (const UnicycleControl u : {UnicycleControl{0.5, 0.8}, UnicycleControl{1.0, 0.0}, UnicycleControl{0.3, -2.0}}) {
    const double dt = 0.4, h = 1e-6;
    Eigen::Matrix<double, 3, 2> V;
    V.col(0) = (model.increment({u.v + h, u.w}, dt).delta - model.increment({u.v - h, u.w}, dt).delta) / (2 * h);
    V.col(1) = (model.increment({u.v, u.w + h}, dt).delta - model.increment({u.v, u.w - h}, dt).delta) / (2 * h);
    const Eigen::Vector2d M(0.2 * u.v * u.v + 0.03 * u.w * u.w, 0.05 * u.v * u.v + 0.3 * u.w * u.w);
    const Eigen::Matrix3d expected = V * M.asDiagonal() * V.transpose();
    EXPECT_TRUE(model.increment(u, dt).cov.isApprox(expected, 1e-7)) << model.increment(u, dt).cov << "\n" << expected;
  }
}

TEST(Unicycle, StandingStillKeepsAnInvertibleFloorNoise) {
  const auto step = Unicycle{}.increment({0.0, 0.0}, 0.5);
  EXPECT_TRUE(step.delta.isZero());
  EXPECT_TRUE(step.cov.isApprox(Eigen::Matrix3d(Eigen::Vector3d::Constant(0.5e-6).asDiagonal())));
}

}  // namespace
}  // namespace sextant
