#pragma once
/// \file Landmarks of a dense (robot, landmarks) information block whose rows hold nothing but their
/// diagonal block W_u and their robot link Omega_ux (in SEIF, the landmarks an update has just
/// added), eliminated from Omega delta = r in closed form before the rest is factorized densely:
///   (Omega_xx - sum_u Omega_xu W_u^-1 Omega_ux) delta_x + Omega_xF delta_F = r_x - sum_u Omega_xu W_u^-1 r_u,
///   delta_u = W_u^-1 (r_u - Omega_ux delta_x).
/// Eliminating them changes only the robot's block (no fill), so the dense factorization is smaller
/// by their dimensions: at the globe's thesis scale ~90 of ~790, a third of the flops.
/// Squared pivots of a Cholesky factorization of the whole block follow without factorizing it:
/// ordered (them, robot, rest), W_u's and the dense factor's; ordered (robot, them, rest), the
/// robot's block's own, those of the Schur complement of the robot over them,
/// Sigma_UU = W_UU - Omega_Ux Omega_xx^-1 Omega_xU, and the dense factor's for the rest (the Schur
/// complement of robot and them over the rest does not depend on the order they are eliminated in).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant {

template <int X, int M>
class ClosedFormLandmarks {
 public:
  /// D: the block, robot first (X dimensions), then landmarks of M; only its lower triangle and
  /// diagonal blocks are read. `positions`: the first dimension of each landmark to eliminate,
  /// ascending; their rows of D must be zero outside the diagonal block and the robot's columns.
  /// Throws numerical_error naming `what` when one of their blocks is not finite or W_u not positive
  /// definite (then neither is D).
  ClosedFormLandmarks(Eigen::Ref<const Eigen::MatrixXd> D, const Eigen::VectorXd& r, std::vector<Eigen::Index> positions,
                      const std::string& what)
      : positions_(std::move(positions)),
        robot_information_(D.template topLeftCorner<X, X>()),
        robot_residual_(r.template head<X>()) {
    for (const Eigen::Index at : positions_) eliminate(D.template block<M, X>(at, 0), D.template block<M, M>(at, at), r.template segment<M>(at), what);
  }

  bool empty() const { return positions_.empty(); }
  /// Omega_xx - sum_u Omega_xu W_u^-1 Omega_ux and r_x - sum_u Omega_xu W_u^-1 r_u: the robot's block
  /// and residual for the dense factorization of the rest.
  const Eigen::Matrix<double, X, X>& robot_information() const { return robot_information_; }
  const Eigen::Matrix<double, X, 1>& robot_residual() const { return robot_residual_; }

  /// The dimensions of a d-dimensional block that are not theirs, ascending: the dense part.
  std::vector<Eigen::Index> dense_dimensions(Eigen::Index d) const {
    std::vector<Eigen::Index> out;
    out.reserve(static_cast<std::size_t>(d));
    auto next = positions_.begin();
    for (Eigen::Index i = 0; i < d; ++i) {
      if (next != positions_.end() && i == *next + M) ++next;
      if (next == positions_.end() || i < *next) out.push_back(i);
    }
    return out;
  }

  /// The lower triangle of D's dense part (rows and columns dense_dimensions(D.rows())) into the
  /// lower triangle of F, copied by the contiguous runs between the eliminated landmarks.
  void copy_dense_lower_triangle(Eigen::Ref<const Eigen::MatrixXd> D, Eigen::Ref<Eigen::MatrixXd> F) const {
    std::vector<std::pair<Eigen::Index, Eigen::Index>> runs;  // (first dimension, end) of each run in D
    Eigen::Index start = 0;
    for (const Eigen::Index at : positions_) {
      if (at > start) runs.emplace_back(start, at);
      start = at + M;
    }
    if (D.rows() > start) runs.emplace_back(start, D.rows());
    Eigen::Index column = 0;
    for (const auto& [column_start, column_end] : runs)
      for (Eigen::Index c = column_start; c < column_end; ++c, ++column) {
        Eigen::Index row = 0;
        for (const auto& [row_start, row_end] : runs) {
          const Eigen::Index first = std::max(row_start, c);
          if (first < row_end) F.col(column).segment(row + first - row_start, row_end - first) = D.col(c).segment(first, row_end - first);
          row += row_end - row_start;
        }
      }
  }

