#pragma once
/// \file The joint Gaussian marginal of the robot and a chosen set of landmarks: what data
/// association and gating need from a back-end, whatever form (moments or information) it keeps.

#include <Eigen/Core>
#include <vector>

#include "sextant/core/observation.hpp"

namespace sextant {

template <class State, int M>
struct JointMarginal {
  State robot;                                          ///< robot mean
  std::vector<LandmarkId> ids;                          ///< the landmarks, in the order of `cov`
  std::vector<Eigen::Matrix<double, M, 1>> landmarks;   ///< their means
  Eigen::MatrixXd cov;  ///< (X + M k)^2: robot block first, then the landmarks in `ids` order

  /// First row of landmark i's block in `cov`.
  Eigen::Index offset(std::size_t i) const { return cov.rows() - M * static_cast<Eigen::Index>(ids.size() - i); }
};

/// The rows of the joint (robot, landmark blocks at `offsets`) in a stacked state whose robot block
/// comes first: 0 .. X-1, then offset .. offset+M-1 for each block in order.
template <int X, int M>
std::vector<Eigen::Index> joint_rows(const std::vector<Eigen::Index>& offsets) {
  std::vector<Eigen::Index> rows;
  rows.reserve(X + M * offsets.size());
  for (Eigen::Index r = 0; r < X; ++r) rows.push_back(r);
  for (const Eigen::Index offset : offsets)
    for (Eigen::Index r = 0; r < M; ++r) rows.push_back(offset + r);
  return rows;
}

/// One block of the innovation covariance of observations p and q, each linearized in the robot
/// (rows 0 .. X-1 of `cov`) and one landmark (rows a .. a+M-1 and b .. b+M-1):
/// H_p Sigma H_q^T, thesis eq. (15) without Q. Data association needs the cross blocks (p != q);
/// a gate needs the diagonal ones, to which it adds Q.
template <class CovP, class Jx, class Jm, class JxQ, class JmQ>
auto innovation_cross_block(const Eigen::MatrixBase<CovP>& cov, const Jx& J_x_p, const Jm& J_m_p, Eigen::Index a,
                            const JxQ& J_x_q, const JmQ& J_m_q, Eigen::Index b) {
  constexpr int Z = Jm::RowsAtCompileTime, M = Jm::ColsAtCompileTime;
  const Eigen::Index X = J_x_p.cols();
  Eigen::Matrix<double, Z, Z> out = J_x_p * cov.block(0, 0, X, X) * J_x_q.transpose() +
                                    J_x_p * cov.block(0, b, X, M) * J_m_q.transpose() +
                                    J_m_p * cov.block(a, 0, M, X) * J_x_q.transpose() +
                                    J_m_p * cov.block(a, b, M, M) * J_m_q.transpose();
  return out;
}

}  // namespace sextant
