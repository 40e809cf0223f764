#include "sextant/models/stereo_imu_se3.hpp"

#include <gtest/gtest.h>

#include <random>
#include <type_traits>

#include "sextant/core/concepts.hpp"
#include "sextant/testing/model_checks.hpp"

namespace sextant {
namespace {

using se3::Vector6d;

/// KITTI-like rectified stereo: 0.54 m baseline, 718 px focal length, IMU x forward, y left, z up,
/// camera z forward, x right, y down, mounted 1 m forward and 0.5 m up.
template <Se3Perturbation P = Se3Perturbation::world>
StereoPixelsSe3Of<P> kitti_like_camera() {
  StereoPixelsSe3Of<P> camera;
  camera.calibration = {.fx = 718.9, .fy = 718.9, .cx = 607.2, .cy = 185.2, .baseline = 0.54};
  Eigen::Matrix3d R_cam_imu;  // rows: camera axes in IMU coordinates
  R_cam_imu << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  camera.cam_T_imu = se3::inverse(se3::make(R_cam_imu.transpose(), Eigen::Vector3d(1.0, 0.0, 0.5)));
  camera.pixel_sigma = 1.5;
  return camera;
}

struct RandomScene {
  std::mt19937_64 rng;
  std::normal_distribution<double> n{0.0, 1.0};
  explicit RandomScene(std::uint64_t seed) : rng(seed) {}
  Vector6d tangent(double scale_t, double scale_r) {
    Vector6d xi;
    xi << scale_t * n(rng), scale_t * n(rng), scale_t * n(rng), scale_r * n(rng), scale_r * n(rng), scale_r * n(rng);
    return xi;
  }
  Eigen::Matrix4d pose() { return se3::exp(tangent(20.0, 1.0)); }
  /// A point 3-40 m ahead of the camera of `camera` at pose T, within +-0.5 of the optical axis.
  template <class Camera>
  Eigen::Vector3d landmark_in_view(const Eigen::Matrix4d& T, const Camera& camera) {
    std::uniform_real_distribution<double> depth(3.0, 40.0), lateral(-0.5, 0.5);
    const double d = depth(rng);
    const Eigen::Vector4d q(lateral(rng) * d, lateral(rng) * d, d, 1.0);
    return (T * se3::inverse(camera.cam_T_imu) * q).template head<3>();
  }
};

/// Both perturbations of the pose (core/se3_space.hpp) give the same models in other coordinates;
/// every check runs for each.
template <class Perturbation>
class StereoImuSe3Perturbations : public ::testing::Test {
 public:
  static constexpr Se3Perturbation perturbation = Perturbation::value;
  using Imu = ImuVelocitySe3Of<perturbation>;
  using Camera = StereoPixelsSe3Of<perturbation>;
  using Space = Se3SpaceOf<perturbation>;
};
using Perturbations = ::testing::Types<std::integral_constant<Se3Perturbation, Se3Perturbation::world>,
                                       std::integral_constant<Se3Perturbation, Se3Perturbation::body>>;
TYPED_TEST_SUITE(StereoImuSe3Perturbations, Perturbations);

TYPED_TEST(StereoImuSe3Perturbations, ModelsFitTheConcepts) {
  using Imu = typename TestFixture::Imu;
  static_assert(MotionModel<Imu>);
  static_assert(HasBetweenFactor<Imu>);
  static_assert(MeasurementModelFor<typename TestFixture::Camera, Imu>);
}

TYPED_TEST(StereoImuSe3Perturbations, MotionJacobiansMatchCentralDifferencesAtRandomStates) {
  RandomScene scene(1);
  typename TestFixture::Imu imu;
  imu.W.diagonal() << 0.25, 0.25, 0.25, 0.0025, 0.0025, 0.0025;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Matrix4d T = scene.pose();
    const Vector6d u = scene.tangent(5.0, 0.3);
    const double dt = 0.1 * (1 + i % 3);
    EXPECT_TRUE(testing::check_motion_jacobians(imu, T, u, dt)) << testing::check_motion_jacobians(imu, T, u, dt).report;
    const Eigen::Matrix4d to = TestFixture::Space::plus(imu.predict(T, u, dt).x, scene.tangent(0.3, 0.05));
    const auto between = testing::check_between_jacobians(imu, T, to, u, dt);
    EXPECT_TRUE(between) << between.report;
  }
}

TYPED_TEST(StereoImuSe3Perturbations, ProcessNoiseIsTheVelocityNoisePropagatedThroughTheMotion) {
  // R = V W V^T with V = d minus(T exp(dt (u + w)^), T exp(dt u^)) / dw, V by central differences.
  RandomScene scene(2);
  typename TestFixture::Imu imu;
  imu.W.diagonal() << 0.25, 0.16, 0.09, 0.0025, 0.0016, 0.0036;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Matrix4d T = scene.pose();
    const Vector6d u = scene.tangent(5.0, 0.5);
    const double dt = 0.1;
    const Eigen::Matrix4d mean = T * se3::exp(dt * u);
    se3::Matrix6d V;
    for (int k = 0; k < 6; ++k) {
      Vector6d h = Vector6d::Zero();
      h(k) = 1e-6;
      V.col(k) = (TestFixture::Space::minus(T * se3::exp(dt * (u + h)), mean) - TestFixture::Space::minus(T * se3::exp(dt * (u - h)), mean)) / 2e-6;
    }
    EXPECT_TRUE(imu.predict(T, u, dt).R.isApprox(V * imu.W * V.transpose(), 1e-6));
  }
}

