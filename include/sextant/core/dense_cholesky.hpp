#pragma once
/// \file The dense Cholesky factorization of the large blocks, in place: SEIF's robot-and-active
/// block (about 790 dimensions in mean recovery at the thesis's scale, 462 after sparsification).
/// With `sextant::lapack` linked (OpenBLAS, which picks the CPU's vector instructions when it is
/// loaded) blocks of kLapackMinDimension and more go to LAPACK's dpotrf: 1.4x Eigen's LLT at 64
/// dimensions, 2x from 256 on, for a build without -march flags (docs/benchmarks.md). Otherwise,
/// and below that size, Eigen's blocked LLT.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cstddef>
#include <limits>

#include "sextant/core/blas_threads.hpp"

#ifdef SEXTANT_HAS_LAPACK
/// LAPACK's dpotrf with gfortran's calling convention (the length of `uplo` passed last).
extern "C" void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info,
                        std::size_t uplo_length);
/// BLAS's dtrsm, the same convention (the lengths of side, uplo, transa and diag passed last).
extern "C" void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m,
                       const int* n, const double* alpha, const double* a, const int* lda, double* b, const int* ldb,
                       std::size_t side_length, std::size_t uplo_length, std::size_t transa_length,
                       std::size_t diag_length);
#endif

namespace sextant {

/// The smallest block handed to LAPACK: below it the call costs what it saves (measured).
inline constexpr Eigen::Index kLapackMinDimension = 64;

/// Overwrites the lower triangle of the symmetric matrix a with its Cholesky factor L, a = L L^T;
/// the strict upper triangle is not touched. Returns false, with the lower triangle holding a
/// partial factor, when a is not positive definite. a must be finite.
inline bool factorize_lower_in_place(Eigen::Ref<Eigen::MatrixXd> a) {
#ifdef SEXTANT_HAS_LAPACK
  constexpr Eigen::Index int_max = std::numeric_limits<int>::max();
  if (a.rows() >= kLapackMinDimension && a.outerStride() <= int_max) {
    const char lower = 'L';
    const int n = static_cast<int>(a.rows()), lda = static_cast<int>(a.outerStride());
    int info = 0;
    dpotrf_(&lower, &n, a.data(), &lda, &info, 1);
    return info == 0;
  }
#endif
  return Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>>(a).info() == Eigen::Success;
}

/// b <- b L^-T in place, L the lower triangle of `factor` (a Cholesky factor: b L^-T = (L^-1 b^T)^T,
/// the EKF's W^T). With `sextant::lapack` linked and b of kLapackMinDimension rows or more, BLAS's
/// dtrsm: 7.4x Eigen's solve at the thesis's last globe frame (11,289 x 360, one core; docs/benchmarks.md),
/// and no transposed copy of b.
inline void right_solve_lower_transposed(Eigen::Ref<const Eigen::MatrixXd> factor, Eigen::Ref<Eigen::MatrixXd> b) {
#ifdef SEXTANT_HAS_LAPACK
  constexpr Eigen::Index int_max = std::numeric_limits<int>::max();
  if (b.rows() >= kLapackMinDimension && b.cols() > 0 && b.outerStride() <= int_max && factor.outerStride() <= int_max) {
    const char right = 'R', lower = 'L', transposed = 'T', non_unit = 'N';
    const int m = static_cast<int>(b.rows()), n = static_cast<int>(b.cols());
    const int lda = static_cast<int>(factor.outerStride()), ldb = static_cast<int>(b.outerStride());
    const double one = 1.0;
    dtrsm_(&right, &lower, &transposed, &non_unit, &m, &n, &one, factor.data(), &lda, b.data(), &ldb, 1, 1, 1, 1);
    return;
  }
#endif
  factor.transpose().triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(b);  // L^T: upper
}

/// The factor that factorize_lower_in_place left in the lower triangle of a matrix: solves with
/// L L^T and its squared pivots L_ii^2. Refers to that matrix, which must outlive it.
class LowerCholeskyFactor {
 public:
  explicit LowerCholeskyFactor(Eigen::Ref<const Eigen::MatrixXd> factor) : factor_(factor) {}

  /// (L L^T)^-1 b: forward substitution with L, then back substitution with L^T (b: one column or more).
  template <class Rhs>
  typename Rhs::PlainObject solve(const Eigen::MatrixBase<Rhs>& b) const {
    typename Rhs::PlainObject x = factor_.triangularView<Eigen::Lower>().solve(b);
    factor_.triangularView<Eigen::Lower>().transpose().solveInPlace(x);
    return x;
  }

  Eigen::VectorXd squared_pivots() const { return factor_.diagonal().array().square().matrix(); }

 private:
  Eigen::Ref<const Eigen::MatrixXd> factor_;
};

}  // namespace sextant
