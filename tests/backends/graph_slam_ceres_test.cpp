// Peer check: GraphSLAM and Ceres (independent autodiff cost functions, both sparse solvers) reach
// the same optimum from the same starting point.
#include <gtest/gtest.h>

#include "sextant/backends/graph_slam.hpp"
#include "sextant/eval/runner.hpp"
#include "sextant/io/isam_reader.hpp"
#include "sextant/sim/ship_2d.hpp"
#include "support/ceres_problems.hpp"
#include "support/shared_data.hpp"

namespace sextant {
namespace {

const GraphOptions kTight{.max_iterations = 50, .step_tolerance = 1e-12, .relative_cost_tolerance = 0.0};

/// Copies GraphSLAM's starting point into the Ceres parameters.
template <int X, class Graph>
void start_from(test::CeresGraph<X>& ceres_graph, const Graph& graph) {
  for (const auto& pose : graph.pose_means()) ceres_graph.poses.push_back(pose);
  for (const auto& landmark : graph.map()) ceres_graph.landmarks[landmark.id] = landmark.mean;
}

template <int X, class Graph>
double largest_difference(const test::CeresGraph<X>& ceres_graph, const Graph& graph) {
  double worst = 0.0;
  for (std::size_t k = 0; k < graph.num_poses(); ++k) {
    Eigen::Matrix<double, X, 1> d = ceres_graph.poses[k] - graph.pose_means()[k];
    if constexpr (X == 3) d(2) = wrap_angle(d(2));
    worst = std::max(worst, d.cwiseAbs().maxCoeff());
  }
  for (LandmarkId id : graph.landmark_ids())
    worst = std::max(worst, (ceres_graph.landmarks.at(id) - graph.landmark(id).mean).cwiseAbs().maxCoeff());
  return worst;
}

class CeresPeer : public ::testing::TestWithParam<ceres::LinearSolverType> {};

TEST_P(CeresPeer, ShipProblemSameOptimum) {
  const auto data = sim::simulate_ship_2d({.seed = 4, .num_steps = 400});
  GraphSlam<BeaconShip2D, BeaconOffset2D> graph{data.motion, data.sensor, data.prior, kTight};
  eval::run(graph, data.steps);
  test::CeresGraph<2> peer;
  start_from(peer, graph);
  std::vector<Eigen::Matrix2d> motion_cov;
  std::vector<Eigen::Vector2d> displacement;
  for (const auto& step : data.steps) {
    const auto p = data.motion.predict(Eigen::Vector2d::Zero(), step.control, step.dt);
    motion_cov.push_back(p.R);
    displacement.push_back(p.x);
  }
  test::build_ship(peer, data.prior.mean, data.prior.cov, data.steps, motion_cov, displacement, data.sensor.noise());
  const auto summary = peer.solve(GetParam());
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  graph.optimize();
  EXPECT_LT(largest_difference(peer, graph), 1e-6);
  EXPECT_NEAR(2.0 * summary.final_cost, graph.cost(), 1e-6 * graph.cost());  // Ceres reports chi2 / 2
}

TEST_P(CeresPeer, CityTreesSameOptimum) {
  const auto path = test::shared_data("city_trees/cityTrees10000.txt");
  SEXTANT_REQUIRE_DATA(path);
  auto data = io::read_isam_2d(path, io::IsamNoise::square_root_information);
  data.steps.resize(2000);  // the first 2000 poses keep the test quick
  PointInRobotFrame2D sensor;
  sensor.Q = data.landmark_cov;
  const Eigen::Matrix3d prior_cov = 1e-6 * Eigen::Matrix3d::Identity();
  GraphSlam<Se2Odometry, PointInRobotFrame2D> graph{Se2Odometry{}, sensor, {Eigen::Vector3d::Zero(), prior_cov}, kTight};
  graph.update(data.initial_observations);
  for (const auto& step : data.steps) {
    graph.predict(step.control, step.dt);
    graph.update(step.observations);
  }
  test::CeresGraph<3> peer;
  start_from(peer, graph);
  test::build_planar(peer, prior_cov, data.initial_observations, data.steps, data.landmark_cov);
  const auto summary = peer.solve(GetParam());
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  graph.optimize();
  EXPECT_LT(largest_difference(peer, graph), 1e-6) << summary.FullReport();
  EXPECT_NEAR(2.0 * summary.final_cost, graph.cost(), 1e-6 * graph.cost());
}

INSTANTIATE_TEST_SUITE_P(BothSparseSolvers, CeresPeer,
                         ::testing::Values(ceres::SPARSE_SCHUR, ceres::SPARSE_NORMAL_CHOLESKY),
                         [](const auto& info) { return std::string(ceres::LinearSolverTypeToString(info.param)); });

}  // namespace
}  // namespace sextant
