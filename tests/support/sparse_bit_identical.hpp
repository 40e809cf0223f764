#pragma once
// Two sparse matrices with the same pattern and the same bits in every entry.

#include <Eigen/SparseCore>

namespace sextant::test {

inline bool bit_identical(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
  for (Eigen::Index c = 0; c < a.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator x(a, c), y(b, c); x; ++x, ++y)
      if (!y || x.row() != y.row() || x.value() != y.value()) return false;
  return true;
}

}  // namespace sextant::test
