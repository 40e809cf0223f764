#pragma once
/// \file The linear assignment problem: every row to a distinct column at the least total cost
/// (Kuhn-Munkres by shortest augmenting paths with dual potentials, O(rows² · columns) at worst).
/// Used where several measurements of one frame must each be explained by a different landmark.

#include <algorithm>
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "sextant/core/error.hpp"

namespace sextant {

/// The column of each row in a least-cost assignment of the rows to distinct columns (rows ≤
/// columns). `cost(i, j) = +inf` forbids the pair; nullopt when no complete assignment avoids every
/// forbidden pair. Throws invalid_input_error on NaN or -inf costs or more rows than columns.
inline std::optional<std::vector<std::size_t>> min_cost_assignment(const Eigen::MatrixXd& cost) {
  const auto rows = static_cast<std::size_t>(cost.rows()), cols = static_cast<std::size_t>(cost.cols());
  if (rows > cols) throw invalid_input_error("min_cost_assignment: more rows than columns");
  if (cost.array().isNaN().any() || (cost.array() == -std::numeric_limits<double>::infinity()).any())
    throw invalid_input_error("min_cost_assignment: a cost is NaN or -inf");
  constexpr double inf = std::numeric_limits<double>::infinity();
  const auto c = [&](std::size_t row, std::size_t col) {  // 1-based, as the potentials below
    return cost(static_cast<Eigen::Index>(row - 1), static_cast<Eigen::Index>(col - 1));
  };
  // Column 0 is a virtual start; row_of[j] is the (1-based) row matched to column j, 0 if none.
  std::vector<double> row_potential(rows + 1, 0.0), col_potential(cols + 1, 0.0), distance(cols + 1);
  std::vector<std::size_t> row_of(cols + 1, 0), previous(cols + 1, 0);
  std::vector<char> reached(cols + 1);
  for (std::size_t row = 1; row <= rows; ++row) {
    // Dijkstra over reduced costs from the new row until it reaches a free column.
    row_of[0] = row;
    std::size_t column = 0;
    std::fill(distance.begin(), distance.end(), inf);
    std::fill(reached.begin(), reached.end(), 0);
    do {
      reached[column] = 1;
      const std::size_t from = row_of[column];
      double step = inf;
      std::size_t next = 0;
      for (std::size_t j = 1; j <= cols; ++j) {
        if (reached[j]) continue;
        const double reduced = c(from, j) - row_potential[from] - col_potential[j];
        if (reduced < distance[j]) distance[j] = reduced, previous[j] = column;
        if (distance[j] < step) step = distance[j], next = j;
      }
      if (next == 0) return std::nullopt;  // every column left is forbidden to the rows reached
      for (std::size_t j = 0; j <= cols; ++j) {
        if (reached[j]) row_potential[row_of[j]] += step, col_potential[j] -= step;
        else distance[j] -= step;
      }
      column = next;
    } while (row_of[column] != 0);
    for (std::size_t before; column != 0; column = before)  // flip the matching along the path
      before = previous[column], row_of[column] = row_of[before];
  }
  std::vector<std::size_t> column_of(rows);
  for (std::size_t j = 1; j <= cols; ++j)
    if (row_of[j] != 0) column_of[row_of[j] - 1] = j - 1;
  return column_of;
}

}  // namespace sextant
