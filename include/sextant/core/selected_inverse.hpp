#pragma once
/// \file Entries of the inverse of a sparse SPD matrix: every marginal covariance block of a SLAM
/// problem from one factorization. While the Cholesky factor stays sparse, Takahashi's selected
/// inversion on the factor's pattern (no dense inverse is formed); when it fills in (visual SLAM:
/// every landmark seen from ~100 poses couples those poses) a dense blocked inverse factor, whose
/// BLAS-3 kernels beat the sparse recursion's scattered look-ups by far. The choice is made before
/// any numeric factorization, from the factor's column counts (docs/design_notes.md).

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant {

class SelectedInverse {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;
  enum class Method { automatic, sparse, dense };

  /// Largest dimension the dense method takes on its own (one n x n matrix of doubles is 2 GiB here).
  static constexpr Eigen::Index dense_limit = 16384;
  /// Cost of one of the sparse method's look-ups (a binary search in a column of the factor, with
  /// the sparse factorization's share) in flops of the dense method: 125-144 measured on GraphSLAM's
  /// globe information matrices of 882-2136 dimensions (BM_GlobeGraphMarginals, docs/benchmarks.md),
  /// rounded down so that a close call keeps the sparse method and its smaller memory.
  static constexpr double lookup_cost_in_flops = 100.0;

  /// Factorizes A (symmetric positive definite; full or lower storage). automatic takes the
  /// method with the smaller predicted work (dense only up to dense_limit). Throws numerical_error
  /// if A is not positive definite.
  explicit SelectedInverse(const SparseMatrix& A, Method method = Method::automatic) {
    if (A.rows() != A.cols()) throw invalid_input_error("selected inverse of a non-square matrix");
    std::optional<Ordered> ordered;  // the AMD ordering, computed once for the choice and the factor
    if (method != Method::dense) ordered = fill_reducing_permuted(A);
    if (method == Method::automatic) method = method_for(*ordered);
    method_ = method;
    if (method == Method::dense)
      invert_densely(A);
    else
      invert_sparsely(*ordered);
  }

  Eigen::Index rows() const { return n_; }
  /// The method used (never automatic).
  Method method() const { return method_; }

  /// (A^-1)(r, c) in the original ordering. The sparse method has the entries on the pattern of
  /// its factor, which holds every entry stored in A (store whole blocks, explicit zeros included,
  /// so that every marginal block can be read); it throws numerical_error for an entry outside.
  /// The dense method has every entry.
  double operator()(Eigen::Index r, Eigen::Index c) const {
    if (method_ == Method::dense) return dense_entry(r, c);
    const Eigen::Index i = permutation_(r), j = permutation_(c);
    return entry(std::max(i, j), std::min(i, j));
  }

  /// The symmetric block of A^-1 on rows and columns [offset, offset + size).
  Eigen::MatrixXd block(Eigen::Index offset, Eigen::Index size) const {
    if (method_ == Method::dense) {  // A^-1 = L^-T L^-1, L^-1 lower triangular
      const auto columns = inverse_factor_.block(offset, offset, n_ - offset, size);
      const Eigen::MatrixXd product = columns.transpose() * columns;
      return 0.5 * (product + product.transpose());  // exactly symmetric, as the sparse method's
    }
    Eigen::MatrixXd out(size, size);
    for (Eigen::Index c = 0; c < size; ++c)
      for (Eigen::Index r = c; r < size; ++r) out(r, c) = out(c, r) = (*this)(offset + r, offset + c);
    return out;
  }

  /// The method `automatic` takes for A: dense when Takahashi's recursion would do more work (one
  /// look-up per pair of entries in a column of the factor) than the dense method's ~2/3 n^3 flops
  /// (factorization and triangular inverse), and n <= dense_limit. Costs one symbolic analysis.
  static Method automatic_method(const SparseMatrix& A) { return method_for(fill_reducing_permuted(A)); }

  /// Off-diagonal entries in each column of the Cholesky factor of P A P^T, P the fill-reducing
  /// (AMD) ordering the sparse method uses: the elimination tree walked row by row (each row of
  /// the factor is the union of the tree paths from the row's entries in A up to the diagonal).
  static std::vector<Eigen::Index> factor_column_counts(const SparseMatrix& A) {
    return column_counts(fill_reducing_permuted(A).C);
  }

 private:
  /// A symmetric matrix in the AMD ordering: C = P A P^T, its upper triangle stored (as Eigen's
  /// SimplicialLDLT stores it after its own ordering, so that the factor is the same to the bit).
  struct Ordered {
    SparseMatrix C;
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P;
  };
  /// The factor's column counts of an ordered matrix (factor_column_counts).
  static std::vector<Eigen::Index> column_counts(const SparseMatrix& C) {
    const Eigen::Index n = C.cols();
    std::vector<Eigen::Index> parent(n, -1), tag(n, -1), count(n, 0);
    for (Eigen::Index k = 0; k < n; ++k) {
      tag[k] = k;
      for (SparseMatrix::InnerIterator it(C, k); it; ++it) {
        for (Eigen::Index i = it.index(); i < k && tag[i] != k; i = parent[i]) {
          if (parent[i] == -1) parent[i] = k;
          ++count[i];
          tag[i] = k;
        }
      }
    }
    return count;
  }

  /// The automatic choice for an ordered matrix (automatic_method).
  static Method method_for(const Ordered& ordered) {
    const Eigen::Index n = ordered.C.rows();
    if (n > dense_limit) return Method::sparse;
    double sparse_work = 0.0;
    for (Eigen::Index count : column_counts(ordered.C)) sparse_work += static_cast<double>(count) * static_cast<double>(count);
    const double dense_work = 2.0 / 3.0 * static_cast<double>(n) * static_cast<double>(n) * static_cast<double>(n);
    return lookup_cost_in_flops * sparse_work > dense_work ? Method::dense : Method::sparse;
  }

  /// The factor of the ordered matrix: its ordering is AMD's, computed once (fill_reducing_permuted),
  /// so the factorization keeps it as it is.
  using Factor = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Upper, Eigen::NaturalOrdering<int>>;

  static Ordered fill_reducing_permuted(const SparseMatrix& A) {
    const SparseMatrix full = A.selfadjointView<Eigen::Lower>();
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse;
    Eigen::AMDOrdering<int>()(full, inverse);
    // AMD gives the inverse permutation; a permutation's inverse is its transpose (an exact
    // re-indexing, no arithmetic). This is the permutation Eigen's SimplicialLDLT with AMD ordering
    // computes and applies itself.
    Ordered out;
    out.P = inverse.transpose();
    out.C.resize(A.rows(), A.cols());
    out.C.selfadjointView<Eigen::Upper>() = A.selfadjointView<Eigen::Lower>().twistedBy(out.P);
    return out;
  }

  static void throw_not_positive_definite() { throw numerical_error("matrix to invert is not positive definite"); }

  // ---- dense: A = L L^T, keep L^-1 --------------------------------------------------------------

  void invert_densely(const SparseMatrix& A) {
    n_ = A.rows();
    Eigen::MatrixXd factor = Eigen::MatrixXd::Zero(n_, n_);  // the lower triangle is all LLT reads
    for (Eigen::Index c = 0; c < A.outerSize(); ++c)
      for (SparseMatrix::InnerIterator it(A, c); it; ++it)
        if (it.row() >= it.col()) factor(it.row(), it.col()) = it.value();
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(factor);  // in place
    if (llt.info() != Eigen::Success) throw_not_positive_definite();
    const auto diagonal = factor.diagonal();
    if (!diagonal.allFinite() || (diagonal.array() <= 0.0).any()) throw_not_positive_definite();
    // L^-1 by column blocks: column block [j, j + b) of L^-1 is zero above row j, so it solves the
    // trailing triangle only (n^3 / 3 flops in all).
    constexpr Eigen::Index block_size = 256;
    inverse_factor_ = Eigen::MatrixXd::Zero(n_, n_);
    for (Eigen::Index j = 0; j < n_; j += block_size) {
      const Eigen::Index b = std::min(block_size, n_ - j);
      auto columns = inverse_factor_.block(j, j, n_ - j, b);
      columns.topRows(b).setIdentity();
      factor.bottomRightCorner(n_ - j, n_ - j).triangularView<Eigen::Lower>().solveInPlace(columns);
    }
    if (!inverse_factor_.allFinite()) throw_not_positive_definite();
  }

  double dense_entry(Eigen::Index r, Eigen::Index c) const {
    const Eigen::Index from = std::max(r, c);
    return inverse_factor_.col(r).tail(n_ - from).dot(inverse_factor_.col(c).tail(n_ - from));
  }

  // ---- sparse: Takahashi on the pattern of the LDL^T factor --------------------------------------

  void invert_sparsely(const Ordered& ordered) {
    ldlt_.emplace(ordered.C);
    if (ldlt_->info() != Eigen::Success) throw_not_positive_definite();
    const Eigen::VectorXd d = ldlt_->vectorD();
    if ((d.array() <= 0.0).any()) throw_not_positive_definite();
    n_ = ordered.C.rows();
    permutation_ = ordered.P.indices().cast<Eigen::Index>();
    compute(d);
  }

  const SparseMatrix& L() const { return ldlt_->matrixL().nestedExpression(); }

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
  }

  Method method_ = Method::sparse;
  Eigen::Index n_ = 0;
  std::optional<Factor> ldlt_;
  std::vector<double> diagonal_, off_diagonal_;
  Eigen::Matrix<Eigen::Index, Eigen::Dynamic, 1> permutation_;
  Eigen::MatrixXd inverse_factor_;  ///< dense method: L^-1
};

}  // namespace sextant
