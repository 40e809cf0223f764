#pragma once
// SEIF sparsification two ways on a dense block D over (x, m+, m0): as the thesis writes it (eqs.
// 39-43: two Schur complements of the whole block) and through core/seif_sparsification.hpp, both
// as the full change of D.

#include <Eigen/Dense>
#include <vector>

#include "sextant/core/seif_sparsification.hpp"

namespace sextant::test {

/// D with the indices `eliminate` marginalized out, zero on their rows and columns.
inline Eigen::MatrixXd marginalized(const Eigen::MatrixXd& D, const std::vector<Eigen::Index>& eliminate) {
  std::vector<bool> gone(D.rows(), false);
  for (Eigen::Index i : eliminate) gone[i] = true;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < D.rows(); ++i)
    if (!gone[i]) keep.push_back(i);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(D.rows(), D.cols());
  out(keep, keep) = D(keep, keep) - D(keep, eliminate) * D(eliminate, eliminate).llt().solve(D(eliminate, keep));
  return out;
}

/// Omega1 - Omega2 - D_Bx D_xx^-1 D_xB, the thesis's change, for x of size X and m+ of n_kept rows.
inline Eigen::MatrixXd thesis_sparsification_change(const Eigen::MatrixXd& D, Eigen::Index X, Eigen::Index n_kept) {
  std::vector<Eigen::Index> robot, dropped;
  for (Eigen::Index i = 0; i < X; ++i) robot.push_back(i);
  for (Eigen::Index i = X + n_kept; i < D.rows(); ++i) dropped.push_back(i);
  std::vector<Eigen::Index> robot_and_dropped = robot;
  robot_and_dropped.insert(robot_and_dropped.end(), dropped.begin(), dropped.end());
  const Eigen::MatrixXd D_xB = D.topRows(X);
  return marginalized(D, dropped) - marginalized(D, robot_and_dropped) -
         D_xB.transpose() * D.topLeftCorner(X, X).llt().solve(D_xB);
}

/// The change seif_sparsification_change describes, written out as a matrix over B.
template <int X>
Eigen::MatrixXd sparsification_change_as_matrix(const Eigen::MatrixXd& D, Eigen::Index n_kept) {
  const Eigen::Index n_R = D.rows() - X, n_dropped = n_R - n_kept;
  Eigen::MatrixXd D_0R = D.bottomRightCorner(n_dropped, n_R), change_on_RR(n_R, n_R);
  const auto change = seif_sparsification_change<X>(D.topLeftCorner<X, X>(), D.topRightCorner(X, n_R), D_0R, change_on_RR);
  Eigen::MatrixXd out(D.rows(), D.cols());
  out.topLeftCorner<X, X>() = change.robot;
  out.block(0, X, X, n_kept) = change.robot_kept;
  out.topRightCorner(X, n_dropped) = -D.topRightCorner(X, n_dropped);  // the links dropped
  out.bottomLeftCorner(n_R, X) = out.topRightCorner(X, n_R).transpose();
  out.bottomRightCorner(n_R, n_R) = change_on_RR.selfadjointView<Eigen::Upper>();  // its upper triangle
  return out;
}

}  // namespace sextant::test
