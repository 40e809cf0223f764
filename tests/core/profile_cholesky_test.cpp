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

/// A robot that comes back to where it started: a chain of rows, and from row 140 on every fifth
/// row also coupled to one of the first five. The dense refactorization from the oldest touched row
/// is then the whole matrix, mostly zero blocks; the sparse one in a fill-reducing order is cheaper
/// and taken, and from then on (a dense step would start at row 0); every solve and the last block
/// of the inverse equal a dense LLT's of the same matrix.
TEST(ProfileCholesky, ALoopBackToTheStartIsFactorizedSparseAndSolvesAsTheDenseFactor) {
  std::mt19937 rng(11);
  Profile S;
  for (std::size_t n = 0; n < 165; ++n) {
    S.append_row();
    S.add(n, n, 10.0 * Block::Identity());
    if (n > 0) S.add(n, n - 1, random_block(rng));
    const bool loop = n >= 140 && n % 5 == 0;
    if (loop) {
      S.add(n, n % 25 / 5, random_block(rng));
      S.add(n % 25 / 5, n % 25 / 5, Block::Identity());
    }
    S.factorize();
#ifdef SEXTANT_HAS_CHOLMOD
    EXPECT_EQ(S.factorized_sparse(), n >= 140) << n;  // the loops reach 140 rows back: > 2e7 flops dense
#else
    EXPECT_FALSE(S.factorized_sparse()) << n;  // no analysis to predict the sparse flops: always dense
#endif
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3 * static_cast<Eigen::Index>(n + 1), -1.0, 2.0);
    const Eigen::VectorXd staged = S.solve(b);
    const Block staged_last = S.last_inverse_block();
    S.commit();
    EXPECT_EQ(S.solve(b), staged) << n;  // the committed factor is the staged one
    if (n < 138 || (!loop && n % 4 != 0)) continue;  // the dense reference is O(n^3)
    const Eigen::MatrixXd dense = S.dense();
    const Eigen::LLT<Eigen::MatrixXd> llt(dense);
    EXPECT_LT((staged - llt.solve(b)).cwiseAbs().maxCoeff(), 1e-12) << n;
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(dense.rows(), 3);
    unit.bottomRows(3).setIdentity();
    EXPECT_LT((staged_last - llt.solve(unit).bottomRows(3)).cwiseAbs().maxCoeff(), 1e-12) << n;
  }
}

/// After a sparse step the matrix and both factors survive what the dense ones do: a copy solves
/// to the same bits, an indefinite change throws and leaves the solve as it was, a discarded one too.
TEST(ProfileCholesky, ASparseStepKeepsTheStrongGuaranteeAndCopies) {
#ifndef SEXTANT_HAS_CHOLMOD
  GTEST_SKIP() << "without CHOLMOD no step goes sparse";
#endif
  std::mt19937 rng(13);
  Profile S = chain(160, 10.0, rng);
  S.factorize();
  S.commit();
  S.append_row();
  S.add(160, 160, 10.0 * Block::Identity());
  S.add(160, 159, random_block(rng));
  S.add(160, 1, random_block(rng));
  S.factorize();
  ASSERT_TRUE(S.factorized_sparse());
  S.commit();
  ASSERT_TRUE(S.factorized_sparse());
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3 * 161, -1.0, 2.0);
  const Eigen::VectorXd before = S.solve(b);
  const Profile copy = S;
  EXPECT_EQ(copy.solve(b), before);
  EXPECT_EQ(copy.last_inverse_block(), S.last_inverse_block());
  S.append_row();
  S.add(161, 161, Block::Identity());
  S.add(161, 0, random_block(rng));
  S.add(100, 100, -100.0 * Block::Identity());
  EXPECT_THROW(S.factorize(), numerical_error);
  EXPECT_EQ(S.rows(), 161u);
  EXPECT_EQ(S.solve(b), before);
  S.add(100, 100, Block::Identity());
  S.factorize();
  EXPECT_NE(S.solve(b), before);
  S.discard();
  EXPECT_EQ(S.solve(b), before);
}

}  // namespace
}  // namespace sextant
