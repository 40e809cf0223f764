#include "sextant/core/closed_form_landmarks.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>
#include <random>
#include <vector>

namespace sextant {
namespace {

constexpr int X = 4, M = 2;  // a robot and landmarks of other sizes than any model's, to catch a mixed-up stride

/// An information block over (robot, `landmarks` landmarks): random factors, those of the landmarks
/// in `unlinked` joining them to the robot alone; positive definite.
Eigen::MatrixXd random_block(int landmarks, const std::vector<int>& unlinked, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  const int d = X + M * landmarks;
  std::vector<bool> alone(landmarks, false);
  for (int u : unlinked) alone[u] = true;
  Eigen::MatrixXd D = 0.1 * Eigen::MatrixXd::Identity(d, d);
  for (int factor = 0; factor < 8 * landmarks; ++factor) {
    const int a = static_cast<int>(rng() % landmarks), b = static_cast<int>(rng() % landmarks);
    Eigen::VectorXd j = Eigen::VectorXd::Zero(d);
    for (int i = 0; i < X; ++i) j(i) = normal(rng);
    for (int i = 0; i < M; ++i) j(X + M * a + i) = normal(rng);
    if (!alone[a] && !alone[b])
      for (int i = 0; i < M; ++i) j(X + M * b + i) += normal(rng);
    D += j * j.transpose();
  }
  return D;
}

std::vector<Eigen::Index> positions_of(const std::vector<int>& landmarks) {
  std::vector<Eigen::Index> out;
  for (int a : landmarks) out.push_back(X + M * a);
  return out;
}

/// Squared pivots of D's Cholesky factor in the order `order`, written back at D's own indices.
Eigen::VectorXd squared_pivots_in_order(const Eigen::MatrixXd& D, const std::vector<Eigen::Index>& order) {
  const Eigen::LLT<Eigen::MatrixXd> llt(D(order, order));
  EXPECT_EQ(llt.info(), Eigen::Success);
  Eigen::VectorXd out(D.rows());
  out(order) = llt.matrixLLT().diagonal().array().square().matrix();
  return out;
}

TEST(ClosedFormLandmarks, SolveEqualsTheDenseSolveAndPivotsThoseOfTheDenseFactorInBothOrders) {
  std::mt19937 rng(5);
  const std::vector<int> unlinked{0, 3, 4, 8};
  const Eigen::MatrixXd D = random_block(9, unlinked, rng);
  const Eigen::Index d = D.rows();
  const Eigen::VectorXd r = Eigen::VectorXd::Random(d);
  Eigen::MatrixXd lower_only = D;  // only the lower triangle and the diagonal blocks may be read
  lower_only.triangularView<Eigen::StrictlyUpper>().setConstant(std::numeric_limits<double>::quiet_NaN());
  for (int a = 0; a < 9; ++a) lower_only.block<M, M>(X + M * a, X + M * a) = D.block<M, M>(X + M * a, X + M * a);
  const ClosedFormLandmarks<X, M> closed(lower_only, r, positions_of(unlinked), "the test block");

  const std::vector<Eigen::Index> dense = closed.dense_dimensions(d);
  ASSERT_EQ(static_cast<Eigen::Index>(dense.size()), d - M * static_cast<Eigen::Index>(unlinked.size()));
  const auto n = static_cast<Eigen::Index>(dense.size());
  Eigen::MatrixXd F = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::quiet_NaN());
  closed.copy_dense_lower_triangle(lower_only, F);
  EXPECT_EQ(Eigen::MatrixXd(F.triangularView<Eigen::Lower>()), Eigen::MatrixXd(D(dense, dense).triangularView<Eigen::Lower>()));
  F = D(dense, dense);
  F.topLeftCorner<X, X>() = closed.robot_information();
  const Eigen::LLT<Eigen::MatrixXd> factor(F);
  Eigen::VectorXd r_dense = r(dense);
  r_dense.head<X>() = closed.robot_residual();
  Eigen::VectorXd delta(d);
  delta(dense) = Eigen::VectorXd(factor.solve(r_dense));
  closed.back_substitute(delta);
  const Eigen::VectorXd expected = D.llt().solve(r);
  EXPECT_LT((delta - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());

  std::vector<Eigen::Index> unlinked_dims, robot_dims, rest_dims;
  for (int u : unlinked)
    for (int i = 0; i < M; ++i) unlinked_dims.push_back(X + M * u + i);
  for (Eigen::Index i : dense) (i < X ? robot_dims : rest_dims).push_back(i);
  Eigen::VectorXd pivots(d);
  pivots(dense) = factor.matrixLLT().diagonal().array().square().matrix();
  {  // (them, robot, rest)
    Eigen::VectorXd first = pivots;
    closed.squared_pivots_first(first);
    std::vector<Eigen::Index> order = unlinked_dims;
    order.insert(order.end(), dense.begin(), dense.end());
    EXPECT_LT((first - squared_pivots_in_order(D, order)).cwiseAbs().maxCoeff(), 1e-10 * D.diagonal().maxCoeff());
  }
  {  // (robot, them, rest): the robot's own pivots come from its block alone
    Eigen::VectorXd after_robot = pivots;
    closed.squared_pivots_after_robot(lower_only, after_robot);
    after_robot.head<X>() = D.topLeftCorner<X, X>().llt().matrixLLT().diagonal().array().square().matrix();
    std::vector<Eigen::Index> order = robot_dims;
    order.insert(order.end(), unlinked_dims.begin(), unlinked_dims.end());
    order.insert(order.end(), rest_dims.begin(), rest_dims.end());
    EXPECT_LT((after_robot - squared_pivots_in_order(D, order)).cwiseAbs().maxCoeff(), 1e-10 * D.diagonal().maxCoeff());
  }
}

TEST(ClosedFormLandmarks, NamesABlockThatIsNotPositiveDefiniteOrNotFinite) {
  std::mt19937 rng(6);
  const Eigen::MatrixXd D = random_block(4, {1}, rng);
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(D.rows());
  const Eigen::Index at = X + M;
  Eigen::MatrixXd indefinite = D;
  indefinite.block<M, M>(at, at) = -Eigen::Matrix<double, M, M>::Identity();
  try {
    ClosedFormLandmarks<X, M>(indefinite, r, {at}, "the test block");
    FAIL() << "no throw";
  } catch (const numerical_error& e) {
    EXPECT_NE(std::string(e.what()).find("the test block is not positive definite"), std::string::npos) << e.what();
  }
  Eigen::MatrixXd with_nan = D;
  with_nan(at + 1, 2) = std::numeric_limits<double>::quiet_NaN();  // its robot link
  EXPECT_THROW((ClosedFormLandmarks<X, M>(with_nan, r, {at}, "the test block")), numerical_error);
  // With none to eliminate the robot's block and residual are the block's own.
  const ClosedFormLandmarks<X, M> none(D, r, {}, "the test block");
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(none.robot_information(), (D.topLeftCorner<X, X>()));
  EXPECT_EQ(static_cast<Eigen::Index>(none.dense_dimensions(D.rows()).size()), D.rows());
}

}  // namespace
}  // namespace sextant
