#pragma once
/// \file Errors after rigid alignment (as evo's APE with --align): the rotation and translation
/// that best map the estimated points onto the true ones in least squares (Umeyama 1991, without
/// scale) are applied before the error is taken. This removes the gauge a SLAM estimate cannot
/// observe (where its frame is anchored: e.g. each FastSLAM particle's map hangs on its own sample
/// of the first pose) and leaves the error of the estimate's shape.

#include <Eigen/Core>
#include <Eigen/SVD>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant::eval {

/// A rigid transform y = R x + t in D dimensions.
template <int D>
struct RigidTransform {
  Eigen::Matrix<double, D, D> R = Eigen::Matrix<double, D, D>::Identity();
  Eigen::Matrix<double, D, 1> t = Eigen::Matrix<double, D, 1>::Zero();
  Eigen::Matrix<double, D, 1> operator()(const Eigen::Matrix<double, D, 1>& x) const { return R * x + t; }
};

/// The rotation and translation minimizing sum_i |R estimate_i + t - truth_i|^2. Needs at least
/// D points in general position; with fewer (or collinear ones in 3D) the rotation about the
/// degenerate direction is not determined and Umeyama's proper-rotation choice is returned.
template <int D>
RigidTransform<D> align_rigidly(const std::vector<Eigen::Matrix<double, D, 1>>& estimate,
                                const std::vector<Eigen::Matrix<double, D, 1>>& truth) {
  if (estimate.size() != truth.size()) throw invalid_input_error("align_rigidly: point sets of different sizes");
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = Eigen::Matrix<double, D, D>;
  RigidTransform<D> out;
  if (estimate.empty()) return out;
  const double n = static_cast<double>(estimate.size());
  Vector mean_e = Vector::Zero(), mean_t = Vector::Zero();
  for (std::size_t i = 0; i < estimate.size(); ++i) mean_e += estimate[i] / n, mean_t += truth[i] / n;
  Matrix cross = Matrix::Zero();  // sum (t_i - mean_t)(e_i - mean_e)^T
  for (std::size_t i = 0; i < estimate.size(); ++i) cross += (truth[i] - mean_t) * (estimate[i] - mean_e).transpose();
  const Eigen::JacobiSVD<Matrix> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix sign = Matrix::Identity();  // a proper rotation, not a reflection
  sign(D - 1, D - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  out.R = svd.matrixU() * sign * svd.matrixV().transpose();
  out.t = mean_t - out.R * mean_e;
  return out;
}

/// |T(estimate_i) - truth_i| for each i after the best rigid alignment T of the whole set.
template <int D>
std::vector<double> aligned_errors(const std::vector<Eigen::Matrix<double, D, 1>>& estimate,
                                   const std::vector<Eigen::Matrix<double, D, 1>>& truth) {
  const auto T = align_rigidly(estimate, truth);
  std::vector<double> out;
  out.reserve(estimate.size());
  for (std::size_t i = 0; i < estimate.size(); ++i) out.push_back((T(estimate[i]) - truth[i]).norm());
  return out;
}

}  // namespace sextant::eval
