// Visual-inertial SLAM on SE(3) (seed 004) with the simulated stereo car (sim/stereo_vi.hpp):
// consistency over seeds, the first-estimate Jacobians that make it possible, and observations the
// stereo model cannot use (behind the camera, disparity <= 0) skipped one by one in every back-end.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/core/landmark_pool_policy.hpp"
#include "sextant/eval/dead_reckoning.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/eval/monte_carlo.hpp"
#include "sextant/eval/pooled_run.hpp"
#include "sextant/sim/stereo_vi.hpp"

namespace sextant {
namespace {

using Ekf = EkfSlam<ImuVelocitySe3, StereoPixelsSe3>;
constexpr PoolLimits kPool{.max_landmarks = 300, .max_new_per_step = 30};

struct RunScores {
  double anees = 0.0, rmse = 0.0, dead_reckoning_rmse = 0.0;
};

/// EKF-SLAM with first-estimate Jacobians through the landmark pool; pose NEES (6 dof, world-frame
/// error) and position RMSE against the truth, and dead reckoning's RMSE on the same data.
RunScores ekf_run(std::uint64_t seed) {
  const auto data = sim::simulate_stereo_vi({.seed = seed});
  Ekf ekf(data.motion, data.sensor, data.prior, {.first_estimate_jacobians = true});
  const auto run = eval::run_through_pool(ekf, data.steps, kPool, 1, [](std::size_t, const auto&) {});
  RunScores out;
  const auto dead_reckoning = eval::dead_reckoning(data.motion, data.prior.mean, data.steps);
  const double steps = static_cast<double>(data.steps.size());
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    const auto& truth = data.true_poses[k + 1];
    const auto& estimate = run.poses[k].estimate;
    const se3::Vector6d e = Se3Space::minus(truth, estimate.mean);
    out.anees += e.dot(estimate.cov.ldlt().solve(e)) / steps;
    out.rmse += (se3::translation(estimate.mean) - se3::translation(truth)).squaredNorm() / steps;
    out.dead_reckoning_rmse += (se3::translation(dead_reckoning[k]) - se3::translation(truth)).squaredNorm() / steps;
  }
  out.rmse = std::sqrt(out.rmse);
  out.dead_reckoning_rmse = std::sqrt(out.dead_reckoning_rmse);
  return out;
}

TEST(StereoVi, FastSlamNewLandmarkThresholdIsTheQuantileForFourPixelCoordinates) {
  // The default is the chi-square quantile at 0.9999 with as many degrees of freedom as the
  // measurement has (fast_slam_test checks the ship's 2): stereo pixels have 4.
  const Gaussian<Eigen::Matrix4d, 6> pose{Eigen::Matrix4d::Identity(), se3::Matrix6d::Identity()};
  const FastSlam<ImuVelocitySe3, StereoPixelsSe3> stereo(ImuVelocitySe3{}, StereoPixelsSe3{}, pose);
  EXPECT_DOUBLE_EQ(stereo.options().new_landmark_nis, chi_square_quantile(4, 0.9999));
  EXPECT_NEAR(chi_square_quantile(4, 0.9999), 23.51, 0.005);
}

TEST(StereoVi, EkfBeatsDeadReckoningAndItsPoseAneesOverTwentySeedsLiesInsideItsInterval) {
  const auto runs = eval::monte_carlo(20, 1, ekf_run);
  std::vector<double> anees;
  double rmse = 0.0, dead_reckoning_rmse = 0.0;
  int better = 0;
  for (const auto& r : runs) {
    anees.push_back(r.anees);
    rmse += r.rmse / static_cast<double>(runs.size());
    dead_reckoning_rmse += r.dead_reckoning_rmse / static_cast<double>(runs.size());
    better += r.rmse < r.dead_reckoning_rmse;
  }
  const auto interval = eval::time_averaged_anees_interval(6, anees, 0.95);
  const double value = eval::mean(anees);
  std::printf("pose ANEES %.3f in [%.3f, %.3f]; position RMSE %.3f m against dead reckoning's %.3f m (better in %d "
              "of %zu runs)\n",
              value, interval.lower, interval.upper, rmse, dead_reckoning_rmse, better, runs.size());
  EXPECT_GT(value, interval.lower);
  EXPECT_LT(value, interval.upper);
  EXPECT_LT(rmse, dead_reckoning_rmse);
}

/// The rotation block of a world-frame pose covariance, as its smallest eigenvalue relative to a
/// reference variance.
double smallest_rotation_variance(const se3::Matrix6d& cov) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov.bottomRightCorner<3, 3>()).eigenvalues().minCoeff();
}

