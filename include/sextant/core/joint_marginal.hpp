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

}  // namespace sextant
