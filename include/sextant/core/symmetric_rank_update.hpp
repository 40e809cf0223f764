#pragma once
/// \file The symmetric rank-k update C <- alpha A^T A + beta C (or alpha A A^T + beta C) on one
/// triangle of C (BLAS's dsyrk): SEIF's sparsification changes the links of all ~260 landmarks it
/// touches by rank-X products (X = 12 on the 12D camera, a ~780 x 780 triangle a frame at the thesis's
/// scale), and the EKF's correction is P - W^T W with W the k observations' L^-1 (P H^T)^T (rank 360 on
/// an 11,289 x 11,289 triangle at that scale, W^T given as n x 360 columns). With `sextant::lapack`
/// linked (OpenBLAS, which picks the CPU's vector instructions when it is loaded;
/// core/dense_cholesky.hpp) triangles of kLapackMinDimension and more go to its dsyrk, otherwise, and
/// below, Eigen's rank update. dsyrk was 1.2-3.3x Eigen's with
/// OpenBLAS's AVX2 kernels and 1.2-6.8x with its AVX-512 ones for n from 70 to 6000 and k from 2 to
/// 360, 0.91-1.45x with its SSE3 ones (a build without -march flags; docs/benchmarks.md).

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <limits>

#include "sextant/core/dense_cholesky.hpp"

#ifdef SEXTANT_HAS_LAPACK
/// BLAS's dsyrk with gfortran's calling convention (the lengths of `uplo` and `trans` passed last).
extern "C" void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha,
                       const double* a, const int* lda, const double* beta, double* c, const int* ldc,
                       std::size_t uplo_length, std::size_t trans_length);
#endif

namespace sextant {

/// Which product of A a rank update adds: A^T A (A: k x n, its rows the k vectors) or A A^T (A: n x k,
/// its columns), BLAS's trans = 'T' or 'N'.
enum class RankUpdateOf { rows, columns };

/// The `UpLo` triangle (Eigen::Lower or Eigen::Upper) of the square C becomes alpha A^T A + beta C
/// (A: k x n; with Of = columns, alpha A A^T + beta C, A: n x k); C: n x n. The other strict triangle is
/// not touched. With beta == 0, C's `UpLo` triangle is not read (it may hold anything).
template <unsigned int UpLo, RankUpdateOf Of = RankUpdateOf::rows>
void symmetric_rank_update(Eigen::Ref<Eigen::MatrixXd> C, const Eigen::Ref<const Eigen::MatrixXd>& A, double alpha,
                           double beta) {
  static_assert(UpLo == Eigen::Lower || UpLo == Eigen::Upper, "symmetric_rank_update: Eigen::Lower or Eigen::Upper");
  constexpr bool of_rows = Of == RankUpdateOf::rows;
#ifdef SEXTANT_HAS_LAPACK
  constexpr Eigen::Index int_max = std::numeric_limits<int>::max();
  if (C.rows() >= kLapackMinDimension && C.outerStride() <= int_max && A.outerStride() <= int_max) {
    const char triangle = UpLo == Eigen::Lower ? 'L' : 'U', trans = of_rows ? 'T' : 'N';
    const int n = static_cast<int>(C.rows()), k = static_cast<int>(of_rows ? A.rows() : A.cols());
    const int lda = static_cast<int>(std::max<Eigen::Index>(A.outerStride(), 1)),
              ldc = static_cast<int>(C.outerStride());
    dsyrk_(&triangle, &trans, &n, &k, &alpha, A.data(), &lda, &beta, C.data(), &ldc, 1, 1);
    return;
  }
#endif
  if (beta == 0.0)
    C.triangularView<UpLo>().setZero();
  else if (beta != 1.0)
    C.triangularView<UpLo>() *= beta;
  if constexpr (of_rows)
    C.selfadjointView<UpLo>().rankUpdate(A.transpose(), alpha);
  else
    C.selfadjointView<UpLo>().rankUpdate(A, alpha);
}

}  // namespace sextant
