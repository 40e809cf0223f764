#pragma once
/// \file Gaussian estimates and the small dense helpers every back-end uses.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "sextant/core/dense_cholesky.hpp"
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

/// A^-1 of a symmetric positive definite A from its Cholesky factor, made exactly symmetric.
template <class Matrix>
Matrix inverse_from_cholesky(const Eigen::LLT<Matrix>& llt) {
  const Matrix inverse = llt.solve(Matrix::Identity(llt.rows(), llt.cols()));
  return symmetrized(inverse);
}

/// A^-1 of a symmetric matrix that must be positive definite (cholesky_or_throw names `what`).
template <class Derived>
typename Derived::PlainObject inverse_of_spd_or_throw(const Eigen::MatrixBase<Derived>& a, const std::string& what) {
  return inverse_from_cholesky(cholesky_or_throw(a, what));
}

/// Whether the lower triangle of a square matrix (all that a Cholesky factorization reads) is finite.
template <class Derived>
bool lower_triangle_is_finite(const Eigen::MatrixBase<Derived>& a) {
  for (Eigen::Index j = 0; j < a.cols(); ++j)
    if (!a.col(j).tail(a.rows() - j).allFinite()) return false;
  return true;
}

/// cholesky_or_throw for a large dynamic block that is not needed afterwards: the lower triangle of
/// `a` (all that is read) is overwritten with its factor (core/dense_cholesky.hpp), which the
/// returned view refers to (no copy).
inline LowerCholeskyFactor cholesky_in_place_or_throw(Eigen::Ref<Eigen::MatrixXd> a, const std::string& what) {
  if (!lower_triangle_is_finite(a)) throw numerical_error(what + " has NaN or Inf entries");
  if (!factorize_lower_in_place(a)) throw numerical_error(what + " is not positive definite");
  return LowerCholeskyFactor(a);
}

/// Throws numerical_error naming `what` unless the symmetric matrix a is positive definite and
/// provably not numerically singular. a is scaled to unit diagonal (Cholesky does not care about
/// diagonal scaling, so the scaled condition is the one that counts) and factorized; its pivots
/// d_i = L_ii^2 lie in [lambda_min, lambda_max], so 1 / min d_i (the largest pivot is 1) is a lower
/// bound of its condition number. If that exceeds 1 / (20 n^(3/2) u), Higham's bound for Cholesky
/// to succeed (Accuracy and Stability of Numerical Algorithms, Thm 10.7), a is rejected. By
/// eigenvalue interlacing a principal block is never worse conditioned than the whole matrix,
/// so failing this on a block proves the whole matrix numerically singular; passing it proves
/// nothing, but nothing sound is cheaper (O(n^3 / 3) for the small blocks it is used on).
/// The test of require_well_conditioned on the pivots d_i = L_ii^2 / a_ii of a Cholesky factor L of
/// a (the pivots of a scaled to unit diagonal), for a caller that has factorized a already.
inline void require_well_conditioned_pivots(const Eigen::VectorXd& pivots, const std::string& what) {
  const double n = static_cast<double>(pivots.size());
  const double bound = 20.0 * n * std::sqrt(n) * Eigen::NumTraits<double>::epsilon();
  const double smallest_pivot = pivots.minCoeff();
  if (!(smallest_pivot > bound)) {
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, "its condition number is at least %.3g after scaling, above %.3g",
                  1.0 / smallest_pivot, 1.0 / bound);
    throw numerical_error(what + " is numerically singular (" + numbers + ")");
  }
}

/// require_well_conditioned on a matrix whose lower triangle (all that is read) it may overwrite
/// (with its scaled Cholesky factor), for a large block that is not needed afterwards: no copy.
template <class Derived>
void require_well_conditioned_in_place(Eigen::MatrixBase<Derived>& a, const std::string& what) {
  using Plain = typename Derived::PlainObject;
  if (!lower_triangle_is_finite(a)) throw numerical_error(what + " has NaN or Inf entries");
  if (!(a.diagonal().array() > 0.0).all()) throw numerical_error(what + " is not positive definite");
  const Eigen::VectorXd scale = a.diagonal().array().rsqrt().matrix();
  a.template triangularView<Eigen::Lower>() = scale.asDiagonal() * a * scale.asDiagonal();
  bool positive_definite = false;
  if constexpr (Derived::RowsAtCompileTime == Eigen::Dynamic) {
    positive_definite = factorize_lower_in_place(a.derived());
  } else {
    Eigen::Ref<Plain> scaled(a.derived());
    positive_definite = Eigen::LLT<Eigen::Ref<Plain>>(scaled).info() == Eigen::Success;  // factorizes in place
  }
  if (!positive_definite) throw numerical_error(what + " is not positive definite");
  require_well_conditioned_pivots(a.diagonal().array().square().matrix(), what);
}

template <class Derived>
void require_well_conditioned(const Eigen::MatrixBase<Derived>& a, const std::string& what) {
  typename Derived::PlainObject copy = a;
  require_well_conditioned_in_place(copy, what);
}

/// Squared Mahalanobis distance r^T A^-1 r given the Cholesky factor of A.
template <class Llt, class Derived>
double mahalanobis_squared(const Llt& llt, const Eigen::MatrixBase<Derived>& r) {
  return llt.matrixL().solve(r).squaredNorm();
}

/// log N(nu; 0, S) = -(NIS + log det S + n log 2 pi) / 2 for an innovation whose NIS
/// nu^T S^-1 nu is `nis`, given the Cholesky factor of S.
template <class Llt>
double log_gaussian_at_nis(const Llt& llt, double nis) {
  const double log_det = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  return -0.5 * (nis + log_det + static_cast<double>(llt.rows()) * std::log(2.0 * std::numbers::pi));
}

/// log N(nu; 0, S) given the Cholesky factor of S.
template <class Llt, class Derived>
double log_gaussian(const Llt& llt, const Eigen::MatrixBase<Derived>& nu) {
  return log_gaussian_at_nis(llt, mahalanobis_squared(llt, nu));
}

}  // namespace sextant
