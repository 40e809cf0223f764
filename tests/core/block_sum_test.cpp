#include "sextant/core/block_sum.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "sextant/core/block_triplets.hpp"
#include "support/sparse_bit_identical.hpp"

namespace sextant {
namespace {

using Block = Eigen::Matrix<double, 6, 6>;

struct Contribution {
  std::size_t i, j;
  Block block;
};

/// Many contributions to a few blocks of a 40 x 40 block grid, with magnitudes spread over twelve
/// decades, so that a sum in another order than the triplets' lands on other bits.
std::vector<Contribution> contributions(std::mt19937& rng) {
  std::uniform_int_distribution<std::size_t> index(0, 39);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0), decade(-6.0, 6.0);
  std::vector<Contribution> out;
  for (int k = 0; k < 3000; ++k) {
    const std::size_t i = index(rng), j = std::min<std::size_t>(39, i + index(rng) % 4);
    out.push_back({i, j, Block(Block::NullaryExpr([&] { return mantissa(rng) * std::pow(10.0, decade(rng)); }))});
  }
  return out;
}

using test::bit_identical;

TEST(BlockSum, IsTheTripletAssemblyBitForBit) {
  std::mt19937 rng(7);
  const auto added = contributions(rng);
  BlockTriplets triplets;
  BlockSum<6> sum;
  for (const auto& [i, j, block] : added) {
    triplets.add(6 * static_cast<Eigen::Index>(i), 6 * static_cast<Eigen::Index>(j), block);
    sum.add(i, j, block);
  }
  EXPECT_LT(sum.blocks(), added.size() / 10) << "the contributions meet in few blocks";
  EXPECT_TRUE(bit_identical(sum.to_sparse(240, 240), triplets.to_sparse(240, 240)));

  BlockSum<6> reversed;  // the same contributions in the other order: the test can tell
  for (auto c = added.rbegin(); c != added.rend(); ++c) reversed.add(c->i, c->j, c->block);
  EXPECT_TRUE(sum.to_sparse(240, 240).isApprox(reversed.to_sparse(240, 240), 1e-12));
  EXPECT_FALSE(bit_identical(sum.to_sparse(240, 240), reversed.to_sparse(240, 240)));
}

TEST(BlockSum, SymmetricBlocksLandTransposed) {
  Block block = Block::Zero();
  block(0, 5) = 2.0;
  BlockSum<6> sum;
  sum.add_symmetric(1, 3, block);
  sum.add(3, 1, Block::Identity());
  const Eigen::MatrixXd dense = sum.to_sparse(24, 24);
  EXPECT_EQ(dense(6 + 0, 18 + 5), 2.0);
  EXPECT_EQ(dense(18 + 5, 6 + 0), 2.0);
  EXPECT_EQ(dense(18 + 2, 6 + 2), 1.0);
  EXPECT_EQ(dense.cwiseAbs().sum(), 2.0 + 2.0 + 6.0);
  EXPECT_EQ(sum.blocks(), 2u);
}

TEST(BlockSum, AnEmptySumIsTheZeroMatrix) {
  const Eigen::SparseMatrix<double> empty = BlockSum<6>{}.to_sparse(24, 18);
  EXPECT_EQ(empty.rows(), 24);
  EXPECT_EQ(empty.cols(), 18);
  EXPECT_EQ(empty.nonZeros(), 0);
}

TEST(BlockSum, ABlockBeyondTheMatrixsColumnsIsRefused) {
  BlockSum<6> sum;
  sum.add(0, 3, Eigen::Matrix<double, 6, 6>::Identity());  // columns 18-23 of an 18-column matrix
  EXPECT_THROW(sum.to_sparse(24, 18), std::out_of_range);
  EXPECT_EQ(sum.to_sparse(24, 24).nonZeros(), 36);
}

}  // namespace
}  // namespace sextant
