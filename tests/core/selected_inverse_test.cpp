#include "sextant/core/selected_inverse.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <utility>
#include <vector>

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
  for (auto method : {SelectedInverse::Method::sparse, SelectedInverse::Method::dense})
    EXPECT_THROW((SelectedInverse{A, method}), numerical_error);
}

/// Visual SLAM's shape: a chain of 6-dim poses and 3-dim points each seen from a long run of
/// consecutive poses, so that the factor fills in.
Eigen::SparseMatrix<double> poses_and_covisible_points(int poses, int points, int seen_from, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  const int dim = 6 * poses + 3 * points;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(dim, dim);
  auto factor = [&](const std::vector<std::pair<int, int>>& blocks, int rows) {  // (offset, size)
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(rows, dim);
    for (const auto& [offset, size] : blocks)
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < size; ++c) H(r, offset + c) = n01(rng);
    A += H.transpose() * H;
  };
  factor({{0, 6}}, 6);
  for (int k = 0; k + 1 < poses; ++k) factor({{6 * k, 6}, {6 * (k + 1), 6}}, 6);
  for (int j = 0; j < points; ++j) {
    const int first = (j * (poses - seen_from)) / std::max(points - 1, 1);
    for (int k = first; k < first + seen_from; ++k) factor({{6 * k, 6}, {6 * poses + 3 * j, 3}}, 2);
  }
  Eigen::SparseMatrix<double> out = A.sparseView(0.0, 0.0);  // every block the factors touch
  return out;
}

TEST(SelectedInverse, DenseMethodHasEveryEntryOfTheInverse) {
  const auto A = chain_with_loops(40, 3);
  const Eigen::MatrixXd dense_inverse = Eigen::MatrixXd(A).inverse();
  const SelectedInverse Z(A, SelectedInverse::Method::dense);
  EXPECT_EQ(Z.method(), SelectedInverse::Method::dense);
  for (int r = 0; r < 80; r += 7)
    for (int c = 0; c < 80; c += 5) EXPECT_NEAR(Z(r, c), dense_inverse(r, c), 1e-9 * dense_inverse.cwiseAbs().maxCoeff());
  for (int k = 0; k + 3 <= 80; k += 3) {
    const Eigen::MatrixXd block = Z.block(k, 3);
    EXPECT_LT((block - dense_inverse.block(k, k, 3, 3)).cwiseAbs().maxCoeff(), 1e-9) << k;
    EXPECT_EQ(block, block.transpose()) << "a marginal covariance block is exactly symmetric";
  }
}

TEST(SelectedInverse, BothMethodsGiveTheSameMarginalsOnAFilledInProblem) {
  // 300 columns of the dense method's inverse factor span two of its 256-column blocks.
  const auto A = poses_and_covisible_points(40, 30, 12, 4);
  const SelectedInverse sparse(A, SelectedInverse::Method::sparse), dense(A, SelectedInverse::Method::dense);
  const Eigen::MatrixXd dense_inverse = Eigen::MatrixXd(A).inverse();
  const double scale = dense_inverse.diagonal().maxCoeff();
  for (int p = 0; p < 40; ++p) {
    EXPECT_LT((sparse.block(6 * p, 6) - dense_inverse.block(6 * p, 6 * p, 6, 6)).cwiseAbs().maxCoeff(), 1e-9 * scale) << p;
    EXPECT_LT((dense.block(6 * p, 6) - dense_inverse.block(6 * p, 6 * p, 6, 6)).cwiseAbs().maxCoeff(), 1e-9 * scale) << p;
  }
  for (int j = 0; j < 30; ++j) {
    const int at = 240 + 3 * j;
    EXPECT_LT((dense.block(at, 3) - sparse.block(at, 3)).cwiseAbs().maxCoeff(), 1e-9 * scale) << j;
  }
}

TEST(SelectedInverse, ColumnCountsAreThoseOfTheSparseFactor) {
  for (const auto& A : {chain_with_loops(60, 5), poses_and_covisible_points(30, 20, 8, 6)}) {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt(A);
    ASSERT_EQ(ldlt.info(), Eigen::Success);
    const Eigen::SparseMatrix<double>& L = ldlt.matrixL().nestedExpression();
    const auto counts = SelectedInverse::factor_column_counts(A);
    ASSERT_EQ(static_cast<Eigen::Index>(counts.size()), L.cols());
    for (Eigen::Index j = 0; j < L.cols(); ++j)
      EXPECT_EQ(counts[j], L.outerIndexPtr()[j + 1] - L.outerIndexPtr()[j]) << j;
  }
}

TEST(SelectedInverse, AutomaticTakesTheSparseMethodForAChainAndTheDenseOneWhenTheFactorFillsIn) {
  EXPECT_EQ(SelectedInverse(chain_with_loops(200, 7)).method(), SelectedInverse::Method::sparse);
  const auto filled_in = poses_and_covisible_points(60, 80, 40, 8);
  EXPECT_EQ(SelectedInverse::automatic_method(filled_in), SelectedInverse::Method::dense);
  EXPECT_EQ(SelectedInverse(filled_in).method(), SelectedInverse::Method::dense);
}

}  // namespace
}  // namespace sextant