TEST(StereoVi, FirstEstimateJacobiansKeepTheGlobalRotationUnobservable) {
  // Velocity and pixels 100x more precise than the default: what remains uncertain is the start's
  // orientation (the prior, 1e-3 rad), which no velocity or landmark can reveal. A filter that does
  // not gain spurious information keeps the pose's world-frame rotation variance at or above the
  // prior's (motion noise only adds); 1% margin for the retraction's second-order terms.
  sim::StereoViOptions options{.seed = 7, .num_steps = 120};
  options.velocity_sigma *= 0.01;
  options.pixel_sigma *= 0.01;
  const auto data = sim::simulate_stereo_vi(options);
  const double prior_variance = options.prior_sigma_angle * options.prior_sigma_angle;
  Ekf first_estimates(data.motion, data.sensor, data.prior, {.first_estimate_jacobians = true});
  Ekf textbook(data.motion, data.sensor, data.prior);
  eval::run_through_pool(first_estimates, data.steps, kPool, 0, [](std::size_t, const auto&) {});
  eval::run_through_pool(textbook, data.steps, kPool, 0, [](std::size_t, const auto&) {});
  ASSERT_GT(first_estimates.num_landmarks(), 50u);
  const double kept = smallest_rotation_variance(first_estimates.pose().cov) / prior_variance;
  const double textbook_kept = smallest_rotation_variance(textbook.pose().cov) / prior_variance;
  std::printf("smallest rotation variance / prior's: first estimates %.3f, textbook EKF %.3f\n", kept, textbook_kept);
  EXPECT_GT(kept, 0.99);
  // The textbook filter is the defect this option removes: it violates the same bound, claiming to
  // know the unobservable orientation better than its prior (measured: 0.54 of it after 120 steps).
  EXPECT_LT(textbook_kept, 0.99);
}

/// One landmark 10 m ahead, then a jump of 20 m forward (it is now behind the camera), then an
/// update with: that landmark, a new one with disparity -5 px, a new one 10 m ahead.
struct BehindTheCamera {
  StereoPixelsSe3 camera;
  ImuVelocitySe3 imu;
  Gaussian<Eigen::Matrix4d, 6> prior{Eigen::Matrix4d::Identity(), 1e-4 * se3::Matrix6d::Identity()};
  Observation<Eigen::Vector4d> ahead, behind_now, negative_disparity, new_ahead;
  se3::Vector6d jump = (se3::Vector6d() << 200.0, 0, 0, 0, 0, 0).finished();  // 20 m in 0.1 s

  BehindTheCamera() {
    camera.calibration = {.fx = 718.9, .fy = 718.9, .cx = 607.2, .cy = 185.2, .baseline = 0.54};
    Eigen::Matrix4d imu_T_cam = Eigen::Matrix4d::Identity();
    imu_T_cam.topLeftCorner<3, 3>() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    camera.cam_T_imu = se3::inverse(imu_T_cam);
    imu.W = 1e-4 * se3::Matrix6d::Identity();
    ahead = {1, camera.predict(Eigen::Matrix4d::Identity(), Eigen::Vector3d(10.0, 1.0, 0.5)).z};
    behind_now = {1, ahead.z};
    negative_disparity = {2, Eigen::Vector4d(600.0, 180.0, 605.0, 180.0)};
    Eigen::Matrix4d after_jump = Eigen::Matrix4d::Identity();
    after_jump(0, 3) = 20.0;
    new_ahead = {3, camera.predict(after_jump, Eigen::Vector3d(30.0, -1.0, 0.5)).z};
  }
  std::vector<Observation<Eigen::Vector4d>> second() const { return {behind_now, negative_disparity, new_ahead}; }
};

