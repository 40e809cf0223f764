#include "sextant/core/conditionally_linear.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <cstring>
#include <random>

#include "sextant/core/state_space.hpp"

namespace sextant {
namespace {

using Matrix5d = Eigen::Matrix<double, 5, 5>;
using Vector5d = Eigen::Matrix<double, 5, 1>;
using Space5 = EuclideanSpace<5>;

struct WithTail {
  static constexpr int kConditionallyLinearDims = 2;
};
struct WithoutTail {};
static_assert(conditionally_linear_dims_v<WithTail> == 2);
static_assert(conditionally_linear_dims_v<WithoutTail> == 0);

/// A covariance with correlations everywhere and a condition number of about 1e4.
Matrix5d correlated_covariance() {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit(0.0, 1.0);
  Matrix5d A;
  for (int i = 0; i < 25; ++i) A(i) = unit(rng);
  Eigen::Matrix<double, 5, 1> scale;
  scale << 1.0, 0.3, 0.1, 2.0, 0.05;
  return scale.asDiagonal() * (A * A.transpose() + 0.1 * Matrix5d::Identity()) * scale.asDiagonal();
}

TEST(ConditionallyLinear, TailCovarianceIsTheSchurComplementOfTheLead) {
  const Matrix5d cov = correlated_covariance();
  const Eigen::Matrix2d expected = cov.bottomRightCorner<2, 2>() - cov.bottomLeftCorner<2, 3>() *
                                                                        cov.topLeftCorner<3, 3>().inverse() *
                                                                        cov.topRightCorner<3, 2>();
  const Matrix5d tail = conditional_tail_covariance<2>(cov);
  const Eigen::Matrix2d kept = tail.bottomRightCorner<2, 2>();
  EXPECT_TRUE(kept.isApprox(expected, 1e-10));
  EXPECT_EQ(tail.topRows<3>().norm(), 0.0);
  EXPECT_EQ(tail.leftCols<3>().norm(), 0.0);
  // The conditional covariance is the inverse of the tail's block of the information matrix.
  const Eigen::Matrix2d information = cov.inverse().bottomRightCorner<2, 2>();
  EXPECT_TRUE(kept.isApprox(information.inverse(), 1e-8));
  EXPECT_EQ(conditional_tail_covariance<0>(cov).norm(), 0.0);
}

TEST(ConditionallyLinear, WithoutATailTheDrawIsThePlainLdltDraw) {
  const Matrix5d cov = correlated_covariance();
  const Vector5d mean = Vector5d::LinSpaced(1.0, 5.0);
  std::mt19937_64 a(17), b(17);
  const auto draw = draw_lead_keep_tail<Space5, 0>(mean, cov, a);
  const Eigen::LDLT<Matrix5d> ldlt(cov);
  std::normal_distribution<double> unit(0.0, 1.0);
  Vector5d n;
  for (int i = 0; i < 5; ++i) n(i) = unit(b) * std::sqrt(std::max(ldlt.vectorD()(i), 0.0));
  const Vector5d plain = mean + ldlt.transpositionsP().transpose() * (ldlt.matrixL() * n);
  EXPECT_EQ(std::memcmp(draw.x.data(), plain.data(), sizeof(Vector5d)), 0);
  EXPECT_EQ(draw.cov.norm(), 0.0);
  EXPECT_EQ(a(), b());  // the same random numbers consumed
}

/// The law of total covariance: over draws, Cov(x) + E[cov] = Sigma and E[x] = mean; and each draw's
/// tail is its conditional mean given its lead, exactly.
TEST(ConditionallyLinear, DrawsKeepTheGaussianTheyComeFrom) {
  const Matrix5d cov = correlated_covariance();
  const Vector5d mean = Vector5d::LinSpaced(-2.0, 2.0);
  const Eigen::Matrix<double, 2, 3> gain = cov.bottomLeftCorner<2, 3>() * cov.topLeftCorner<3, 3>().inverse();
  std::mt19937_64 rng(5);
  constexpr int kDraws = 40000;
  Vector5d sum = Vector5d::Zero();
  Matrix5d outer = Matrix5d::Zero();
  Matrix5d retained = Matrix5d::Zero();
  for (int k = 0; k < kDraws; ++k) {
    const auto draw = draw_lead_keep_tail<Space5, 2>(mean, cov, rng);
    const Vector5d d = draw.x - mean;
    ASSERT_TRUE((d.tail<2>() - gain * d.head<3>()).isZero(1e-9 * (1.0 + d.norm())));
    sum += d;
    outer += d * d.transpose();
    retained = draw.cov;  // the same for every draw
  }
  const Vector5d average = sum / kDraws;
  const Matrix5d total = outer / kDraws - average * average.transpose() + retained;
  for (int i = 0; i < 5; ++i) {
    const double sd = std::sqrt(cov(i, i));
    // 5 standard errors of an average of kDraws: the test fails by chance once in ~1.7 million.
    EXPECT_LT(std::abs(average(i)), 5.0 * sd / std::sqrt(kDraws)) << i;
    for (int j = 0; j < 5; ++j) {
      // Standard error of a sample covariance: sqrt((S_ii S_jj + S_ij^2) / n).
      const double se = std::sqrt((cov(i, i) * cov(j, j) + cov(i, j) * cov(i, j)) / kDraws);
      EXPECT_LT(std::abs(total(i, j) - cov(i, j)), 5.0 * se) << i << "," << j;
    }
  }
  EXPECT_TRUE(retained.isApprox(conditional_tail_covariance<2>(cov)));
}

TEST(ConditionallyLinear, ASingularLeadIsDrawnOnItsRangeAndTheTailConditionedByThePseudoInverse) {
  Matrix5d cov = correlated_covariance();
  cov.row(0).setZero();  // the first entry is known exactly
  cov.col(0).setZero();
  std::mt19937_64 rng(9);
  const auto draw = draw_lead_keep_tail<Space5, 2>(Vector5d::Ones(), cov, rng);
  EXPECT_EQ(draw.x(0), 1.0);
  EXPECT_TRUE(draw.x.allFinite());
  EXPECT_TRUE(draw.cov.allFinite());
  const Eigen::Matrix2d kept = draw.cov.bottomRightCorner<2, 2>();
  EXPECT_GT(kept.determinant(), 0.0);
}

}  // namespace
}  // namespace sextant
