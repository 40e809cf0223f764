// GraphSLAM's online mode (GraphOptions::incremental): one Gauss-Newton step a frame on the
// incrementally factorized reduced pose system.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>
#include <random>

#include "sextant/backends/graph_slam.hpp"
#include "sextant/eval/runner.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/sim/ship_2d.hpp"
#include "support/batch_least_squares.hpp"

namespace sextant {
namespace {

using Graph = GraphSlam<BeaconShip2D, BeaconOffset2D>;

/// Largest difference between two graphs' pose and landmark means.
template <class A, class B>
double largest_difference(const A& a, const B& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.pose_means().size(); ++k)
    worst = std::max(worst, (a.pose_means()[k] - b.pose_means()[k]).cwiseAbs().maxCoeff());
  for (const auto& [id, mean] : a.landmark_means())
    worst = std::max(worst, (mean - b.landmark(id).mean).cwiseAbs().maxCoeff());
  return worst;
}

/// On a linear problem one Gauss-Newton step is the optimum, so after every frame the online
/// estimate must be the batch optimum of the frames so far, and pose() the newest pose's marginal.
TEST(GraphSlamOnline, EqualsTheBatchOptimumAfterEveryFrameOnALinearProblem) {
  const auto steps = test::random_linear_steps(60, 6, 7);
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.incremental = true}};
  double worst_mean = 0.0, worst_cov = 0.0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    online.predict(steps[k].control, steps[k].dt);
    online.update(steps[k].observations);
    if (k % 7 != 6 && k + 1 != steps.size()) continue;
    Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
    eval::run(batch, std::span(steps).first(k + 1));
    batch.optimize();
    worst_mean = std::max(worst_mean, largest_difference(online, batch));
    worst_cov = std::max(worst_cov, (online.pose().cov - batch.trajectory().back().cov).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst_mean, 1e-9);
  EXPECT_LT(worst_cov, 1e-9);
}

/// A robot that drives the same loop twice, seeing on the second lap the landmarks of the first: from
/// the first re-observation on, each row of the reduced system reaches a lap back and the dense
/// refactorization from there passes ProfileCholesky's check, so the steps go sparse (a fill-reducing
/// order). Linear, so the online estimate must still be the batch optimum, and pose() its marginal.
TEST(GraphSlamOnline, ALoopThatWidensTheEnvelopeGoesSparseAndStaysTheBatchOptimum) {
  constexpr int kLap = 210;  // 2 x 211 = 422 dimensions back at the first closure: > 2e7 flops dense
  std::mt19937_64 rng(17);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>> steps;
  for (int k = 0; k < 2 * kLap; ++k) {
    const double heading = 2.0 * std::numbers::pi * (k % kLap) / kLap;
    Step<Eigen::Vector2d, Eigen::Vector2d> step{Eigen::Vector2d(1.0, heading), 0.5, {}};
    for (int j = (k % kLap) / 3; j <= (k % kLap) / 3 + 1; ++j)
      step.observations.push_back({static_cast<LandmarkId>(j), Eigen::Vector2d(unit(rng), unit(rng))});
    steps.push_back(step);
  }
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.incremental = true}};
  std::size_t sparse = 0, first_sparse = 0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    online.predict(steps[k].control, steps[k].dt);
    online.update(steps[k].observations);
    if (online.last_online_step().sparse && sparse++ == 0) first_sparse = k;
  }
#ifdef SEXTANT_HAS_CHOLMOD
  EXPECT_EQ(first_sparse, static_cast<std::size_t>(kLap));  // the first frame that closes the loop
  EXPECT_EQ(sparse, static_cast<std::size_t>(kLap));        // and every frame after it
#else
  EXPECT_EQ(sparse, 0u);  // without CHOLMOD no analysis predicts the sparse flops: always dense
#endif
  Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
  eval::run(batch, steps);
  batch.optimize();
  EXPECT_LT(largest_difference(online, batch), 1e-9);
  EXPECT_LT((online.pose().cov - batch.trajectory().back().cov).cwiseAbs().maxCoeff(), 1e-9);
}

