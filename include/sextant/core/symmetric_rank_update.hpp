#pragma once
/// \file The symmetric rank-k update C <- alpha A^T A + beta C on C's upper triangle (BLAS's dsyrk):
/// SEIF's sparsification changes the links of all ~260 landmarks it touches by rank-X products
/// (X = 12 on the 12D camera, a ~780 x 780 triangle a frame at the thesis's scale). With
/// `sextant::lapack` linked (OpenBLAS, which picks the CPU's vector instructions when it is loaded;
/// core/dense_cholesky.hpp) triangles of kLapackMinDimension and more go to its dsyrk, otherwise,
/// and below, Eigen's rank update.

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

/// The upper triangle of the square C becomes alpha A^T A + beta C (A: k x n, C: n x n); C's strict
/// lower triangle is not touched. With beta == 0, C's upper triangle is not read (it may hold anything).
inline void symmetric_rank_update_upper(Eigen::Ref<Eigen::MatrixXd> C, const Eigen::Ref<const Eigen::MatrixXd>& A,
                                        double alpha, double beta) {
#ifdef SEXTANT_HAS_LAPACK
  constexpr Eigen::Index int_max = std::numeric_limits<int>::max();
  if (C.rows() >= kLapackMinDimension && C.outerStride() <= int_max && A.outerStride() <= int_max) {
    const char upper = 'U', transposed = 'T';
    const int n = static_cast<int>(C.rows()), k = static_cast<int>(A.rows());
    const int lda = static_cast<int>(std::max<Eigen::Index>(A.outerStride(), 1)),
              ldc = static_cast<int>(C.outerStride());
    dsyrk_(&upper, &transposed, &n, &k, &alpha, A.data(), &lda, &beta, C.data(), &ldc, 1, 1);
    return;
  }
#endif
  if (beta == 0.0)
    C.triangularView<Eigen::Upper>().setZero();
  else if (beta != 1.0)
    C.triangularView<Eigen::Upper>() *= beta;
  C.selfadjointView<Eigen::Upper>().rankUpdate(A.transpose(), alpha);
}

}  // namespace sextant
