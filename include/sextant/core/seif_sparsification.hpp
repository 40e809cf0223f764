#pragma once
/// \file SEIF sparsification (thesis eqs. 37-44, Appendix A; Thrun et al. 2004) as the change it
/// makes to the information matrix on the block B = (x, m+, m0): the robot x keeps its links to the
/// landmarks m+ and loses those to m0. The thesis writes the change as
///   Omega~ - Omega = Omega1 - Omega2 - D_Bx D_xx^-1 D_xB      (D = Omega_BB),
/// Omega1 = D with m0 marginalized, Omega2 = D with x and m0 marginalized: two Schur complements of
/// the whole dense block. With S = Omega1 on (x, m+) the quotient property of Schur complements gives
/// Omega2 = S_++ - S_+x S_xx^-1 S_x+, and every term but one cancels to a rank-X product:
///   xx: -D_x0 D_00^-1 D_0x        x+: -D_x0 D_00^-1 D_0+        x0: -D_x0 (the links dropped)
///   RR: -D_Rx D_xx^-1 D_xR  (+ S_+x S_xx^-1 S_x+ on ++),        R = (m+, m0),
/// S_xx = D_xx - D_x0 D_00^-1 D_0x, S_x+ = D_x+ - D_x0 D_00^-1 D_0+ (docs/derivations/seif_error_state.md).
/// Cost: one factorization of D_00 and O(|B|^2 X) products, against O(|B|^3) for the thesis's form;
/// D_++ is never read.

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "sextant/core/dense_cholesky.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/symmetric_rank_update.hpp"

namespace sextant {

/// The change of Omega on B; the x0 links are to be removed (their change is -D_x0).
template <int X>
struct SeifSparsificationChange {
  Eigen::Matrix<double, X, X> robot;  ///< on xx
  Eigen::MatrixXd robot_kept;         ///< on x+ (X x |m+|); the change on RR goes to the caller's matrix
  /// L_ii^2 of the Cholesky factor of S_xx, the robot block after sparsification: with the robot
  /// ordered first, the factor of the new (x, m+) block is [chol(S_xx), 0; S_+x chol(S_xx)^-T, L_++]
  /// with L_++ that of D_(x+)(x+) (both leave D_++ - D_+x D_xx^-1 D_x+ as the Schur complement).
  Eigen::Matrix<double, X, 1> robot_squared_pivots;
};

/// D_xx = Omega_xx; D_xR = Omega_{x, (m+, m0)}; D_0R = Omega_{m0, (m+, m0)} (the rows of the
/// landmarks to deactivate), whose last |m0| columns (D_00) are overwritten with their Cholesky
/// factor. The change on RR = (m+, m0) x (m+, m0) is written into the upper triangle of
/// `change_on_RR` (|R| x |R|, the caller's storage: at the thesis's scale a 5 MB matrix, which
/// allocated afresh every frame page-faulted for 7% of the run). Throws numerical_error, naming the
/// block, when D_00, S_xx or D_xx is not positive definite; `change_on_RR` is then unspecified.
template <int X>
SeifSparsificationChange<X> seif_sparsification_change(const Eigen::Matrix<double, X, X>& D_xx,
                                                       const Eigen::MatrixXd& D_xR, Eigen::Ref<Eigen::MatrixXd> D_0R,
                                                       Eigen::Ref<Eigen::MatrixXd> change_on_RR) {
  using MatrixX = Eigen::Matrix<double, X, X>;
  const Eigen::Index n_dropped = D_0R.rows(), n_kept = D_xR.cols() - n_dropped;
  const auto L_00 = cholesky_in_place_or_throw(D_0R.rightCols(n_dropped), "information of the landmarks to deactivate");
  const Eigen::MatrixXd Y = L_00.solve(D_xR.rightCols(n_dropped).transpose());  // D_00^-1 D_0x
  SeifSparsificationChange<X> out;
  out.robot = -D_xR.rightCols(n_dropped) * Y;
  out.robot_kept = -Y.transpose() * D_0R.leftCols(n_kept);
  const auto llt_S = cholesky_or_throw(MatrixX(symmetrized(D_xx + out.robot)),
                                       "information of the robot and the landmarks to deactivate");
  out.robot_squared_pivots = llt_S.matrixLLT().diagonal().array().square().matrix();
  const auto llt_xx = cholesky_or_throw(D_xx, "robot block of the information matrix");
  const Eigen::MatrixXd W = llt_xx.matrixL().solve(D_xR);                                    // -W^T W on RR
  const Eigen::MatrixXd V = llt_S.matrixL().solve(D_xR.leftCols(n_kept) + out.robot_kept);  // +V^T V on ++
  symmetric_rank_update<Eigen::Upper>(change_on_RR, W, -1.0, 0.0);
  symmetric_rank_update<Eigen::Upper>(change_on_RR.topLeftCorner(n_kept, n_kept), V, 1.0, 1.0);
  return out;
}

}  // namespace sextant
