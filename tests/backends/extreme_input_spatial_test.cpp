// Extreme inputs (extreme_input_suite.hpp) on a 6D robot: Se3Odometry, RangeBearing3D.
#include "backends/extreme_input_suite.hpp"
#include "sextant/models/range_bearing_3d.hpp"
#include "sextant/models/se3_odometry.hpp"

namespace sextant::test {
namespace {

struct SpatialWorld {
  static constexpr const char* kName = "spatial";
  static Se3Odometry motion(double) { return {}; }  // the control carries the noise
  static RangeBearing3D sensor(double sigma) {
    RangeBearing3D s;
    s.Q = Eigen::Vector3d(0.05 * sigma, 0.01 * sigma, 0.01 * sigma).cwiseAbs2().asDiagonal();
    return s;
  }
  static OdometryIncrement3D control(double scale, double sigma) {
    Vector6d delta = Vector6d::Zero();
    delta(0) = 0.5 * scale;
    delta(3) = 0.05;
    return {delta, Matrix6d::Identity() * (1e-4 * sigma * sigma)};
  }
  /// (range, yaw, pitch): distinct points for distinct j
  static Eigen::Vector3d measurement(int j, double scale) {
    return {scale * (2.0 + 0.01 * j), -1.0 + 0.001 * j, 0.3 - 0.0003 * j};
  }
  static Gaussian<Vector6d, 6> prior() { return {Vector6d::Zero(), 1e-4 * Matrix6d::Identity()}; }
};

INSTANTIATE_TYPED_TEST_SUITE_P(Spatial, ExtremeInput, ExtremeCases<SpatialWorld>, ExtremeCaseName);

}  // namespace
}  // namespace sextant::test
