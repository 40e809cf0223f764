// The concepts accept the shipped models and reject models that break the contract.
#include "sextant/core/concepts.hpp"

#include <gtest/gtest.h>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/models/beacon_ship_2d.hpp"

namespace sextant {
namespace {

static_assert(MotionModel<BeaconShip2D>);
static_assert(MeasurementModelFor<BeaconOffset2D, BeaconShip2D>);
static_assert(SlamBackend<EkfSlam<BeaconShip2D, BeaconOffset2D>>);

struct MotionWithoutSpace {
  using State = Eigen::Vector2d;
  using Control = Eigen::Vector2d;
  static constexpr int kDim = 2;
  MotionPrediction<State, kDim> predict(const State&, const Control&, double) const { return {}; }
};
static_assert(!MotionModel<MotionWithoutSpace>);

struct MotionWithWrongJacobianSize : BeaconShip2D {
  MotionPrediction<State, 3> predict(const State&, const Control&, double) const { return {}; }
};
static_assert(!MotionModel<MotionWithWrongJacobianSize>);

struct SensorWithoutInverse {
  using Landmark = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  MeasurementPrediction<2, 2, 2> predict(const Eigen::Vector2d&, const Landmark&) const { return {}; }
  Measurement residual(const Measurement& a, const Measurement& b) const { return a - b; }
};
static_assert(!MeasurementModelFor<SensorWithoutInverse, BeaconShip2D>);

struct SensorForThreeDimensionalRobot : BeaconOffset2D {
  MeasurementPrediction<2, 3, 2> predict(const Eigen::Vector2d&, const Landmark&) const { return {}; }
};
static_assert(!MeasurementModelFor<SensorForThreeDimensionalRobot, BeaconShip2D>);

TEST(Concepts, AreCheckedAtCompileTime) { SUCCEED(); }

}  // namespace
}  // namespace sextant
