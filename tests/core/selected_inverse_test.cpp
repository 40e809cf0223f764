#include "sextant/core/selected_inverse.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace sextant {
namespace {

/// A chain of 2x2 blocks (like poses with odometry) plus a few long-range links (loop closures).
Eigen::SparseMatrix<double> chain_with_loops(int blocks, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * blocks, 2 * blocks);
  auto link = [&](int a, int b) {
    Eigen::Matrix2d J;
    J << u(rng), u(rng), u(rng), u(rng);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, 2 * blocks);
    H.block<2, 2>(0, 2 * a) = Eigen::Matrix2d::Identity();
    H.block<2, 2>(0, 2 * b) = -J;
    A += H.transpose() * H;
  };
  for (int k = 0; k + 1 < blocks; ++k) link(k, k + 1);
  for (int k = 0; k + 7 < blocks; k += 5) link(k, k + 7);
  A.block<2, 2>(0, 0) += Eigen::Matrix2d::Identity();
  // Whole 2x2 blocks are stored wherever a block is non-zero (explicit zeros included), as the
  // back-ends assemble their information matrices.
  std::vector<Eigen::Triplet<double>> triplets;
  for (int a = 0; a < blocks; ++a)
    for (int b = 0; b < blocks; ++b)
      if (A.block<2, 2>(2 * a, 2 * b).cwiseAbs().maxCoeff() > 0.0)
        for (int r = 0; r < 2; ++r)
          for (int c = 0; c < 2; ++c) triplets.emplace_back(2 * a + r, 2 * b + c, A(2 * a + r, 2 * b + c));
  Eigen::SparseMatrix<double> out(2 * blocks, 2 * blocks);
  out.setFromTriplets(triplets.begin(), triplets.end());
  return out;
}

TEST(SelectedInverse, DiagonalAndNeighbourBlocksEqualTheDenseInverse) {
  const auto A = chain_with_loops(40, 1);
  const Eigen::MatrixXd dense_inverse = Eigen::MatrixXd(A).inverse();
  const SelectedInverse Z(A);
  for (int k = 0; k < 40; ++k) {
    EXPECT_LT((Z.block(2 * k, 2) - dense_inverse.block(2 * k, 2 * k, 2, 2)).cwiseAbs().maxCoeff(), 1e-9) << k;
    if (k + 1 < 40) {
      EXPECT_NEAR(Z(2 * k, 2 * k + 2), dense_inverse(2 * k, 2 * k + 2), 1e-9) << k;
    }
  }
}

TEST(SelectedInverse, RejectsIndefiniteMatrices) {
  Eigen::SparseMatrix<double> A = chain_with_loops(5, 2);
  A.coeffRef(3, 3) = -100.0;
  EXPECT_THROW(SelectedInverse{A}, numerical_error);
}

}  // namespace
}  // namespace sextant
