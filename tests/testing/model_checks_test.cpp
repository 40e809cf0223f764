// The Jacobian checker must catch wrong Jacobians, not only pass right ones.
#include "sextant/testing/model_checks.hpp"

#include <gtest/gtest.h>

#include "sextant/models/beacon_ship_2d.hpp"

namespace sextant {
namespace {

/// The ship model with a Jacobian that ignores part of the motion: a classic sign/term slip.
struct ShipWithCorruptJacobian : BeaconShip2D {
  MotionPrediction<State, 2> predict(const State& x, const Control& u, double dt) const {
    auto out = BeaconShip2D::predict(x, u, dt);
    out.J_x_x(0, 1) += 0.5;
    return out;
  }
};

/// A nonlinear motion model (drag proportional to position) to show a correct non-identity G passes.
struct ShipWithDrag : BeaconShip2D {
  MotionPrediction<State, 2> predict(const State& x, const Control& u, double dt) const {
    auto out = BeaconShip2D::predict(x, u, dt);
    out.x -= dt * 0.01 * x.cwiseProduct(x);
    out.J_x_x -= dt * 0.02 * x.asDiagonal().toDenseMatrix();
    return out;
  }
};

struct SensorWithCorruptLandmarkJacobian : BeaconOffset2D {
  MeasurementPrediction<2, 2, 2> predict(const Eigen::Vector2d& x, const Landmark& m) const {
    auto out = BeaconOffset2D::predict(x, m);
    out.J_z_m = -out.J_z_m;
    return out;
  }
};

struct SensorWithWrongInverse : BeaconOffset2D {
  LandmarkInit<2, 2, 2> initialize(const Eigen::Vector2d& x, const Measurement& z) const {
    auto out = BeaconOffset2D::initialize(x, z);
    out.m = x - z;  // inverse that does not invert predict
    out.J_m_z = -out.J_m_z;
    return out;
  }
};

const Eigen::Vector2d kX(1.0, 2.0), kU(5.0, 0.3), kM(10.0, -3.0);

TEST(ModelChecks, CorrectModelsPass) {
  EXPECT_TRUE(testing::check_motion_jacobians(BeaconShip2D{}, kX, kU, 1.0));
  const auto drag = testing::check_motion_jacobians(ShipWithDrag{}, kX, kU, 1.0);
  EXPECT_TRUE(drag) << drag.report;
}

TEST(ModelChecks, CorruptMotionJacobianFailsWithReadableReport) {
  const auto check = testing::check_motion_jacobians(ShipWithCorruptJacobian{}, kX, kU, 1.0);
  EXPECT_FALSE(check);
  EXPECT_NE(check.report.find("J_x_x(0,1): analytic 0.5 vs numeric 0"), std::string::npos) << check.report;
}

TEST(ModelChecks, CorruptMeasurementJacobianFails) {
  const auto check = testing::check_measurement_jacobians<BeaconShip2D>(SensorWithCorruptLandmarkJacobian{}, kX, kM);
  EXPECT_FALSE(check);
  EXPECT_NE(check.report.find("J_z_m"), std::string::npos) << check.report;
  EXPECT_EQ(check.report.find("J_z_x"), std::string::npos) << check.report;
}

TEST(ModelChecks, WrongInverseModelFails) {
  const auto check = testing::check_measurement_jacobians<BeaconShip2D>(SensorWithWrongInverse{}, kX, kM);
  EXPECT_FALSE(check);
  EXPECT_NE(check.report.find("inverse model"), std::string::npos) << check.report;
}

}  // namespace
}  // namespace sextant
