#include "sextant/backends/ekf_slam.hpp"

#include <gtest/gtest.h>

#include "sextant/eval/runner.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/sim/ship_2d.hpp"
#include "sextant/testing/textbook_ekf.hpp"
#include "sextant/eval/metrics.hpp"
#include "support/batch_least_squares.hpp"
#include "support/nees_bound.hpp"

namespace sextant {
namespace {

using Ekf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
static_assert(SlamBackend<Ekf>);

const auto& kMotion = test::kLinearMotion;
const auto& kSensor = test::kLinearSensor;
const auto& kPrior = test::kLinearPrior;

Ekf run_filter(const std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>>& steps, EkfOptions options) {
  Ekf ekf{kMotion, kSensor, kPrior, options};
  eval::run(ekf, steps);
  return ekf;
}

void expect_equals_batch(const Ekf& ekf, const test::BatchSolution& batch, double tolerance) {
  const auto pose = ekf.pose();
  const Eigen::Index p = batch.final_pose_offset;
  EXPECT_LT((pose.mean - batch.mean.segment<2>(p)).cwiseAbs().maxCoeff(), tolerance);
  EXPECT_LT((pose.cov - batch.covariance.block<2, 2>(p, p)).cwiseAbs().maxCoeff(), tolerance);
  ASSERT_EQ(ekf.num_landmarks(), batch.landmark_offset.size());
  for (const auto& [id, offset] : batch.landmark_offset) {
    const auto landmark = ekf.landmark(id);
    EXPECT_LT((landmark.mean - batch.mean.segment<2>(offset)).cwiseAbs().maxCoeff(), tolerance) << "landmark " << id;
    EXPECT_LT((landmark.cov - batch.covariance.block<2, 2>(offset, offset)).cwiseAbs().maxCoeff(), tolerance)
        << "landmark " << id;
  }
}

TEST(EkfSlam, LinearGaussianProblemEqualsExactBatchLeastSquares) {
  const auto steps = test::random_linear_steps(60, 6, 7);
  const auto batch = test::solve_linear_ship_problem(kMotion, kSensor, kPrior, steps);
  expect_equals_batch(run_filter(steps, {}), batch, 1e-9);
}

TEST(EkfSlam, SequentialAndJosephUpdatesEqualBatchLeastSquaresToo) {
  const auto steps = test::random_linear_steps(60, 6, 8);
  const auto batch = test::solve_linear_ship_problem(kMotion, kSensor, kPrior, steps);
  expect_equals_batch(run_filter(steps, {.batch_update = false}), batch, 1e-9);
  expect_equals_batch(run_filter(steps, {.covariance_update = CovarianceUpdate::joseph}), batch, 1e-9);
}

// On a linear model the first Gauss-Newton step is the optimum: the iterated EKF stops after its
// second linearization finds nothing to move, and is the Kalman filter.
TEST(EkfSlam, IteratedUpdateOnALinearProblemIsTheKalmanUpdate) {
  const auto steps = test::random_linear_steps(60, 6, 9);
  const auto batch = test::solve_linear_ship_problem(kMotion, kSensor, kPrior, steps);
  expect_equals_batch(run_filter(steps, {.iterations = 5}), batch, 1e-9);
}

TEST(EkfSlam, BlockSparseUpdateEqualsTextbookDenseUpdate) {
  const auto steps = test::random_linear_steps(10, 6, 10);
  Ekf ekf{kMotion, kSensor, kPrior};
  eval::run(ekf, steps);
  // One more correction of four known landmarks, both ways, each with its own noise scale.
  std::vector<Observation<Eigen::Vector2d>> observations;
  const double scales[] = {1.0, 0.5, 2.0, 3.0};
  for (std::size_t i = 0; i < 4; ++i) observations.push_back({ekf.landmark_ids()[i], Eigen::Vector2d(i, 1.0), scales[i]});
  Eigen::MatrixXd P = ekf.covariance();
  Eigen::VectorXd mean(P.rows());
  mean.head<2>() = ekf.pose().mean;
  for (std::size_t slot = 0; slot < ekf.num_landmarks(); ++slot)
    mean.segment<2>(2 + 2 * slot) = ekf.landmark(ekf.landmark_ids()[slot]).mean;
  const auto dense = testing::linearize_dense(ekf, kSensor, observations);
  testing::textbook_ekf_update(P, mean, dense.H, dense.Q, dense.residual);
  ekf.update(observations);
  EXPECT_LT((Eigen::MatrixXd(ekf.covariance()) - P).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((ekf.pose().mean - mean.head<2>()).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(EkfSlam, NewLandmarkGetsInverseModelCovarianceAndCrossCovariance) {
  Ekf ekf{kMotion, kSensor, kPrior};
  ekf.update(std::vector<Observation<Eigen::Vector2d>>{{5, Eigen::Vector2d(2.0, 3.0)}});
  const auto landmark = ekf.landmark(5);
  EXPECT_TRUE(landmark.mean.isApprox(kPrior.mean + Eigen::Vector2d(2.0, 3.0)));
  EXPECT_TRUE(landmark.cov.isApprox(kPrior.cov + kSensor.noise()));
  const Eigen::MatrixXd P = ekf.covariance();
  EXPECT_TRUE(P.block(2, 0, 2, 2).isApprox(kPrior.cov));
}

TEST(EkfSlam, RemoveLandmarkMarginalizesAndKeepsTheOthersIntact) {
  const auto steps = test::random_linear_steps(20, 5, 11);
  Ekf ekf = run_filter(steps, {});
  const auto before = ekf.map();
  const LandmarkId removed = before[1].id;
  ekf.remove_landmark(removed);
  EXPECT_FALSE(ekf.has_landmark(removed));
  EXPECT_EQ(ekf.num_landmarks(), before.size() - 1);
  EXPECT_EQ(ekf.state_dim(), 2 + 2 * static_cast<Eigen::Index>(before.size() - 1));
  for (const auto& estimate : before) {
    if (estimate.id == removed) continue;
    const auto after = ekf.landmark(estimate.id);
    EXPECT_EQ(after.mean, estimate.mean);
    EXPECT_EQ(after.cov, estimate.cov);
  }
  // The filter keeps working after removal (the slot was reused by the last landmark).
  ekf.predict(Eigen::Vector2d(1.0, 0.3), 1.0);
  EXPECT_NO_THROW(ekf.update(std::vector<Observation<Eigen::Vector2d>>{{before.back().id, Eigen::Vector2d(1, 1)}}));
}

TEST(EkfSlam, GateRejectsOutliersAndReportsThem) {
  Ekf ekf{kMotion, kSensor, kPrior, {.gate_probability = 0.999}};
  ekf.update(std::vector<Observation<Eigen::Vector2d>>{{1, Eigen::Vector2d(2.0, 0.0)}, {2, Eigen::Vector2d(0.0, 2.0)}});
  const auto result = ekf.update(
      std::vector<Observation<Eigen::Vector2d>>{{1, Eigen::Vector2d(2.1, 0.0)}, {2, Eigen::Vector2d(40.0, 2.0)}});
  EXPECT_EQ(result.corrected, 1u);
  ASSERT_EQ(result.rejected.size(), 1u);
  EXPECT_EQ(result.rejected.front(), 2u);
}

TEST(EkfSlam, ShipRunTracksTheTruth) {
  sim::Ship2DOptions options;
  options.seed = 3;
  const auto data = sim::simulate_ship_2d(options);
  Ekf ekf{data.motion, data.sensor, data.prior};
  const auto record = eval::run(ekf, data.steps);
  ASSERT_EQ(record.steps.size(), 1390u);
  EXPECT_EQ(ekf.num_landmarks(), data.true_landmarks.size());
  // A consistent estimate: final pose and every landmark inside their chi-square bounds (1% overall).
  const auto pose = record.steps.back().pose;
  EXPECT_LT(eval::nees(pose.mean - data.true_poses.back(), pose.cov), test::nees_bound(2));
  const auto map = ekf.map();
  for (const auto& landmark : map)
    EXPECT_LT(eval::nees(landmark.mean - data.true_landmarks.at(landmark.id), landmark.cov), test::nees_bound(2, map.size()))
        << landmark.id;
}

}  // namespace
}  // namespace sextant
