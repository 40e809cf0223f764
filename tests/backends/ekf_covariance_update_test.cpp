// The two covariance corrections of EkfSlam: the symmetric form of eq. 17 and the Joseph form.
// On a well-conditioned problem they agree; on an ill-conditioned one (landmarks known to 1e4 m,
// then observed with sigma 1e-8 m) the symmetric form cancels to a covariance with negative eigenvalues
// while the Joseph form stays positive semi-definite.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <memory>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "support/batch_least_squares.hpp"

namespace sextant {
namespace {

/// z = m - x (BeaconOffset2D) whose noise the test can change between updates: a coarse sensor
/// first, then a very accurate one.
struct SwitchableOffsetSensor : BeaconOffset2D {
  std::shared_ptr<double> shared_sigma = std::make_shared<double>(1.0);
  MeasurementPrediction<2, 2, 2> predict(const Eigen::Vector2d& x, const Landmark& m) const {
    auto out = BeaconOffset2D::predict(x, m);
    out.Q = *shared_sigma * *shared_sigma * Eigen::Matrix2d::Identity();
    return out;
  }
  LandmarkInit<2, 2, 2> initialize(const Eigen::Vector2d& x, const Measurement& z) const {
    auto out = BeaconOffset2D::initialize(x, z);
    out.Q = *shared_sigma * *shared_sigma * Eigen::Matrix2d::Identity();
    return out;
  }
};

using Ekf = EkfSlam<BeaconShip2D, SwitchableOffsetSensor>;
using Obs = Observation<Eigen::Vector2d>;

double smallest_eigenvalue(const Eigen::MatrixXd& P) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
}

TEST(EkfCovarianceUpdate, JosephAndSymmetricFormsAgreeOnAWellConditionedProblem) {
  const auto steps = test::random_linear_steps(30, 8, 5);
  Ekf symmetric{test::kLinearMotion, SwitchableOffsetSensor{}, test::kLinearPrior, {}};
  Ekf joseph{test::kLinearMotion, SwitchableOffsetSensor{}, test::kLinearPrior,
             {.covariance_update = CovarianceUpdate::joseph}};
  for (const auto& step : steps)
    for (Ekf* ekf : {&symmetric, &joseph}) {
      ekf->predict(step.control, step.dt);
      ekf->update(step.observations);
    }
  // Both are exact in exact arithmetic; the difference is rounding on entries of order 1.
  EXPECT_LT((symmetric.covariance() - joseph.covariance()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((symmetric.pose().mean - joseph.pose().mean).norm(), 1e-12);
}

/// A robot known to 1e-6 m maps 20 landmarks with a sensor of sigma 1e4 m, then measures them all
/// again with sigma 1e-8 m: each landmark's variance falls from 1e8 to ~1e-12 m^2, 20 orders of
/// magnitude, below the rounding error (1e8 * 2^-52 ~ 2e-8) of the subtraction in eq. 17.
template <CovarianceUpdate kForm>
Eigen::MatrixXd covariance_after_accurate_remeasurement() {
  SwitchableOffsetSensor sensor;
  const Gaussian<Eigen::Vector2d, 2> prior{Eigen::Vector2d::Zero(), 1e-12 * Eigen::Matrix2d::Identity()};
  Ekf ekf{test::kLinearMotion, sensor, prior, {.covariance_update = kForm}};
  std::vector<Obs> observations;
  for (int j = 0; j < 20; ++j) observations.push_back({static_cast<LandmarkId>(j), Eigen::Vector2d(j, 0.5 * j * j)});
  *sensor.shared_sigma = 1e4;
  ekf.update(observations);
  *sensor.shared_sigma = 1e-8;
  ekf.update(observations);
  return ekf.covariance();
}

TEST(EkfCovarianceUpdate, JosephFormStaysPositiveSemiDefiniteWhereTheSymmetricFormDoesNot) {
  const Eigen::MatrixXd symmetric = covariance_after_accurate_remeasurement<CovarianceUpdate::symmetric>();
  const Eigen::MatrixXd joseph = covariance_after_accurate_remeasurement<CovarianceUpdate::joseph>();
  const double lambda_symmetric = smallest_eigenvalue(symmetric), lambda_joseph = smallest_eigenvalue(joseph);
  std::printf("smallest eigenvalue after the accurate update: symmetric %.3g, Joseph %.3g\n", lambda_symmetric,
              lambda_joseph);
  // The true posterior is positive definite (every variance >= 1e-16 from Q alone).
  EXPECT_LT(lambda_symmetric, 0.0) << "eq. 17 is expected to cancel below zero here";
  EXPECT_GE(lambda_joseph, 0.0);
  // And the Joseph form is also accurate: each landmark's variance is the robot's plus Q, about
  // 1e-12 + 1e-16 m^2 per axis; rounding of X_SS = I - K H (~1e-16) times 1e8 stays far below.
  for (Eigen::Index i = 2; i < joseph.rows(); ++i) EXPECT_NEAR(joseph(i, i), 1e-12 + 1e-16, 1e-14) << i;
}

}  // namespace
}  // namespace sextant