  /// Their delta_u = W_u^-1 (r_u - Omega_ux delta_x), into delta, once delta_x is in it.
  void back_substitute(Eigen::VectorXd& delta) const {
    for (std::size_t u = 0; u < positions_.size(); ++u)
      delta.template segment<M>(positions_[u]) = W_inv_r_[u] - W_inv_link_[u] * delta.template head<X>();
  }

  /// Their squared pivots in a factorization ordered (them, robot, rest): W_u's.
  void squared_pivots_first(Eigen::VectorXd& pivots) const {
    for (std::size_t u = 0; u < positions_.size(); ++u) pivots.template segment<M>(positions_[u]) = W_squared_pivots_[u];
  }
  /// Their squared pivots in a factorization ordered (robot, them, rest): Sigma_UU's, zero where it is
  /// not positive definite (nor then is D). O((M n)^3) for n of them.
  void squared_pivots_after_robot(Eigen::Ref<const Eigen::MatrixXd> D, Eigen::VectorXd& pivots) const {
    const auto n = static_cast<Eigen::Index>(positions_.size());
    if (n == 0) return;
    Eigen::MatrixXd links(X, M * n);  // Omega_xU
    for (Eigen::Index u = 0; u < n; ++u)
      links.template middleCols<M>(M * u) = D.template block<M, X>(positions_[u], 0).transpose();
    const Eigen::LLT<Eigen::Matrix<double, X, X>> robot(D.template topLeftCorner<X, X>());
    const Eigen::MatrixXd Z = robot.matrixL().solve(links);
    Eigen::MatrixXd sigma = -Z.transpose() * Z;
    for (Eigen::Index u = 0; u < n; ++u)
      sigma.template block<M, M>(M * u, M * u) += D.template block<M, M>(positions_[u], positions_[u]);
    const Eigen::LLT<Eigen::MatrixXd> llt(sigma);
    const bool positive_definite = robot.info() == Eigen::Success && llt.info() == Eigen::Success;
    for (Eigen::Index u = 0; u < n; ++u)
      pivots.template segment<M>(positions_[u]) =
          positive_definite ? Eigen::Matrix<double, M, 1>(llt.matrixLLT().diagonal().template segment<M>(M * u).array().square())
                            : Eigen::Matrix<double, M, 1>::Zero();
  }

 private:
  void eliminate(const Eigen::Matrix<double, M, X>& link, const Eigen::Matrix<double, M, M>& W,
                 const Eigen::Matrix<double, M, 1>& r_u, const std::string& what) {
    if (!link.allFinite() || !W.allFinite()) throw numerical_error(what + " has NaN or Inf entries");
    const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(W);
    if (llt.info() != Eigen::Success) throw numerical_error(what + " is not positive definite");
    W_inv_link_.push_back(llt.solve(link));
    W_inv_r_.push_back(llt.solve(r_u));
    W_squared_pivots_.push_back(llt.matrixLLT().diagonal().array().square().matrix());
    robot_information_ -= link.transpose() * W_inv_link_.back();
    robot_residual_ -= link.transpose() * W_inv_r_.back();
  }

  std::vector<Eigen::Index> positions_;
  Eigen::Matrix<double, X, X> robot_information_;
  Eigen::Matrix<double, X, 1> robot_residual_;
  std::vector<Eigen::Matrix<double, M, X>> W_inv_link_;  ///< W_u^-1 Omega_ux
  std::vector<Eigen::Matrix<double, M, 1>> W_inv_r_;     ///< W_u^-1 r_u
  std::vector<Eigen::Matrix<double, M, 1>> W_squared_pivots_;
};

}  // namespace sextant
