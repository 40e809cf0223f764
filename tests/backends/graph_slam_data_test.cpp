// GraphSLAM on real and benchmark data sets from ../shared/data; skipped when they are absent.
#include <gtest/gtest.h>

#include "sextant/backends/graph_slam.hpp"
#include "sextant/io/isam_reader.hpp"
#include "support/shared_data.hpp"

namespace sextant {
namespace {

using PlanarGraph = GraphSlam<Se2Odometry, PointInRobotFrame2D>;

PlanarGraph load(const io::PlanarDataset& data, GraphOptions options) {
  PointInRobotFrame2D sensor;
  sensor.Q = data.landmark_cov;
  PlanarGraph graph{Se2Odometry{}, sensor, {Eigen::Vector3d::Zero(), 1e-6 * Eigen::Matrix3d::Identity()}, options};
  graph.update(data.initial_observations);
  for (const auto& step : data.steps) {
    graph.predict(step.control, step.dt);
    graph.update(step.observations);
  }
  return graph;
}

TEST(GraphSlamData, CityTrees10000AgainstItsGroundTruth) {
  const auto path = test::shared_data("city_trees/cityTrees10000.txt");
  const auto truth_path = test::shared_data("city_trees/cityTrees10000_groundtruth.txt");
  SEXTANT_REQUIRE_DATA(path);
  SEXTANT_REQUIRE_DATA(truth_path);
  auto graph = load(io::read_isam_2d(path, io::IsamNoise::square_root_information), {});
  const auto summary = graph.optimize();
  EXPECT_TRUE(summary.converged);
  EXPECT_LE(summary.iterations, 10);
  const auto truth = io::ground_truth_from_noise_free(io::read_isam_2d(truth_path, io::IsamNoise::square_root_information));
  ASSERT_EQ(truth.poses.size(), graph.num_poses());
  // The bound comes from the noise model: the marginal covariances predict the mean squared error,
  // E|e_k|^2 = tr(Sigma_k). Errors along one trajectory are correlated, but even with only the 2
  // dof of one planar error, P(MSE > 9 E[MSE]) <= P(chi2_2 / 2 > 9) = e^-9: RMSE <= 3 sqrt(E[MSE]).
  const auto trajectory = graph.trajectory();
  const auto map = graph.map();
  double pose_sq = 0.0, landmark_sq = 0.0, pose_expected = 0.0, landmark_expected = 0.0;
  for (std::size_t k = 0; k < truth.poses.size(); ++k) {
    pose_sq += (trajectory[k].mean - truth.poses[k]).head<2>().squaredNorm();
    pose_expected += trajectory[k].cov.topLeftCorner<2, 2>().trace();
  }
  for (const auto& landmark : map) {
    landmark_sq += (landmark.mean - truth.landmarks.at(landmark.id)).squaredNorm();
    landmark_expected += landmark.cov.trace();
  }
  const double poses = static_cast<double>(truth.poses.size()), landmarks = static_cast<double>(map.size());
  const double pose_rmse = std::sqrt(pose_sq / poses), landmark_rmse = std::sqrt(landmark_sq / landmarks);
  const double pose_bound = 3.0 * std::sqrt(pose_expected / poses), landmark_bound = 3.0 * std::sqrt(landmark_expected / landmarks);
  std::printf("cityTrees10000: %d iterations, chi2 %.2f, pose RMSE %.4f m (bound %.4f), landmark RMSE %.4f m (bound %.4f)\n",
              summary.iterations, summary.cost.back(), pose_rmse, pose_bound, landmark_rmse, landmark_bound);
  EXPECT_LT(pose_rmse, pose_bound);
  EXPECT_LT(landmark_rmse, landmark_bound);
}

/// GraphSLAM on Victoria Park: whether it converged, and its chi2 over the degrees of freedom
/// (residuals minus unknowns); a consistent solution has it near 1.
std::pair<bool, double> victoria_park_chi2_per_dof(const io::PlanarDataset& data, GraphOptions options, const char* label) {
  auto graph = load(data, options);
  const auto summary = graph.optimize();
  std::size_t observations = data.initial_observations.size();
  for (const auto& step : data.steps) observations += step.observations.size();
  const double dof = 3.0 * data.steps.size() + 2.0 * observations - 3.0 * data.steps.size() - 2.0 * graph.num_landmarks();
  std::printf("Victoria Park, %s: %d iterations, chi2 %.1f for %.0f degrees of freedom, %zu landmarks\n", label,
              summary.iterations, summary.cost.back(), dof, graph.num_landmarks());
  return {summary.converged, summary.cost.back() / dof};
}

/// With a windowed initialization (200 steps, and sextant-run's default for iSAM files, [isam]
/// graph_window = 1000, with [graph]'s other defaults) chi2 per degree of freedom ends inside
/// [0.5, 1.5]; from dead reckoning (the peer) Gauss-Newton ends in a twisted minimum far above it.
TEST(GraphSlamData, VictoriaParkConvergesWithWindowedInitialization) {
  const auto path = test::shared_data("victoria_park/victoria_park.txt");
  SEXTANT_REQUIRE_DATA(path);
  const auto data = io::read_isam_2d(path, io::IsamNoise::covariance);
  for (const auto& [options, label] : {std::pair{GraphOptions{.max_iterations = 20, .window = 200, .window_iterations = 3}, "window 200"},
                                       std::pair{GraphOptions{.window = 1000}, "window 1000, as sextant-run"}}) {
    const auto [converged, chi2_per_dof] = victoria_park_chi2_per_dof(data, options, label);
    EXPECT_TRUE(converged) << label;
    EXPECT_GT(chi2_per_dof, 0.5) << label;
    EXPECT_LT(chi2_per_dof, 1.5) << label;
  }
  EXPECT_GT(victoria_park_chi2_per_dof(data, {}, "from dead reckoning").second, 1.5);
}

}  // namespace
}  // namespace sextant
