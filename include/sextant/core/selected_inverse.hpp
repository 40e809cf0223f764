#pragma once
/// \file Entries of the inverse of a sparse SPD matrix on the pattern of its Cholesky factor
/// (Takahashi's selected inversion): every marginal covariance block of a SLAM problem from one
/// sparse LDL^T factorization, without forming the dense inverse.

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant {

class SelectedInverse {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;

  /// Factorizes A (symmetric positive definite; full or lower storage) with a fill-reducing
  /// ordering, then computes Z = A^-1 on the pattern of L. Throws numerical_error if A is not PD.
  explicit SelectedInverse(const SparseMatrix& A) : ldlt_(A) {
    if (ldlt_.info() != Eigen::Success) throw numerical_error("matrix to invert is not positive definite");
    const Eigen::VectorXd d = ldlt_.vectorD();
    if ((d.array() <= 0.0).any()) throw numerical_error("matrix to invert is not positive definite");
    compute(d);
  }

  Eigen::Index rows() const { return static_cast<Eigen::Index>(diagonal_.size()); }

  /// (A^-1)(r, c) in the original ordering; (r, c) must lie in the pattern of the factor, which
  /// holds for every entry stored in A. Store whole blocks (explicit zeros included) so that every
  /// marginal block can be read; throws numerical_error for an entry outside the pattern.
  double operator()(Eigen::Index r, Eigen::Index c) const {
    const Eigen::Index i = permutation_(r), j = permutation_(c);
    return entry(std::max(i, j), std::min(i, j));
  }

  /// The symmetric block of A^-1 on rows and columns [offset, offset + size).
  Eigen::MatrixXd block(Eigen::Index offset, Eigen::Index size) const {
    Eigen::MatrixXd out(size, size);
    for (Eigen::Index c = 0; c < size; ++c)
      for (Eigen::Index r = c; r < size; ++r) out(r, c) = out(c, r) = (*this)(offset + r, offset + c);
    return out;
  }

 private:
  using Factor = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>>;

  const SparseMatrix& L() const { return ldlt_.matrixL().nestedExpression(); }

  /// Position of L(i, j), i > j, in L's value array, or -1 when (i, j) is not in the pattern.
  Eigen::Index position(Eigen::Index i, Eigen::Index j) const {
    const auto* rows = L().innerIndexPtr();
    const auto* begin = rows + L().outerIndexPtr()[j];
    const auto* end = rows + L().outerIndexPtr()[j + 1];
    const auto* it = std::lower_bound(begin, end, static_cast<int>(i));
    return (it != end && *it == i) ? static_cast<Eigen::Index>(it - rows) : -1;
  }

  double entry(Eigen::Index i, Eigen::Index j) const {  // permuted indices, i >= j
    if (i == j) return diagonal_[i];
    const Eigen::Index p = position(i, j);
    if (p < 0)
      throw numerical_error("entry (" + std::to_string(i) + ", " + std::to_string(j) +
                            ") of the inverse is outside the factor's pattern");
    return off_diagonal_[p];
  }

  /// Takahashi: for j = n-1 .. 0, with P(j) the rows of column j of L,
  ///   Z_ij = -sum_{k in P(j)} L_kj Z_ki  (i in P(j)),   Z_jj = 1/d_j - sum_{k in P(j)} L_kj Z_kj.
  void compute(const Eigen::VectorXd& d) {
    const SparseMatrix& l = L();
    const Eigen::Index n = l.cols();
    diagonal_.assign(n, 0.0);
    off_diagonal_.assign(l.nonZeros(), 0.0);
    const auto* outer = l.outerIndexPtr();
    const auto* rows = l.innerIndexPtr();
    const double* values = l.valuePtr();
    for (Eigen::Index j = n - 1; j >= 0; --j) {
      const Eigen::Index first = outer[j], last = outer[j + 1];
      for (Eigen::Index a = first; a < last; ++a) {
        const Eigen::Index i = rows[a];
        double sum = 0.0;
        for (Eigen::Index b = first; b < last; ++b) {
          const Eigen::Index k = rows[b];
          sum += values[b] * entry(std::max(i, k), std::min(i, k));
        }
        off_diagonal_[a] = -sum;
      }
      double sum = 0.0;
      for (Eigen::Index b = first; b < last; ++b) sum += values[b] * off_diagonal_[b];
      diagonal_[j] = 1.0 / d[j] - sum;
    }
    permutation_ = ldlt_.permutationP().indices().cast<Eigen::Index>();
  }

  Factor ldlt_;
  std::vector<double> diagonal_, off_diagonal_;
  Eigen::Matrix<Eigen::Index, Eigen::Dynamic, 1> permutation_;
};

}  // namespace sextant
