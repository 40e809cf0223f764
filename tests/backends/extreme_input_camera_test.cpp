// Extreme inputs (extreme_input_suite.hpp) on the thesis's 12D camera: EulerCamera12D, PointInCamera3D.
#include "backends/extreme_input_suite.hpp"
#include "sextant/models/euler_camera_12d.hpp"

namespace sextant::test {
namespace {

struct CameraWorld {
  static constexpr const char* kName = "camera";
  static EulerCamera12D motion(double sigma) {
    EulerCamera12D m;
    m.sigma_velocity *= sigma;
    m.sigma_rate *= sigma;
    return m;
  }
  static PointInCamera3D sensor(double sigma) {
    PointInCamera3D s;
    s.noise.pixel_sigma *= sigma;
    return s;
  }
  static EulerCamera12D::Control control(double, double) { return {}; }  // handheld: no control
  /// A point in front of the camera: distinct points for distinct j
  static Eigen::Vector3d measurement(int j, double scale) {
    return scale * Eigen::Vector3d(-0.1 + 0.0001 * j, 0.05 * std::sin(0.7 * j), 0.5 + 0.0002 * j);
  }
  static Gaussian<Vector12d, 12> prior() {
    Vector12d x = Vector12d::Zero();
    x(6) = 0.05;  // moving sideways at 5 cm/s
    return {x, 1e-6 * Eigen::Matrix<double, 12, 12>::Identity()};
  }
};

INSTANTIATE_TYPED_TEST_SUITE_P(Camera, ExtremeInput, ExtremeCases<CameraWorld>, ExtremeCaseName);

}  // namespace
}  // namespace sextant::test
