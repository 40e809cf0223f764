#pragma once
/// \file Gaussian estimates and the small dense helpers every back-end uses.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

/// A Gaussian over a state whose tangent space has dimension N: mean and covariance.
template <class Mean, int N>
struct Gaussian {
  Mean mean;
  Eigen::Matrix<double, N, N> cov;
};

/// A landmark estimate: id, mean and covariance.
template <int M>
struct LandmarkEstimate {
  LandmarkId id;
  Eigen::Matrix<double, M, 1> mean;
  Eigen::Matrix<double, M, M> cov;
};

/// (A + A^T) / 2.
template <class Derived>
typename Derived::PlainObject symmetrized(const Eigen::MatrixBase<Derived>& a) {
  return 0.5 * (a + a.transpose());
}

/// Cholesky factor of a symmetric matrix; throws numerical_error naming `what` when the matrix
/// is not positive definite or not finite.
template <class Derived>
Eigen::LLT<typename Derived::PlainObject> cholesky_or_throw(const Eigen::MatrixBase<Derived>& a,
                                                            const std::string& what) {
  if (!a.allFinite()) throw numerical_error(what + " has NaN or Inf entries");
  Eigen::LLT<typename Derived::PlainObject> llt(a);
  if (llt.info() != Eigen::Success) throw numerical_error(what + " is not positive definite");
  return llt;
}

/// Squared Mahalanobis distance r^T A^-1 r given the Cholesky factor of A.
template <class Llt, class Derived>
double mahalanobis_squared(const Llt& llt, const Eigen::MatrixBase<Derived>& r) {
  return llt.matrixL().solve(r).squaredNorm();
}

}  // namespace sextant