/// The ship is nonlinear (heading in the motion, range and bearing): the online estimate, relinearized
/// only where a variable moved by more than a tenth of its conditional standard deviation, must end
/// near the converged batch optimum. Margin: a quarter of each pose's marginal standard deviation,
/// i.e. a difference the estimate's own uncertainty cannot tell apart.
TEST(GraphSlamOnline, EndsAtTheBatchOptimumOnTheShip) {
  const auto data = sim::simulate_ship_2d({.seed = 4, .num_steps = 400});
  Graph online{data.motion, data.sensor, data.prior, {.incremental = true}};
  Graph batch{data.motion, data.sensor, data.prior};
  eval::run(online, data.steps);
  eval::run(batch, data.steps);
  ASSERT_TRUE(batch.optimize().converged);
  const auto trajectory = batch.trajectory();
  double worst = 0.0;
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    const Eigen::Vector2d sigma = trajectory[k].cov.diagonal().cwiseSqrt();
    worst = std::max(worst, ((online.pose_means()[k] - trajectory[k].mean).cwiseAbs().cwiseQuotient(sigma)).maxCoeff());
  }
  std::printf("largest online - batch pose difference: %.4f marginal standard deviations\n", worst);
  EXPECT_LT(worst, 0.25);
  EXPECT_GT(online.last_online_step().poses, 400u);
}

/// A linear corridor: landmark j is in view from step 2 j to step 2 j + 5, so each frame's factors
/// reach at most six poses back, however long the run.
std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>> corridor_steps(int num_steps) {
  std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>> steps;
  for (int k = 0; k < num_steps; ++k) {
    Step<Eigen::Vector2d, Eigen::Vector2d> step{Eigen::Vector2d(1.0, 0.1 * (k % 5)), 0.5, {}};
    for (int j = std::max(0, (k - 5 + 1) / 2); 2 * j <= k; ++j)
      step.observations.push_back({static_cast<LandmarkId>(j), Eigen::Vector2d(0.3 * (2 * j - k), 1.0 + 0.01 * k)});
    steps.push_back(step);
  }
  return steps;
}

/// The incremental property: the reduced system is refactorized from the oldest pose that saw a
/// landmark the new frame sees (or the previous pose, which the motion factor reaches), never from
/// the first pose. Relinearization is off here (a moved pose reaches back further by design).
TEST(GraphSlamOnline, RefactorizesOnlyFromTheOldestPoseTheNewFactorsReach) {
  const auto steps = corridor_steps(120);
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.incremental = true, .relinearize_threshold = 1e300}};
  std::map<LandmarkId, std::size_t> first_seen;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    online.predict(steps[k].control, steps[k].dt);
    online.update(steps[k].observations);
    std::size_t oldest = k;  // the motion factor reaches pose k (the new one is k + 1)
    for (const auto& observation : steps[k].observations)
      oldest = std::min(oldest, first_seen.emplace(observation.landmark_id, k + 1).first->second);
    if (k == 0) oldest = 0;  // the first step builds the system
    EXPECT_EQ(online.last_online_step().first_row, oldest) << k;
    EXPECT_GE(online.last_online_step().first_row + 8, k) << k;
  }
  Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
  eval::run(batch, steps);
  batch.optimize();
  EXPECT_LT(largest_difference(online, batch), 1e-9);
}

/// optimize() in between, then more online frames: the online system is rebuilt at the optimum.
TEST(GraphSlamOnline, ContinuesAfterABatchOptimization) {
  const auto steps = test::random_linear_steps(40, 5, 9);
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.incremental = true}};
  Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
  eval::run(online, std::span(steps).first(20));
  online.optimize();
  eval::run(online, std::span(steps).subspan(20));
  eval::run(batch, steps);
  batch.optimize();
  EXPECT_LT(largest_difference(online, batch), 1e-9);
}

/// Removing landmarks (the bounded pool) keeps their information in S as linear factors: on a linear
/// problem the online estimate still equals the batch optimum with the same removals, and a removed
/// id seen again starts a new landmark in both.
TEST(GraphSlamOnline, RemovedLandmarksKeepTheirInformation) {
  const auto steps = test::random_linear_steps(40, 6, 12);
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.incremental = true}};
  Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
  for (std::size_t k = 0; k < steps.size(); ++k) {
    for (Graph* graph : {&online, &batch}) {
      graph->predict(steps[k].control, steps[k].dt);
      graph->update(steps[k].observations);
      if (k % 9 == 8) graph->remove_landmark(graph->landmark_ids()[k % graph->num_landmarks()]);
    }
  }
  batch.optimize();
  EXPECT_EQ(online.num_landmarks(), batch.num_landmarks());
  EXPECT_LT(largest_difference(online, batch), 1e-9);
}