TYPED_TEST(StereoImuSe3Perturbations, MeasurementJacobiansAndTriangulationMatchAtRandomStates) {
  RandomScene scene(3);
  const auto camera = kitti_like_camera<TestFixture::perturbation>();
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix4d T = scene.pose();
    const Eigen::Vector3d m = scene.landmark_in_view(T, camera);
    const auto check = testing::check_measurement_jacobians<typename TestFixture::Imu>(camera, T, m);
    EXPECT_TRUE(check) << check.report;
  }
}

TEST(StereoImuSe3, PixelsAreThePinholeProjectionInBothCameras) {
  // Seed eq. 7 by hand: uL = fx x/z + cx, vL = vR = fy y/z + cy, uR = fx (x - b)/z + cx.
  auto camera = kitti_like_camera();
  camera.cam_T_imu.setIdentity();
  const Eigen::Vector3d p(2.0, -1.0, 10.0);
  const auto z = camera.predict(Eigen::Matrix4d::Identity(), p).z;
  const auto& c = camera.calibration;
  EXPECT_NEAR(z(0), c.fx * 0.2 + c.cx, 1e-12);
  EXPECT_NEAR(z(1), c.fy * -0.1 + c.cy, 1e-12);
  EXPECT_NEAR(z(2), c.fx * (2.0 - c.baseline) / 10.0 + c.cx, 1e-12);
  EXPECT_EQ(z(3), z(1));
  EXPECT_NEAR(z(0) - z(2), c.fx * c.baseline / 10.0, 1e-12);  // disparity
}

TEST(StereoImuSe3, PointsBehindOrTooNearTheCameraAndNonPositiveDisparitiesAreErrorsNotNaN) {
  auto camera = kitti_like_camera();
  const Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  // The camera looks along the IMU's +x from x = 1: a point at x = -5 is behind it, one at x = 1
  // has depth 0, one at x = 1.001 is in front but nearer than the baseline (the default near
  // plane), where its Jacobian (~fx x / depth^2) would be ~1e9 and swamp S in rounding.
  ASSERT_GT(camera.calibration.baseline, 0.01);
  for (const Eigen::Vector3d& m : {Eigen::Vector3d(-5.0, 0.0, 0.5), Eigen::Vector3d(1.0, 0.0, 0.5),
                                   Eigen::Vector3d(1.001, 3.0, 0.5)}) {
    try {
      (void)camera.predict(T, m);
      ADD_FAILURE() << "a point at depth " << m.x() - 1.0 << " m was predicted";
    } catch (const unobservable_error& e) {
      EXPECT_NE(std::string(e.what()).find("behind or too near the camera"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW((void)camera.predict(T, Eigen::Vector3d(1.0 + 1.01 * camera.calibration.baseline, 0.0, 0.5)));
  camera.min_depth = 0.01;  // a near plane set by hand
  EXPECT_NO_THROW((void)camera.predict(T, Eigen::Vector3d(1.02, 0.0, 0.5)));
  EXPECT_THROW((void)camera.predict(T, Eigen::Vector3d(1.005, 0.0, 0.5)), unobservable_error);
  // Outside the field of view: 10 m ahead, 25 m to the side (bearing tangent 2.5 > 2).
  try {
    (void)camera.predict(T, Eigen::Vector3d(11.0, -25.0, 0.5));
    ADD_FAILURE() << "a point 68 degrees off the optical axis was predicted";
  } catch (const unobservable_error& e) {
    EXPECT_NE(std::string(e.what()).find("outside the field of view"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW((void)camera.predict(T, Eigen::Vector3d(11.0, -15.0, 0.5)));  // tangent 1.5
  for (const double uR : {600.0, 610.0}) {  // disparity 0 and -10 px
    try {
      (void)camera.initialize(T, Eigen::Vector4d(600.0, 180.0, uR, 180.0));
      ADD_FAILURE() << "disparity " << 600.0 - uR << " was triangulated";
    } catch (const unobservable_error& e) {
      EXPECT_NE(std::string(e.what()).find("disparity"), std::string::npos) << e.what();
    }
  }
}

TEST(StereoImuSe3, TheWorldPerturbationHasAnEstimateFreeMotionJacobian) {
  // exp(d^) T exp(tau u^): the world-frame error is carried over unchanged (G = I), which is what
  // lets first-estimate Jacobians keep the global pose unobservable (backends/ekf_slam.hpp).
  RandomScene scene(4);
  ImuVelocitySe3 imu;
  const auto prediction = imu.predict(scene.pose(), scene.tangent(5.0, 0.3), 0.1);
  EXPECT_TRUE(prediction.J_x_x.isIdentity(0.0));
}

TEST(StereoImuSe3, TriangulationBelowTheSmallestDisparityIsUnusableNotAnError) {
  auto camera = kitti_like_camera();
  camera.min_disparity = 30.0;
  const Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  EXPECT_NO_THROW((void)camera.initialize(T, Eigen::Vector4d(640.0, 180.0, 600.0, 180.0)));  // 40 px
  EXPECT_THROW((void)camera.initialize(T, Eigen::Vector4d(620.0, 180.0, 600.0, 180.0)), unobservable_error);  // 20 px
}

}  // namespace
}  // namespace sextant
