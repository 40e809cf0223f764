#include "sextant/sim/globe_camera.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <set>

#include "sextant/eval/metrics.hpp"

namespace sextant {
namespace {

TEST(GlobeCamera, IsDeterministicPerSeed) {
  const auto a = sim::simulate_globe_camera({.seed = 4, .num_steps = 30});
  const auto b = sim::simulate_globe_camera({.seed = 4, .num_steps = 30});
  const auto c = sim::simulate_globe_camera({.seed = 5, .num_steps = 30});
  ASSERT_EQ(a.steps.size(), 30u);
  EXPECT_EQ(a.true_poses.back(), b.true_poses.back());
  EXPECT_EQ(a.steps.back().observations.back().z, b.steps.back().observations.back().z);
  EXPECT_NE(a.true_poses.back(), c.true_poses.back());
}

TEST(GlobeCamera, ResponseJitterChangesWhichPointsAreDetectedButNotTheMotion) {
  const sim::GlobeCameraOptions steady{.seed = 3, .num_steps = 60, .num_points = 6000};
  sim::GlobeCameraOptions jittered = steady;
  jittered.response_jitter = 1.0;
  const auto a = sim::simulate_globe_camera(steady), b = sim::simulate_globe_camera(jittered);
  EXPECT_EQ(a.true_poses, b.true_poses) << "the jitter has its own random stream";
  EXPECT_EQ(a.true_landmarks, b.true_landmarks);
  const auto distinct_ids = [](const sim::GlobeCameraDataset& data) {
    std::set<LandmarkId> ids;
    for (const auto& step : data.steps)
      for (const auto& observation : step.observations) ids.insert(observation.landmark_id);
    return ids.size();
  };
  // Without jitter the strongest points repeat from frame to frame; with it the cut moves.
  EXPECT_GT(distinct_ids(b), 2 * distinct_ids(a));
  for (const auto& step : b.steps)
    EXPECT_EQ(step.observations.size(), static_cast<std::size_t>(jittered.max_features_per_frame));
}

TEST(GlobeCamera, CirclesTheGlobeLookingAtItAndClosesTheLoopNearStep420) {
  const sim::GlobeCameraOptions options;
  const auto data = sim::simulate_globe_camera(options);
  ASSERT_EQ(data.true_poses.size(), 501u);
  EXPECT_EQ(data.true_landmarks.size(), 3000u);
  double turned = 0.0, closest_after_half = 1e9;
  std::size_t closest_step = 0;
  for (std::size_t k = 1; k < data.true_poses.size(); ++k) {
    const Eigen::Vector3d p = data.true_poses[k].head<3>(), previous = data.true_poses[k - 1].head<3>();
    turned += std::atan2(previous.z() * p.x() - previous.x() * p.z(), previous.x() * p.x() + previous.z() * p.z());
    // The optical axis points at the globe: the centre is within 10 degrees of it.
    const Eigen::Vector3d axis = euler_yxz::rotation(data.true_poses[k].segment<3>(3)).col(2);
    EXPECT_GT(axis.dot(-p.normalized()), std::cos(10.0 * std::numbers::pi / 180.0)) << k;
    const double horizontal = std::hypot(p.x(), p.z());
    EXPECT_GT(horizontal, 0.3) << k;
    EXPECT_LT(horizontal, 0.6) << k;
    if (k > 250 && (p - data.true_poses[0].head<3>()).norm() < closest_after_half) {
      closest_after_half = (p - data.true_poses[0].head<3>()).norm();
      closest_step = k;
    }
  }
  EXPECT_GT(std::abs(turned), 2.0 * std::numbers::pi) << "the camera goes once around and on";
  EXPECT_NEAR(static_cast<double>(closest_step), 420.0, 30.0);
}

TEST(GlobeCamera, ObservesVisiblePointsWithTheStereoNoise) {
  const sim::GlobeCameraOptions options{.seed = 2, .num_steps = 200};
  const auto data = sim::simulate_globe_camera(options);
  double nis_sum = 0.0;
  std::size_t count = 0;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    const Vector12d& x = data.true_poses[k + 1];
    const Eigen::Matrix3d R = euler_yxz::rotation(x.segment<3>(3));
    ASSERT_EQ(data.steps[k].observations.size(), static_cast<std::size_t>(options.max_features_per_frame));
    for (const auto& observation : data.steps[k].observations) {
      const Eigen::Vector3d m = data.true_landmarks.at(observation.landmark_id);
      const Eigen::Vector3d q = R.transpose() * (m - x.head<3>());
      ASSERT_GT(q.z(), 0.0);
      ASSERT_GT(m.dot(x.head<3>() - m), 0.0) << "a point on the far hemisphere was observed";
      ASSERT_LT(std::abs(options.stereo.focal_px * q.x() / q.z()), 0.5 * options.image_width);
      const Eigen::Vector3d e = observation.z - q;
      nis_sum += e.dot(options.stereo.covariance(q).ldlt().solve(e));
      ++count;
    }
  }
  const auto interval = eval::anees_interval(3, static_cast<int>(count), 0.99);
  EXPECT_GT(nis_sum / count, interval.lower);
  EXPECT_LT(nis_sum / count, interval.upper);
}

}  // namespace
}  // namespace sextant