/// The fixed-lag mode (GraphOptions::lag) on the linear corridor, where each landmark is in view over
/// six frames and never again: marginalizing the poses that leave the window (and the landmarks
/// no window pose sees) is exact on a linear problem, so after every frame the window's poses, the
/// landmarks they see and pose()'s covariance must equal the batch optimum of the frames so far,
/// with the lag (4) shorter than a landmark's track, so that the prior carries landmarks still in view.
/// Removals (the bounded pool) marginalize the landmark into the prior, as the batch's linear factor.
void expect_fixed_lag_equals_the_batch(std::size_t remove_every) {
  constexpr std::size_t lag = 4;
  const auto steps = corridor_steps(60);
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.lag = lag}};
  Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
  double worst_mean = 0.0, worst_cov = 0.0;
  std::size_t compared_landmarks = 0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    for (Graph* graph : {&online, &batch}) {
      graph->predict(steps[k].control, steps[k].dt);
      graph->update(steps[k].observations);
      if (remove_every > 0 && k % remove_every == remove_every - 1) graph->remove_landmark(graph->landmark_ids()[k % graph->num_landmarks()]);
    }
    Graph solved = batch;
    solved.optimize();
    const std::size_t newest = k + 1, first = newest + 1 > lag ? newest + 1 - lag : 0;
    EXPECT_EQ(online.last_online_step().first_row, first == 0 ? 0 : first - 1) << k;  // the step's window, before it slid
    for (std::size_t p = first; p <= newest; ++p)
      worst_mean = std::max(worst_mean, (online.pose_means()[p] - solved.pose_means()[p]).cwiseAbs().maxCoeff());
    const auto means = online.landmark_means();
    const std::map<LandmarkId, Eigen::Vector2d> ours(means.begin(), means.end());
    for (std::size_t back = 0; back < lag && back <= k; ++back)
      for (const auto& observation : steps[k - back].observations)
        if (ours.contains(observation.landmark_id)) {
          const Eigen::Vector2d theirs = solved.landmark(observation.landmark_id).mean;
          worst_mean = std::max(worst_mean, (ours.at(observation.landmark_id) - theirs).cwiseAbs().maxCoeff());
          ++compared_landmarks;
        }
    worst_cov = std::max(worst_cov, (online.pose().cov - solved.trajectory().back().cov).cwiseAbs().maxCoeff());
  }
  std::printf("fixed lag - batch: means %.3g, newest covariance %.3g (%zu landmark comparisons)\n", worst_mean, worst_cov,
              compared_landmarks);
  EXPECT_GT(compared_landmarks, 500u);
  EXPECT_LT(worst_mean, 1e-9);
  EXPECT_LT(worst_cov, 1e-9);
}

TEST(GraphSlamFixedLag, EqualsTheBatchOptimumOnTheWindowOfALinearCorridor) { expect_fixed_lag_equals_the_batch(0); }

TEST(GraphSlamFixedLag, RemovedLandmarksKeepTheirInformation) { expect_fixed_lag_equals_the_batch(9); }

/// The step's dense blocks live in memory kept from frame to frame (LagScratch), which a copy does not
/// share: a copy made mid-run whose original is then destroyed goes on bit for bit as a run that was
/// never copied (under the sanitizers, a view into the original's memory would be a use after free).
TEST(GraphSlamFixedLag, ACopyGoesOnInItsOwnMemory) {
  const auto steps = corridor_steps(40);
  const GraphOptions options{.lag = 4};
  Graph reference{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, options};
  std::optional<Graph> original(std::in_place, test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, options);
  std::optional<Graph> copy;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    if (k == steps.size() / 2) {
      copy.emplace(*original);
      original.reset();
    }
    for (Graph* graph : {&reference, original ? &*original : &*copy}) {
      graph->predict(steps[k].control, steps[k].dt);
      graph->update(steps[k].observations);
    }
    if (!copy) continue;
    ASSERT_EQ(copy->pose_means().size(), reference.pose_means().size());
    for (std::size_t p = 0; p < reference.pose_means().size(); ++p) EXPECT_EQ(copy->pose_means()[p], reference.pose_means()[p]) << k;
    EXPECT_EQ(copy->pose().cov, reference.pose().cov) << k;
  }
  ASSERT_TRUE(copy.has_value());
}

