// Extreme inputs (extreme_input_suite.hpp) on a planar robot: Se2Odometry, RangeBearing2D.
#include "backends/extreme_input_suite.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant::test {
namespace {

struct PlanarWorld {
  static constexpr const char* kName = "planar";
  static Se2Odometry motion(double) { return {}; }  // the control carries the noise
  static RangeBearing2D sensor(double sigma) {
    RangeBearing2D s;
    s.Q = Eigen::Vector2d(0.05 * sigma, 0.01 * sigma).cwiseAbs2().asDiagonal();
    return s;
  }
  static OdometryIncrement2D control(double scale, double sigma) {
    return {Eigen::Vector3d(0.5 * scale, 0.0, 0.05), Eigen::Matrix3d::Identity() * (1e-4 * sigma * sigma)};
  }
  /// (range, bearing): distinct points for distinct j
  static Eigen::Vector2d measurement(int j, double scale) { return {scale * (2.0 + 0.01 * j), -1.0 + 0.001 * j}; }
  static Gaussian<Eigen::Vector3d, 3> prior() { return {Eigen::Vector3d::Zero(), 1e-4 * Eigen::Matrix3d::Identity()}; }
};

INSTANTIATE_TYPED_TEST_SUITE_P(Planar, ExtremeInput, ExtremeCases<PlanarWorld>, ExtremeCaseName);

}  // namespace
}  // namespace sextant::test
