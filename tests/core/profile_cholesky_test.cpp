#include "sextant/core/profile_cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>
#include <random>

namespace sextant {
namespace {

using Profile = ProfileCholesky<3>;
using Block = Profile::Block;

/// A random block that keeps the matrix diagonally dominant (positive definite) when it is added
/// with its transpose: entries in [-0.5, 0.5].
Block random_block(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  Block b;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) b(i, j) = u(rng);
  return b;
}

/// Rows 0 .. rows - 1 of a block-tridiagonal matrix (a chain of poses), staged, not factorized.
Profile chain(std::size_t rows, double diagonal, std::mt19937& rng) {
  Profile S;
  for (std::size_t n = 0; n < rows; ++n) {
    S.append_row();
    S.add(n, n, diagonal * Block::Identity());
    if (n > 0) S.add(n, n - 1, random_block(rng));
  }
  return S;
}

/// Grows a block matrix row by row as an online smoother does (each new row couples to the last
/// `reach` rows, now and then one far back, a loop closure), factorizing after every row; the
/// solve must equal a dense LLT's of the same matrix, and the first changed row must be the
/// oldest one the step touched.
TEST(ProfileCholesky, IncrementalFactorEqualsTheDenseOneAndRefactorizesOnlyFromTheOldestTouchedRow) {
  std::mt19937 rng(3);
  Profile S;
  const std::size_t reach = 4;
  for (std::size_t n = 0; n < 60; ++n) {
    S.append_row();
    S.add(n, n, 10.0 * Block::Identity());
    std::size_t oldest = n;
    for (std::size_t k = 1; k <= reach && k <= n; ++k) {
      S.add(n, n - k, random_block(rng));
      oldest = n - k;
    }
    if (n % 17 == 16) {  // a loop closure to row 2
      S.add(n, 2, random_block(rng));
      S.add(2, 2, Block::Identity());
      oldest = 2;
    }
    EXPECT_EQ(S.first_changed(), oldest) << n;
    S.factorize();
    S.commit();
    ASSERT_EQ(S.rows(), n + 1);
    const Eigen::MatrixXd dense = S.dense();
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(dense.rows(), -1.0, 2.0);
    const Eigen::VectorXd expected = dense.llt().solve(b);
    EXPECT_LT((S.solve(b) - expected).cwiseAbs().maxCoeff(), 1e-12) << n;
    const Eigen::MatrixXd inverse = dense.inverse();
    EXPECT_LT((S.last_inverse_block() - inverse.bottomRightCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-12) << n;
  }
}

/// A change that makes the matrix indefinite throws, and the matrix and its factor are as they
/// were: the next solve is bit for bit the one before.
TEST(ProfileCholesky, AnIndefiniteChangeThrowsAndLeavesMatrixAndFactorAsTheyWere) {
  std::mt19937 rng(5);
  Profile S = chain(10, 4.0, rng);
  S.factorize();
  S.commit();
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(30);
  const Eigen::VectorXd before = S.solve(b);
  const Eigen::MatrixXd dense_before = S.dense();
  S.append_row();
  S.add(10, 10, Block::Identity());
  S.add(6, 6, -100.0 * Block::Identity());
  EXPECT_THROW(S.factorize(), numerical_error);
  EXPECT_EQ(S.rows(), 10u);
  EXPECT_EQ(S.dense(), dense_before);
  EXPECT_EQ(S.solve(b), before);
  S.add(6, 6, Block::Identity());  // a valid change, factorized and then discarded
  S.factorize();
  EXPECT_NE(S.solve(b), before);
  S.discard();
  EXPECT_EQ(S.solve(b), before);
  EXPECT_THROW(S.add(3, 4, Block::Identity()), invalid_input_error);  // not in the lower triangle
}

/// factorize() works in memory it keeps between calls; what is left there from an earlier, larger
/// factorization (a loop closure) must not reach a later one: the original and a copy (whose memory
/// starts empty) factorize the same change to the same bits, and a NaN in the change is refused.
TEST(ProfileCholesky, MemoryKeptBetweenFactorizationsIsNotPartOfTheResult) {
  std::mt19937 rng(7);
  Profile S = chain(12, 10.0, rng);
  S.add(11, 0, random_block(rng));  // reaches back to row 0: the whole matrix is the trailing block
  S.factorize();
  S.commit();
  Profile copy = S;
  for (Profile* P : {&S, &copy}) {
    std::mt19937 same(9);
    P->append_row();
    P->add(12, 12, 10.0 * Block::Identity());
    P->add(12, 11, random_block(same));
    P->add(12, 10, random_block(same));
    P->factorize();
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(39, -1.0, 2.0);
  EXPECT_EQ(S.solve(b), copy.solve(b));
  EXPECT_EQ(S.last_inverse_block(), copy.last_inverse_block());
  S.commit();
  const Eigen::VectorXd before = S.solve(b);
  Block nan = Block::Zero();
  nan(1, 0) = std::numeric_limits<double>::quiet_NaN();
  S.add(12, 12, nan);
  EXPECT_THROW(S.factorize(), numerical_error);
  EXPECT_EQ(S.solve(b), before);
}

}  // namespace
}  // namespace sextant
