#include "sextant/core/symmetric_matrix.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace sextant {
namespace {

Eigen::MatrixXd random_spd(Eigen::Index n, unsigned seed) {
  std::srand(seed);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd S = A * A.transpose() + n * Eigen::MatrixXd::Identity(n, n);
  return 0.5 * (S + S.transpose());  // exactly symmetric
}

TEST(SymmetricBlocks, ReadFullColumnAndDiagonalBlocksFromTheLowerTriangle) {
  const Eigen::MatrixXd full = random_spd(9, 4);
  Eigen::MatrixXd lower = full.triangularView<Eigen::Lower>();
  for (Eigen::Index offset : {0, 3, 7}) {
    EXPECT_EQ(symmetric_column_block<2>(lower, offset), full.middleCols(offset, 2)) << offset;
    EXPECT_EQ(symmetric_diagonal_block<2>(lower, offset), full.block(offset, offset, 2, 2)) << offset;
  }
  mirror_lower_to_upper(lower);
  EXPECT_EQ(lower, full);
}

TEST(GrowableSquareMatrix, GrowKeepsContentAndZeroesTheNewBlock) {
  GrowableSquareMatrix m(2);
  m.view() << 1, 2, 3, 4;
  for (int i = 0; i < 20; ++i) m.grow(3);
  EXPECT_EQ(m.dim(), 62);
  EXPECT_EQ(m.view()(1, 0), 3.0);
  EXPECT_EQ(m.view().bottomRightCorner(60, 60).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(m.view().topRightCorner(2, 60).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LE(m.capacity(), 93);  // grows by half: never more than 1.5x the dimension
  m.reserve(200);
  EXPECT_EQ(m.capacity(), 200);
  EXPECT_EQ(m.view()(1, 0), 3.0);
}

TEST(GrowableSquareMatrix, RemovingABlockEqualsDeletingItsRowsAndColumnsAfterAPermutation) {
  const Eigen::MatrixXd full = random_spd(8, 3);
  GrowableSquareMatrix m(8);
  m.view() = full;
  m.remove_block_by_moving_last(2, 2);  // block [2,4) replaced by block [6,8)
  const std::vector<int> order{0, 1, 6, 7, 4, 5};
  ASSERT_EQ(m.dim(), 6);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) EXPECT_EQ(m.view()(r, c), full(order[r], order[c]));
}

}  // namespace
}  // namespace sextant
