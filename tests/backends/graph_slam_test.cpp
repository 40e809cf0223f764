#include "sextant/backends/graph_slam.hpp"

#include <gtest/gtest.h>

#include <map>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/eval/runner.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/sim/ordered_draws.hpp"
#include "sextant/sim/ship_2d.hpp"
#include "support/batch_least_squares.hpp"
#include "support/nees_bound.hpp"

namespace sextant {
namespace {

using Graph = GraphSlam<BeaconShip2D, BeaconOffset2D>;
static_assert(SlamBackend<Graph>);

const auto& kMotion = test::kLinearMotion;
const auto& kSensor = test::kLinearSensor;
const auto& kPrior = test::kLinearPrior;

class GraphLinear : public ::testing::TestWithParam<GraphSolver> {};

TEST_P(GraphLinear, OneSolveEqualsExactBatchLeastSquaresAndEkfMarginals) {
  const auto steps = test::random_linear_steps(60, 6, 7);
  const auto batch = test::solve_linear_ship_problem(kMotion, kSensor, kPrior, steps);
  Graph graph{kMotion, kSensor, kPrior, {.max_iterations = 1, .solver = GetParam()}};
  eval::run(graph, steps);
  const auto summary = graph.optimize();
  EXPECT_EQ(summary.iterations, 1);
  const auto trajectory = graph.trajectory();
  ASSERT_EQ(trajectory.size(), steps.size() + 1);
  double worst = 0.0;
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    worst = std::max(worst, (trajectory[k].mean - batch.mean.segment<2>(2 * k)).cwiseAbs().maxCoeff());
    worst = std::max(worst, (trajectory[k].cov - batch.covariance.block(2 * k, 2 * k, 2, 2)).cwiseAbs().maxCoeff());
  }
  EkfSlam<BeaconShip2D, BeaconOffset2D> ekf{kMotion, kSensor, kPrior};
  eval::run(ekf, steps);
  for (const auto& [id, offset] : batch.landmark_offset) {
    const auto landmark = graph.landmark(id);
    worst = std::max(worst, (landmark.mean - batch.mean.segment<2>(offset)).cwiseAbs().maxCoeff());
    worst = std::max(worst, (landmark.cov - batch.covariance.block(offset, offset, 2, 2)).cwiseAbs().maxCoeff());
    // Landmarks are static: EKF's final landmark marginals are the full posterior's.
    worst = std::max(worst, (landmark.cov - ekf.landmark(id).cov).cwiseAbs().maxCoeff());
    worst = std::max(worst, (landmark.mean - ekf.landmark(id).mean).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(BothSolvers, GraphLinear, ::testing::Values(GraphSolver::landmark_schur, GraphSolver::full));

TEST(GraphSlam, ShipRunConvergesWithinTenIterationsAndBeatsEkf) {
  const auto data = sim::simulate_ship_2d({.seed = 4});
  Graph graph{data.motion, data.sensor, data.prior};
  eval::run(graph, data.steps);
  const auto summary = graph.optimize();
  EXPECT_TRUE(summary.converged);
  EXPECT_LE(summary.iterations, 10);
  EXPECT_LT(summary.cost.back(), summary.cost.front());
  double graph_error = 0.0, ekf_error = 0.0;
  EkfSlam<BeaconShip2D, BeaconOffset2D> ekf{data.motion, data.sensor, data.prior};
  const auto record = eval::run(ekf, data.steps);
  for (std::size_t k = 1; k < data.true_poses.size(); ++k) {
    graph_error += (graph.pose_means()[k] - data.true_poses[k]).norm();
    ekf_error += (record.steps[k - 1].pose.mean - data.true_poses[k]).norm();
  }
  EXPECT_LT(graph_error, ekf_error);  // smoothing uses the future too
}

/// A robot driving a circle of radius 8 among twelve landmarks on a circle of radius 10, seeing those
/// within 6 m ahead: noisy odometry and point measurements in its frame, and the true poses.
struct Se2Circle {
  std::vector<Step<OdometryIncrement2D, Eigen::Vector2d>> steps;
  std::vector<Eigen::Vector3d> true_poses;
  PointInRobotFrame2D sensor;
};

Se2Circle se2_circle(int num_steps) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit(0.0, 1.0);
  const Eigen::Matrix3d odometry_cov = Eigen::Vector3d(0.01, 0.01, 0.004).asDiagonal();
  PointInRobotFrame2D sensor;
  sensor.Q = 0.01 * Eigen::Matrix2d::Identity();
  std::vector<Eigen::Vector2d> landmarks;
  for (int j = 0; j < 12; ++j) landmarks.emplace_back(10.0 * std::cos(j * 0.52), 10.0 * std::sin(j * 0.52));
  Eigen::Vector3d truth(8.0, 0.0, std::numbers::pi / 2);
  std::vector<Step<OdometryIncrement2D, Eigen::Vector2d>> steps;
  std::vector<Eigen::Vector3d> true_poses{truth};
  for (int k = 0; k < num_steps; ++k) {
    const Eigen::Vector3d delta(0.5, 0.0, 0.0625);
    truth = Se2Odometry{}.predict(truth, {delta, odometry_cov}, 1.0).x;
    true_poses.push_back(truth);
    Step<OdometryIncrement2D, Eigen::Vector2d> step{
        {delta + Eigen::Vector3d(0.1, 0.1, 0.063).cwiseProduct(sim::ordered_draws<3>(unit, rng)), odometry_cov}, 1.0, {}};
    for (std::size_t j = 0; j < landmarks.size(); ++j) {
      const Eigen::Vector2d z = sensor.predict(truth, landmarks[j]).z;
      if (z.x() > 0.0 && z.norm() < 6.0) step.observations.push_back({j, z + 0.1 * sim::ordered_draws<2>(unit, rng)});
    }
    steps.push_back(step);
  }
  return {std::move(steps), std::move(true_poses), sensor};
}

/// A planar robot with odometry and landmarks in its frame: nonlinear, needs relinearization.
TEST(GraphSlam, Se2ProblemConvergesAndWindowedInitializationAgrees) {
  const auto [steps, true_poses, sensor] = se2_circle(150);
  const Gaussian<Eigen::Vector3d, 3> prior{true_poses[0], 1e-6 * Eigen::Matrix3d::Identity()};
  // Converge on the step alone, to 1e-10, so that two runs can be compared to 1e-6.
  const GraphOptions tight{.max_iterations = 30, .step_tolerance = 1e-10, .relative_cost_tolerance = 0.0};
  GraphOptions tight_windowed = tight;
  tight_windowed.window = 30;
  tight_windowed.window_iterations = 3;
  GraphSlam<Se2Odometry, PointInRobotFrame2D> plain{Se2Odometry{}, sensor, prior, tight};
  GraphSlam<Se2Odometry, PointInRobotFrame2D> windowed{Se2Odometry{}, sensor, prior, tight_windowed};
  eval::run(plain, steps);
  eval::run(windowed, steps);
  const double initial_cost = plain.cost();
  const auto summary = plain.optimize();
  const auto windowed_summary = windowed.optimize();
  EXPECT_TRUE(summary.converged);
  EXPECT_TRUE(windowed_summary.converged);
  EXPECT_LT(summary.cost.back(), 0.01 * initial_cost);
  EXPECT_GT(summary.iterations, 2);  // nonlinear: relinearization was needed
  // With the default stopping rule and exact Jacobians (the between factor), ten iterations suffice.
  GraphSlam<Se2Odometry, PointInRobotFrame2D> by_default{Se2Odometry{}, sensor, prior};
  eval::run(by_default, steps);
  const auto default_summary = by_default.optimize();
  EXPECT_TRUE(default_summary.converged);
  EXPECT_LE(default_summary.iterations, 10);
  double worst = 0.0, worst_nees = 0.0;
  const auto trajectory = plain.trajectory();
  for (std::size_t k = 0; k < true_poses.size(); ++k) {
    worst = std::max(worst, Se2Space::minus(plain.pose_means()[k], windowed.pose_means()[k]).cwiseAbs().maxCoeff());
    const Eigen::Vector3d e = Se2Space::minus(trajectory[k].mean, true_poses[k]);
    worst_nees = std::max(worst_nees, eval::nees(e, trajectory[k].cov));
  }
  EXPECT_LT(worst, 1e-6);  // same optimum
  // The optimum is as far from the truth as its own marginals say: each pose's NEES within the
  // chi-square bound for 3 dof, Bonferroni over the poses (errors along a path are correlated, which
  // makes this conservative).
  std::printf("largest pose NEES %.2f, bound %.2f\n", worst_nees, test::nees_bound(3, true_poses.size()));
  EXPECT_LT(worst_nees, test::nees_bound(3, true_poses.size()));
}

/// Headings wrong by up to 5 rad: a start from which Gauss-Newton does not descend monotonically.
std::vector<Eigen::Vector3d> far_headings(std::vector<Eigen::Vector3d> poses) {
  for (std::size_t k = 0; k < poses.size(); ++k) poses[k].z() += 5.0 * std::sin(0.1 * static_cast<double>(k));
  return poses;
}

/// Plain Gauss-Newton (damp_after_rise off) from a far start: the estimate optimize() keeps is its best
/// iterate's, not the last one's, and Levenberg-Marquardt from the same start never records a rise.
TEST(GraphSlam, GaussNewtonKeepsItsBestIterateWhereTheLastOneIsWorse) {
  const auto [steps, true_poses, sensor] = se2_circle(150);
  const Gaussian<Eigen::Vector3d, 3> prior{true_poses[0], 1e-6 * Eigen::Matrix3d::Identity()};
  for (const bool damped : {false, true}) {
    GraphSlam<Se2Odometry, PointInRobotFrame2D> graph{
        Se2Odometry{}, sensor, prior, {.max_iterations = 12, .levenberg_marquardt = damped, .damp_after_rise = false}};
    eval::run(graph, steps);
    graph.warm_start(far_headings(true_poses), {});
    const auto summary = graph.optimize();
    const auto lowest = std::min_element(summary.cost.begin(), summary.cost.end());
    if (damped) {
      EXPECT_TRUE(std::is_sorted(summary.cost.rbegin(), summary.cost.rend()));
      EXPECT_EQ(summary.best_iteration, summary.iterations);
    } else {
      ASSERT_GT(summary.cost.back(), *lowest) << "this start no longer makes Gauss-Newton rise at its end";
      EXPECT_EQ(summary.best_iteration, lowest - summary.cost.begin());
    }
    EXPECT_EQ(summary.damped_from, -1);
    EXPECT_EQ(graph.cost(), *lowest) << (damped ? "Levenberg-Marquardt" : "Gauss-Newton");
  }
}

/// By default Gauss-Newton goes on damped after its first rise: up to that iteration its costs are
/// plain Gauss-Newton's, the rising step is undone, and from there the cost never rises, so the last
/// iterate is the lowest; from this start it ends below plain Gauss-Newton's best iterate.
TEST(GraphSlam, GaussNewtonGoesOnDampedAfterItsCostRises) {
  const Se2Circle circle = se2_circle(150);
  const Gaussian<Eigen::Vector3d, 3> prior{circle.true_poses[0], 1e-6 * Eigen::Matrix3d::Identity()};
  auto optimized = [&](const GraphOptions& options) {
    GraphSlam<Se2Odometry, PointInRobotFrame2D> graph{Se2Odometry{}, circle.sensor, prior, options};
    eval::run(graph, circle.steps);
    graph.warm_start(far_headings(circle.true_poses), {});
    const auto summary = graph.optimize();
    EXPECT_EQ(graph.cost(), summary.cost[static_cast<std::size_t>(summary.best_iteration)]);
    return summary;
  };
  const auto plain = optimized({.max_iterations = 12, .damp_after_rise = false});
  const auto safeguarded = optimized({.max_iterations = 12});
  ASSERT_GE(safeguarded.damped_from, 1) << "this start no longer makes Gauss-Newton rise";
  const auto rise = static_cast<std::size_t>(safeguarded.damped_from);
  ASSERT_GT(plain.cost[rise], plain.cost[rise - 1]);  // plain Gauss-Newton rose at the same iteration
  for (std::size_t k = 0; k < rise; ++k) EXPECT_EQ(safeguarded.cost[k], plain.cost[k]) << "iteration " << k;
  EXPECT_EQ(safeguarded.cost[rise], safeguarded.cost[rise - 1]);  // the rising step undone
  EXPECT_TRUE(std::is_sorted(safeguarded.cost.rbegin(), safeguarded.cost.rend()));
  EXPECT_EQ(safeguarded.best_iteration, safeguarded.iterations);
  EXPECT_LT(safeguarded.cost.back(), *std::min_element(plain.cost.begin(), plain.cost.end()));
  std::printf("plain Gauss-Newton: lowest chi2 %.6g; damped after its rise at iteration %d: %.6g\n",
              *std::min_element(plain.cost.begin(), plain.cost.end()), safeguarded.damped_from, safeguarded.cost.back());
}

/// Exact odometry cannot make a motion factor, which weighs by R^-1: the pose is refused with an
/// error naming the noise covariance (it named the joint covariance with the newest pose, which a
/// user could not trace to the zero noise), and the graph keeps the poses it had.
TEST(GraphSlam, ExactOdometryIsRefusedNamingItsNoiseCovariance) {
  PointInRobotFrame2D sensor;
  sensor.Q = 0.01 * Eigen::Matrix2d::Identity();
  GraphSlam<Se2Odometry, PointInRobotFrame2D> graph{
      Se2Odometry{}, sensor, {Eigen::Vector3d::Zero(), 1e-2 * Eigen::Matrix3d::Identity()}};
  graph.predict({Eigen::Vector3d(0.5, 0.0, 0.1), 1e-4 * Eigen::Matrix3d::Identity()}, 1.0);
  try {
    graph.predict({Eigen::Vector3d(0.5, 0.0, 0.1), Eigen::Matrix3d::Zero()}, 1.0);
    FAIL() << "exact odometry was taken";
  } catch (const numerical_error& e) {
    EXPECT_NE(std::string(e.what()).find("noise covariance"), std::string::npos) << e.what();
  }
  EXPECT_EQ(graph.num_poses(), 2u);
}

TEST(GraphSlam, RemoveLandmarkKeepsItsInformationAsALinearFactor) {
  const auto steps = test::random_linear_steps(30, 5, 12);
  Graph graph{kMotion, kSensor, kPrior};
  eval::run(graph, steps);
  graph.optimize();
  const auto before = graph.trajectory();
  const LandmarkId removed = graph.landmark_ids()[1];
  const auto kept = graph.landmark(graph.landmark_ids()[0]);
  graph.remove_landmark(removed);
  EXPECT_FALSE(graph.has_landmark(removed));
  graph.optimize();
  const auto after = graph.trajectory();
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_LT((after[k].mean - before[k].mean).cwiseAbs().maxCoeff(), 1e-9) << k;
    EXPECT_LT((after[k].cov - before[k].cov).cwiseAbs().maxCoeff(), 1e-9) << k;
  }
  EXPECT_LT((graph.landmark(kept.id).cov - kept.cov).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_THROW(graph.remove_landmark(removed), unknown_landmark_error);
}

/// A filter's estimate of a ship run to warm-start a graph from: its pose after every step (the prior
/// first) and its map at the end.
struct FilterStart {
  std::vector<Eigen::Vector2d> poses;
  Graph::MapEstimate map;
};

FilterStart ekf_start(const sim::Ship2DDataset& data) {
  EkfSlam<BeaconShip2D, BeaconOffset2D> ekf{data.motion, data.sensor, data.prior};
  const auto record = eval::run(ekf, data.steps);
  FilterStart start{{data.prior.mean}, ekf.map()};
  for (const auto& step : record.steps) start.poses.push_back(step.pose.mean);
  return start;
}

TEST(GraphSlam, WarmStartFromAFilterReachesTheSameOptimum) {
  const auto data = sim::simulate_ship_2d({.seed = 6, .num_steps = 300});
  const auto [poses, map] = ekf_start(data);
  Graph cold{data.motion, data.sensor, data.prior}, warm{data.motion, data.sensor, data.prior};
  eval::run(cold, data.steps);
  eval::run(warm, data.steps);
  warm.warm_start(poses, map);
  EXPECT_LT(warm.cost(), cold.cost());  // the filter's estimate is a better start than dead reckoning
  cold.optimize();
  warm.optimize();
  double worst = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k)
    worst = std::max(worst, (warm.pose_means()[k] - cold.pose_means()[k]).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-6);
  EXPECT_THROW(warm.warm_start(std::vector<Eigen::Vector2d>(3), map), invalid_input_error);
}

// A filter that keeps a pool of landmarks holds few of them at the end (the visual-inertial runner's):
// the others must move with the new trajectory, not stay where dead reckoning put them.
TEST(GraphSlam, WarmStartPlacesTheLandmarksItIsNotGivenFromTheirFirstMeasurementAtTheNewPoses) {
  const auto data = sim::simulate_ship_2d({.seed = 6, .num_steps = 300});
  const auto [poses, map] = ekf_start(data);
  Graph graph{data.motion, data.sensor, data.prior};
  eval::run(graph, data.steps);
  const Graph::MapEstimate given(map.begin(), map.begin() + 1);
  graph.warm_start(poses, given);
  std::map<LandmarkId, Eigen::Vector2d> started;
  for (const auto& [id, mean] : graph.landmark_means()) started[id] = mean;
  EXPECT_EQ(started.at(given[0].id), given[0].mean);
  std::size_t placed = 0;
  for (std::size_t k = 0; k < data.steps.size(); ++k)
    for (const auto& observation : data.steps[k].observations) {
      if (observation.landmark_id == given[0].id || !started.contains(observation.landmark_id)) continue;
      EXPECT_LT((started.at(observation.landmark_id) - data.sensor.initialize(poses[k + 1], observation.z).m).norm(), 1e-12)
          << "landmark " << observation.landmark_id << ", first seen at step " << k;
      started.erase(observation.landmark_id);  // only its first measurement places it
      ++placed;
    }
  EXPECT_EQ(placed + 1, map.size());
}

TEST(GraphSlam, SymbolicAnalysisIsReusedWhileThePatternIsUnchanged) {
  const auto steps = test::random_linear_steps(20, 4, 13);
  Graph graph{kMotion, kSensor, kPrior, {.max_iterations = 3}};
  eval::run(graph, steps);
  graph.optimize();
  graph.optimize();
  EXPECT_EQ(graph.symbolic_analyses(), 1);  // every iteration of both calls shared one analysis
  graph.predict(Eigen::Vector2d(1.0, 0.3), 1.0);
  graph.optimize();
  EXPECT_EQ(graph.symbolic_analyses(), 2);  // a new pose changes the pattern
}

}  // namespace
}  // namespace sextant
