#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <limits>
#include <random>
#include <string>

#include "sextant/core/validation.hpp"

namespace sextant {
namespace {

/// The error require_process_noise throws for R, or "" when it accepts R.
template <class Matrix>
std::string verdict(const Matrix& R) {
  try {
    require_process_noise(R);
    return "";
  } catch (const numerical_error& e) {
    return e.what();
  }
}

/// A random rotation of dimension n (the Q of a Gaussian matrix's QR).
Eigen::MatrixXd random_rotation(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  return Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ();
}

/// Motion models whose noise acts on fewer directions than the state has (a unicycle's, a camera's
/// velocities) give a singular R; it is positive semi-definite and must pass.
TEST(ProcessNoise, ASingularPositiveSemiDefiniteRPasses) {
  EXPECT_EQ(verdict(Eigen::Vector3d(1e-2, 1e-2, 0.0).asDiagonal().toDenseMatrix()), "");
  EXPECT_EQ(verdict(Eigen::Matrix3d::Zero().eval()), "");
  std::mt19937_64 rng(3);
  const Eigen::MatrixXd B = random_rotation(12, rng).leftCols(6) * 0.05;
  EXPECT_EQ(verdict((B * B.transpose()).eval()), "");
}

/// The tolerance is 1e-9 of R's largest entry: a smallest eigenvalue just inside it passes, one
/// just outside fails with a message that names it, whichever way the eigenvectors point.
TEST(ProcessNoise, TheSmallestEigenvalueDecidesAtTheToleranceInAnyBasis) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 11;
    const Eigen::MatrixXd Q = random_rotation(n, rng);
    Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
    const double tolerance = 1e-9 * (Q * lambda.asDiagonal() * Q.transpose()).cwiseAbs().maxCoeff();
    const bool inside = trial % 2 == 0;
    lambda(0) = inside ? -0.9 * tolerance : -1.1 * tolerance;
    Eigen::MatrixXd R = Q * lambda.asDiagonal() * Q.transpose();
    R = (0.5 * (R + R.transpose())).eval();
    ASSERT_NEAR(1e-9 * R.cwiseAbs().maxCoeff(), tolerance, 1e-3 * tolerance);  // the small change keeps the scale
    const std::string message = verdict(R);
    if (inside)
      EXPECT_EQ(message, "") << "n = " << n << ", smallest eigenvalue -0.9 x the tolerance";
    else
      EXPECT_NE(message.find("process noise R is not positive semi-definite (smallest eigenvalue"), std::string::npos)
          << "n = " << n << ": " << message;
  }
}

TEST(ProcessNoise, ANonFiniteOrAsymmetricRFailsWithWhatIsWrong) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(verdict(R), "process noise R has NaN or Inf entries");
  R = Eigen::Matrix3d::Identity();
  R(0, 1) = 0.5;
  EXPECT_EQ(verdict(R), "process noise R is not symmetric");
  EXPECT_NE(verdict(Eigen::Vector3d(1.0, 1.0, -1e-3).asDiagonal().toDenseMatrix()).find("not positive semi-definite"),
            std::string::npos);
}

}  // namespace
}  // namespace sextant