/// Landmarks that leave the window and come back (each one skips every third frame; lag 1: every
/// frame retires the landmarks it did not see and brings back those it sees again with their marginal
/// as a prior, docs/derivations/fixed_lag_graph_slam.md). The re-entering marginal drops its
/// correlation with what was marginalized with it, so the estimate is no longer the batch's; margin:
/// every frame's newest pose within 3 of the batch's marginal standard deviations of the batch optimum
/// (the estimate's own uncertainty), its covariance positive definite and finite.
TEST(GraphSlamFixedLag, LandmarksSeenAgainAfterTheyLeftTheWindowBringTheirMarginalBack) {
  const auto steps = test::random_linear_steps(40, 6, 7);
  Graph online{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.lag = 1, .reuse_retired_marginals = true}};
  double worst = 0.0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    online.predict(steps[k].control, steps[k].dt);
    ASSERT_NO_THROW(online.update(steps[k].observations)) << k;
    Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
    eval::run(batch, std::span(steps).first(k + 1));
    batch.optimize();
    const auto newest = batch.trajectory().back();
    ASSERT_TRUE(online.pose().cov.allFinite()) << k;
    ASSERT_EQ(Eigen::LLT<Eigen::Matrix2d>(online.pose().cov).info(), Eigen::Success) << k;
    const Eigen::Vector2d sigma = newest.cov.diagonal().cwiseSqrt();
    worst = std::max(worst, (online.pose().mean - newest.mean).cwiseAbs().cwiseQuotient(sigma).maxCoeff());
  }
  std::printf("fixed lag 1 - batch, newest pose: %.3f marginal standard deviations at most\n", worst);
  EXPECT_LT(worst, 3.0);
}

TEST(GraphSlamOnline, RejectsANonPositiveRelinearizationThreshold) {
  EXPECT_THROW((Graph{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior,
                      {.incremental = true, .relinearize_threshold = 0.0}}),
               invalid_input_error);
}

/// What re-using a retired landmark's marginal costs (GraphOptions::reuse_retired_marginals). On a
/// linear problem the batch's marginal is the exact posterior. A fixed lag that brings a landmark back
/// without its old marginal ignores that it was seen before, which can only lose information: its
/// newest pose covariance is never below the batch's (conservative, to rounding). Bringing the
/// marginal back counts the information the marginalized poses and landmarks share with it twice:
/// somewhere below the batch's (overconfident). Same steps as the test above (lag 1).
TEST(GraphSlamFixedLag, WithoutTheRetiredMarginalsTheWindowIsConservativeAndWithThemItIsNot) {
  const auto steps = test::random_linear_steps(40, 6, 7);
  Graph fresh{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.lag = 1}};
  Graph reusing{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.lag = 1, .reuse_retired_marginals = true}};
  double fresh_lowest = 0.0, reusing_lowest = 0.0;  // smallest eigenvalue of online - batch, relative to the batch's largest
  for (std::size_t k = 0; k < steps.size(); ++k) {
    for (Graph* graph : {&fresh, &reusing}) {
      graph->predict(steps[k].control, steps[k].dt);
      graph->update(steps[k].observations);
    }
    Graph batch{test::kLinearMotion, test::kLinearSensor, test::kLinearPrior, {.max_iterations = 1}};
    eval::run(batch, std::span(steps).first(k + 1));
    batch.optimize();
    const Eigen::Matrix2d exact = batch.trajectory().back().cov;
    const double scale = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(exact).eigenvalues().maxCoeff();
    const auto lowest = [&](const Graph& g) {
      return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(g.pose().cov - exact).eigenvalues().minCoeff() / scale;
    };
    fresh_lowest = std::min(fresh_lowest, lowest(fresh));
    reusing_lowest = std::min(reusing_lowest, lowest(reusing));
  }
  std::printf("fixed lag 1, newest pose covariance - batch's, smallest eigenvalue / batch's largest: without the retired "
              "marginals %.3g, with them %.3g\n", fresh_lowest, reusing_lowest);
  EXPECT_GT(fresh_lowest, -1e-9);
  EXPECT_LT(reusing_lowest, -1e-3);
}

}  // namespace
}  // namespace sextant
