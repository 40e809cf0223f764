#include "sextant/sim/ship_2d.hpp"

#include <gtest/gtest.h>

#include <set>

namespace sextant::sim {
namespace {

TEST(Ship2D, SameSeedSameDataDifferentSeedDifferentNoise) {
  Ship2DOptions options;
  const auto a = simulate_ship_2d(options), b = simulate_ship_2d(options);
  ASSERT_EQ(a.steps.size(), 1390u);
  EXPECT_EQ(a.true_poses.size(), 1391u);
  EXPECT_EQ(a.steps[500].control, b.steps[500].control);
  EXPECT_EQ(a.true_poses.back(), b.true_poses.back());
  options.seed = 2;
  const auto c = simulate_ship_2d(options);
  EXPECT_NE(a.steps[500].control, c.steps[500].control);
}

TEST(Ship2D, HasAnOpenSeaLegAndALoopClosureNearTheEnd) {
  const auto data = simulate_ship_2d({});
  EXPECT_GT(data.true_landmarks.size(), 50u);
  // The open-sea leg: a long run of steps without any beacon in range.
  int longest_blind = 0, blind = 0, blind_end = 0;
  for (int k = 0; k < static_cast<int>(data.steps.size()); ++k) {
    blind = data.steps[k].observations.empty() ? blind + 1 : 0;
    if (blind > longest_blind) longest_blind = blind, blind_end = k;
  }
  EXPECT_GT(longest_blind, 200);
  EXPECT_GT(blind_end, 800);
  EXPECT_LT(blind_end, 950);
  // Loop closure: beacons first seen in the first 50 steps are seen again after step 1150.
  std::set<LandmarkId> early;
  for (int k = 0; k < 50; ++k)
    for (const auto& obs : data.steps[k].observations) early.insert(obs.landmark_id);
  bool revisited = false;
  for (std::size_t k = 1150; k < data.steps.size(); ++k)
    for (const auto& obs : data.steps[k].observations) revisited |= early.contains(obs.landmark_id);
  EXPECT_TRUE(revisited);
}

TEST(Ship2D, MeasurementsAreBeaconOffsetsWithTheConfiguredNoise) {
  const auto data = simulate_ship_2d({});
  double sum_sq = 0.0;
  int count = 0;
  for (std::size_t k = 0; k < data.steps.size(); ++k)
    for (const auto& obs : data.steps[k].observations) {
      const Eigen::Vector2d error = obs.z - (data.true_landmarks.at(obs.landmark_id) - data.true_poses[k + 1]);
      sum_sq += error.squaredNorm();
      count += 2;
    }
  EXPECT_NEAR(std::sqrt(sum_sq / count), Ship2DOptions{}.sigma_beacon, 0.05);
}

}  // namespace
}  // namespace sextant::sim