template <class Backend>
void expect_unusable_skipped(Backend& backend, const BehindTheCamera& scene) {
  backend.predict(se3::Vector6d::Zero(), 0.1);
  ASSERT_EQ(backend.update(std::vector{scene.ahead}).initialized, 1u);
  backend.predict(scene.jump, 0.1);
  const UpdateResult result = backend.update(scene.second());
  std::vector<LandmarkId> unusable = result.unusable;
  std::sort(unusable.begin(), unusable.end());
  EXPECT_EQ(unusable, (std::vector<LandmarkId>{1, 2}));
  EXPECT_EQ(result.corrected, 0u);
  EXPECT_EQ(result.initialized, 1u);
  EXPECT_TRUE(backend.has_landmark(1));
  EXPECT_FALSE(backend.has_landmark(2));
  EXPECT_TRUE(backend.has_landmark(3));
  EXPECT_TRUE(backend.pose().mean.allFinite());
}

TEST(StereoVi, EveryBackendSkipsObservationsTheStereoModelCannotUse) {
  const BehindTheCamera scene;
  {
    Ekf ekf(scene.imu, scene.camera, scene.prior);
    expect_unusable_skipped(ekf, scene);
  }
  {
    Ekf ekf(scene.imu, scene.camera, scene.prior, {.first_estimate_jacobians = true});
    expect_unusable_skipped(ekf, scene);
  }
  {
    SeifSlam<ImuVelocitySe3, StereoPixelsSe3> seif(scene.imu, scene.camera, scene.prior);
    expect_unusable_skipped(seif, scene);
  }
  {
    GraphSlam<ImuVelocitySe3, StereoPixelsSe3> graph(scene.imu, scene.camera, scene.prior);
    expect_unusable_skipped(graph, scene);
    EXPECT_NO_THROW(graph.optimize());
  }
  {
    FastSlam<ImuVelocitySe3, StereoPixelsSe3> fast(scene.imu, scene.camera, scene.prior, {.particles = 20});
    expect_unusable_skipped(fast, scene);
  }
}

TEST(StereoVi, ThePoolDoesNotCountAnUnusableNewLandmarkAsAdded) {
  const BehindTheCamera scene;
  Ekf ekf(scene.imu, scene.camera, scene.prior);
  LandmarkPoolPolicy policy({.max_landmarks = 10, .max_new_per_step = 10});
  const std::vector first{scene.ahead, scene.negative_disparity};
  const auto result = update_through_pool(ekf, policy, std::span<const Observation<Eigen::Vector4d>>(first), 0);
  EXPECT_EQ(result.unusable, std::vector<LandmarkId>{2});
  EXPECT_EQ(policy.size(), 1u);
  EXPECT_FALSE(policy.contains(2));
  ASSERT_EQ(policy.history().size(), 1u);
  EXPECT_EQ(policy.history()[0].added, 1u);
  EXPECT_EQ(policy.history()[0].unusable, 1u);
  EXPECT_EQ(policy.history()[0].in_pool, ekf.num_landmarks());
}

/// EkfOptions::tangent_reset: the correction is the same; the pose covariance after it is the one
/// without the reset read in the tangent at the corrected pose, G P G^T with G = plus_jacobian.
TEST(StereoVi, TheTangentResetReadsTheCovarianceAtTheCorrectedPose) {
  const auto data = sim::simulate_stereo_vi({.seed = 3});
  Ekf plain(data.motion, data.sensor, data.prior, {});
  Ekf reset(data.motion, data.sensor, data.prior, {.tangent_reset = true});
  for (const auto& step : data.steps) {
    plain.predict(step.control, step.dt);
    reset.predict(step.control, step.dt);
    const Eigen::Matrix4d before = plain.pose().mean;
    const auto result = plain.update(step.observations);
    reset.update(step.observations);
    if (result.corrected == 0) continue;
    const Eigen::Matrix4d after = plain.pose().mean;
    EXPECT_EQ(after, reset.pose().mean);
    const se3::Matrix6d G = Se3Space::plus_jacobian(before, Se3Space::minus(after, before));
    const se3::Matrix6d expected = G * plain.pose().cov * G.transpose();
    EXPECT_GT((G - se3::Matrix6d::Identity()).norm(), 0.0);
    EXPECT_LT((reset.pose().cov - expected).norm(), 1e-12 * expected.norm());
    return;
  }
  FAIL() << "no step corrected a known landmark";
}

}  // namespace
}  // namespace sextant
