#include "sextant/eval/metrics.hpp"
#include "sextant/sim/ordered_draws.hpp"

#include <gtest/gtest.h>

#include <random>

namespace sextant::eval {
namespace {

TEST(Metrics, ChiSquareBoundsOfTheThesis) {
  EXPECT_NEAR(nees_upper_bound(2), 5.991, 5e-4);  // thesis §4.3.1, 2 dof
  EXPECT_NEAR(nees_upper_bound(3), 7.815, 5e-4);  // 3 dof
  EXPECT_NEAR(nees_upper_bound(1, 0.99), 6.635, 5e-4);
  EXPECT_THROW(nees_upper_bound(0), invalid_input_error);
  EXPECT_THROW(nees_upper_bound(2, 1.0), invalid_input_error);
}

TEST(Metrics, AneesIntervalForNRuns) {
  // 50 runs of a 2-dof estimate: 100 dof, chi2_100 quantiles 74.22 and 129.56, divided by 50.
  const Interval interval = anees_interval(2, 50);
  EXPECT_NEAR(interval.lower, 74.2219 / 50, 1e-4);
  EXPECT_NEAR(interval.upper, 129.5612 / 50, 1e-4);
  EXPECT_TRUE(interval.contains(2.0));
  EXPECT_FALSE(interval.contains(2.7));
  EXPECT_THROW(anees_interval(2, 0), invalid_input_error);
}

TEST(Metrics, AbsoluteErrorNeesMaeRmse) {
  EXPECT_DOUBLE_EQ(absolute_error(Eigen::Vector2d(3.0, 4.0), Eigen::Vector2d::Zero()), 5.0);
  const Eigen::Matrix2d cov = Eigen::Vector2d(4.0, 1.0).asDiagonal();
  EXPECT_DOUBLE_EQ(nees(Eigen::Vector2d(2.0, 1.0), cov), 2.0);
  EXPECT_THROW(nees(Eigen::Vector2d(1.0, 1.0), Eigen::Matrix2d::Zero()), numerical_error);
  EXPECT_EQ(nees_or_infinity(Eigen::Vector2d(1.0, 1.0), Eigen::Matrix2d::Zero()), std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(nees_or_infinity(Eigen::Vector2d(2.0, 1.0), cov), 2.0);
  const std::vector<double> errors{1.0, 2.0, 2.0, 3.0};
  EXPECT_DOUBLE_EQ(mean(errors), 2.0);
  EXPECT_DOUBLE_EQ(rms(errors), std::sqrt(4.5));
  EXPECT_DOUBLE_EQ(fraction_at_most(errors, 2.0), 0.75);
  EXPECT_EQ(mean({}), 0.0);
  EXPECT_TRUE(std::isnan(mean_or_nan({})) && std::isnan(rms_or_nan({})) && std::isnan(fraction_at_most_or_nan({}, 1.0)));
  EXPECT_DOUBLE_EQ(mean_or_nan(errors), 2.0);
  EXPECT_DOUBLE_EQ(rms_or_nan(errors), std::sqrt(4.5));
  EXPECT_DOUBLE_EQ(fraction_at_most_or_nan(errors, 2.0), 0.75);
}

TEST(Metrics, AneesPerStepAveragesRuns) {
  const auto anees = anees_per_step({{1.0, 2.0, 3.0}, {3.0, 4.0, 5.0}});
  EXPECT_EQ(anees, (std::vector<double>{2.0, 3.0, 4.0}));
  EXPECT_THROW(anees_per_step({{1.0}, {1.0, 2.0}}), invalid_input_error);
}

TEST(Metrics, EvaluateMapPerLandmark) {
  const std::vector<LandmarkEstimate<2>> map{{4, Eigen::Vector2d(3.0, 4.0), Eigen::Matrix2d::Identity()},
                                             {9, Eigen::Vector2d(1.0, 1.0), 4.0 * Eigen::Matrix2d::Identity()}};
  const std::map<LandmarkId, Eigen::Vector2d> truth{{4, Eigen::Vector2d::Zero()}, {9, Eigen::Vector2d(1.0, 3.0)}};
  const auto evaluation = evaluate_map(map, truth);
  EXPECT_EQ(evaluation.ids, (std::vector<LandmarkId>{4, 9}));
  EXPECT_EQ(evaluation.errors, (std::vector<double>{5.0, 2.0}));
  EXPECT_EQ(evaluation.nees, (std::vector<double>{25.0, 1.0}));
  EXPECT_THROW(evaluate_map(map, std::map<LandmarkId, Eigen::Vector2d>{{4, Eigen::Vector2d::Zero()}}),
               unknown_landmark_error);
}

/// N runs of K steps of a consistent estimator whose errors are correlated in time: e_k = rho
/// e_{k-1} + sqrt(1 - rho^2) w_k, stationary N(0, I_2), so every NEES = |e_k|^2 ~ chi2(2).
std::vector<double> correlated_run_averages(std::mt19937_64& rng, int runs, int steps, double rho) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> out;
  for (int i = 0; i < runs; ++i) {
    Eigen::Vector2d e = sim::ordered_draws<2>(unit, rng);
    double sum = 0.0;
    for (int k = 0; k < steps; ++k) {
      e = rho * e + std::sqrt(1.0 - rho * rho) * sim::ordered_draws<2>(unit, rng);
      sum += e.squaredNorm();
    }
    out.push_back(sum / steps);
  }
  return out;
}

TEST(Metrics, TimeAveragedAneesIntervalCoversAConsistentEstimatorWithCorrelatedSteps) {
  constexpr int kTrials = 400, kRuns = 20, kSteps = 100;
  std::mt19937_64 rng(11);
  int covered = 0, covered_by_independent_steps_interval = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const auto averages = correlated_run_averages(rng, kRuns, kSteps, 0.9);
    const double anees = mean(averages);
    covered += time_averaged_anees_interval(2, averages).contains(anees);
    covered_by_independent_steps_interval += anees_interval(2, kRuns * kSteps).contains(anees);
  }
  // Coverage 0.95 (t interval, exact up to the CLT for 20 runs): 380 of 400, binomial sd 4.4; 4 sd.
  EXPECT_NEAR(covered, 0.95 * kTrials, 4 * std::sqrt(kTrials * 0.95 * 0.05));
  // Treating the 2000 correlated steps as independent gives an interval far too narrow.
  EXPECT_LT(covered_by_independent_steps_interval, 0.7 * kTrials);
  EXPECT_THROW(time_averaged_anees_interval(2, std::vector<double>{2.0}), invalid_input_error);
  // Two runs far apart: t(1 dof) s / sqrt(2) = 12.7 x 7.0 / 1.41 = 62.9, so dof - 62.9 < 0; the
  // interval starts at 0 and keeps its upper end.
  const std::vector<double> scattered{0.1, 10.0};
  const double half_width = 12.706204736174698 * std::sqrt(0.5 * 9.9 * 9.9) / std::sqrt(2.0);
  const auto wide = time_averaged_anees_interval(2, scattered);
  EXPECT_EQ(wide.lower, 0.0);
  EXPECT_NEAR(wide.upper, 2.0 + half_width, 1e-9);
}

}  // namespace
}  // namespace sextant::eval
