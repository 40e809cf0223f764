#include "sextant/core/min_cost_assignment.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <set>

#include <gtest/gtest.h>

namespace sextant {
namespace {

constexpr double kForbidden = std::numeric_limits<double>::infinity();

double total(const Eigen::MatrixXd& cost, const std::vector<std::size_t>& column_of) {
  double sum = 0.0;
  for (std::size_t i = 0; i < column_of.size(); ++i) sum += cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(column_of[i]));
  return sum;
}

/// The least total over every injective map of the rows to the columns (the oracle).
double least_total_by_enumeration(const Eigen::MatrixXd& cost) {
  std::vector<std::size_t> columns(static_cast<std::size_t>(cost.cols()));
  std::iota(columns.begin(), columns.end(), std::size_t{0});
  double best = kForbidden;
  do {  // every permutation; its first `rows` entries are one injective map (each seen several times)
    best = std::min(best, total(cost, std::vector<std::size_t>(columns.begin(), columns.begin() + cost.rows())));
  } while (std::next_permutation(columns.begin(), columns.end()));
  return best;
}

TEST(MinCostAssignment, EqualsEnumeratingEveryAssignment) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(0.0, 10.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Index rows = 1 + trial % 5, cols = rows + trial % 3;
    Eigen::MatrixXd cost(rows, cols);
    for (Eigen::Index i = 0; i < rows; ++i)
      for (Eigen::Index j = 0; j < cols; ++j) cost(i, j) = std::floor(uniform(rng));  // ties too
    const auto column_of = min_cost_assignment(cost);
    ASSERT_TRUE(column_of);
    EXPECT_EQ(std::set<std::size_t>(column_of->begin(), column_of->end()).size(), column_of->size()) << "trial " << trial;
    EXPECT_DOUBLE_EQ(total(cost, *column_of), least_total_by_enumeration(cost)) << "trial " << trial;
  }
}

TEST(MinCostAssignment, TheNearestOfTwoRowsMayHaveToYieldIt) {
  // Both rows are nearest to column 0; the least total gives it to row 1, whose other choice costs more.
  Eigen::MatrixXd cost(2, 3);
  cost << 0.1, 0.5, 9.0,
          0.2, 4.0, 9.0;
  EXPECT_EQ(*min_cost_assignment(cost), (std::vector<std::size_t>{1, 0}));
}

TEST(MinCostAssignment, ForbiddenPairsAreAvoidedOrReported) {
  Eigen::MatrixXd cost(3, 3);
  cost << 1.0, kForbidden, kForbidden,
          0.0, 5.0, kForbidden,
          0.0, 0.0, 7.0;
  EXPECT_EQ(*min_cost_assignment(cost), (std::vector<std::size_t>{0, 1, 2}));
  cost(2, 2) = kForbidden;  // column 2 is now forbidden to every row
  EXPECT_FALSE(min_cost_assignment(cost));
}

TEST(MinCostAssignment, BadCostsAndShapesAreRefused) {
  Eigen::MatrixXd cost = Eigen::MatrixXd::Zero(2, 2);
  cost(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(min_cost_assignment(cost), invalid_input_error);
  cost(1, 0) = -kForbidden;
  EXPECT_THROW(min_cost_assignment(cost), invalid_input_error);
  EXPECT_THROW(min_cost_assignment(Eigen::MatrixXd::Zero(3, 2)), invalid_input_error);
  EXPECT_EQ(min_cost_assignment(Eigen::MatrixXd(0, 4))->size(), 0u);
}

}  // namespace
}  // namespace sextant
