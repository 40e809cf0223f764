// Extreme inputs (extreme_input_suite.hpp) on the thesis's beacon ship: BeaconShip2D, BeaconOffset2D.
#include "backends/extreme_input_suite.hpp"
#include "sextant/models/beacon_ship_2d.hpp"

namespace sextant::test {
namespace {

struct ShipWorld {
  static constexpr const char* kName = "ship";
  static BeaconShip2D motion(double sigma) {
    BeaconShip2D m;
    m.sigma_v *= sigma;
    m.sigma_heading *= sigma;
    return m;
  }
  static BeaconOffset2D sensor(double sigma) { return BeaconOffset2D{2.0 * sigma}; }
  /// (speed, compass heading)
  static Eigen::Vector2d control(double scale, double) { return {10.0 * scale, 0.3}; }
  static Eigen::Vector2d measurement(int j, double scale) { return scale * Eigen::Vector2d(5.0 + 3.0 * j, 2.0 + j % 7); }
  static Gaussian<Eigen::Vector2d, 2> prior() { return {Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity()}; }
};

INSTANTIATE_TYPED_TEST_SUITE_P(Ship, ExtremeInput, ExtremeCases<ShipWorld>, ExtremeCaseName);

}  // namespace
}  // namespace sextant::test
