#include "sextant/models/beacon_ship_2d.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

#include "sextant/testing/model_checks.hpp"
#include "sextant/sim/ordered_draws.hpp"

namespace sextant {
namespace {

class ShipModels : public ::testing::TestWithParam<HeadingNoise> {};

TEST_P(ShipModels, MotionJacobianMatchesCentralDifferences) {
  const BeaconShip2D motion{1.0, 0.26, GetParam()};
  for (double heading : {-3.0, -0.7, 0.0, 1.2, 2.9}) {
    const auto check = testing::check_motion_jacobians(motion, Eigen::Vector2d(12.0, -4.0),
                                                       Eigen::Vector2d(10.0, heading), 0.7);
    EXPECT_TRUE(check) << check.report;
  }
}

TEST_P(ShipModels, ProcessNoiseIsSymmetricPositiveDefinite) {
  const BeaconShip2D motion{1.0, 0.26, GetParam()};
  const auto R = motion.predict(Eigen::Vector2d::Zero(), Eigen::Vector2d(10.0, 0.4), 1.0).R;
  EXPECT_EQ(R, R.transpose());
  EXPECT_EQ(Eigen::LLT<Eigen::Matrix2d>(R).info(), Eigen::Success);
}

INSTANTIATE_TEST_SUITE_P(BothNoiseModels, ShipModels,
                         ::testing::Values(HeadingNoise::linearized, HeadingNoise::unbiased));

TEST(BeaconShip2D, LinearizedNoiseIsVMVtWithVTheControlJacobian) {
  const BeaconShip2D motion{0.8, 0.3, HeadingNoise::linearized};
  const Eigen::Vector2d x(1.0, 2.0), u(9.0, 0.6);
  const double dt = 1.5, h = 1e-6;
  Eigen::Matrix2d V;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d d = h * Eigen::Vector2d::Unit(i);
    V.col(i) = (motion.predict(x, u + d, dt).x - motion.predict(x, u - d, dt).x) / (2 * h);
  }
  const Eigen::Matrix2d M = Eigen::Vector2d(0.8 * 0.8, 0.3 * 0.3).asDiagonal();
  EXPECT_TRUE(motion.predict(x, u, dt).R.isApprox(V * M * V.transpose(), 1e-8));
}

TEST(BeaconShip2D, UnbiasedNoiseModelMatchesSampledDisplacementErrors) {
  // Fixed true control; the filter sees noisy (v, heading). The unbiased model's mean must equal
  // the true displacement on average and R the covariance of its error.
  const BeaconShip2D motion{1.0, 0.26, HeadingNoise::unbiased};
  const Eigen::Vector2d u_true(10.0, 0.8), x = Eigen::Vector2d::Zero();
  const Eigen::Vector2d d_true = u_true(0) * Eigen::Vector2d(std::cos(u_true(1)), std::sin(u_true(1)));
  std::mt19937_64 rng(42);
  std::normal_distribution<double> unit(0.0, 1.0);
  const int samples = 400000;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero(), sum_linearized = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sum_sq = Eigen::Matrix2d::Zero();
  const BeaconShip2D linearized{1.0, 0.26, HeadingNoise::linearized};
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector2d n = sim::ordered_draws<2>(unit, rng);
    const Eigen::Vector2d u_observed(u_true(0) + motion.sigma_v * n(0), u_true(1) + motion.sigma_heading * n(1));
    const Eigen::Vector2d error = motion.predict(x, u_observed, 1.0).x - d_true;
    sum += error;
    sum_sq += error * error.transpose();
    sum_linearized += linearized.predict(x, u_observed, 1.0).x - d_true;
  }
  const Eigen::Vector2d bias = sum / samples;
  const Eigen::Matrix2d cov = sum_sq / samples - bias * bias.transpose();
  EXPECT_LT(bias.norm(), 0.02);  // sampling std of the mean ~ 0.004
  // R is the error covariance over the heading the filter does not know: the true heading drawn
  // around the observed one (sigma_heading), then observed with noise. Pooled over both, the errors
  // (unbiased for every true heading) have covariance E_h[Cov(error | h)], which R must equal.
  Eigen::Matrix2d pooled = Eigen::Matrix2d::Zero();
  for (int i = 0; i < samples; ++i) {
    const double heading = u_true(1) + motion.sigma_heading * unit(rng);
    const Eigen::Vector2d d = u_true(0) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    const Eigen::Vector2d n = sim::ordered_draws<2>(unit, rng);
    const Eigen::Vector2d u_observed(u_true(0) + motion.sigma_v * n(0), heading + motion.sigma_heading * n(1));
    const Eigen::Vector2d error = motion.predict(x, u_observed, 1.0).x - d;
    pooled += error * error.transpose() / samples;
  }
  // Entries ~ 1..7; the sampling std of each is ~ 7 sqrt(2 / 400000) = 0.016: 5 std.
  EXPECT_LT((motion.predict(x, u_true, 1.0).R - pooled).cwiseAbs().maxCoeff(), 0.08);
  // Given one fixed true heading the error is more anisotropic than R (that is what R averages).
  EXPECT_GT((motion.predict(x, u_true, 1.0).R - cov).cwiseAbs().maxCoeff(), 0.08);
  // The thesis's linearized mean is short by (1 - exp(-sigma^2/2)) * 10 = 0.33, far outside sampling error.
  EXPECT_NEAR((sum_linearized / samples).norm(), 10.0 * (1.0 - std::exp(-0.5 * 0.26 * 0.26)), 0.02);
}

TEST(BeaconOffset2D, JacobiansAndInverseModelMatchCentralDifferences) {
  const BeaconOffset2D sensor{2.0};
  const auto check = testing::check_measurement_jacobians<BeaconShip2D>(sensor, Eigen::Vector2d(3.0, -1.0),
                                                                        Eigen::Vector2d(40.0, 25.0));
  EXPECT_TRUE(check) << check.report;
  const auto prediction = sensor.predict(Eigen::Vector2d(3.0, -1.0), Eigen::Vector2d(40.0, 25.0));
  EXPECT_EQ(prediction.z, Eigen::Vector2d(37.0, 26.0));  // eq. (98)
  EXPECT_EQ(prediction.Q, 4.0 * Eigen::Matrix2d::Identity());
}

}  // namespace
}  // namespace sextant
