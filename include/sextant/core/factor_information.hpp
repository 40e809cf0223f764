#pragma once
/// \file The one information accumulation of the back-ends in information form (SEIF's measurement
/// update, GraphSLAM's factors and its landmark marginalization): a Gaussian factor on two blocks
/// a and b says nu = A da + B db + v, v ~ N(0, C / w), and adds to the canonical form
/// Omega += [A B]^T W [A B], xi += [A B]^T W nu, W = w C^-1 (thesis eqs. 29-30 for SEIF, 60-63 for
/// GraphSLAM). The noise model factors C once (C = L L^T) and applies C^-1 through it; w is a robust
/// loss's weight rho'(s) at the factor's squared Mahalanobis norm s = nu^T C^-1 nu (iteratively
/// reweighted least squares, core/robust_kernel.hpp), 1 without one.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <string>

#include "sextant/core/robust_kernel.hpp"
#include "sextant/core/gaussian.hpp"

namespace sextant {

/// The blocks a factor adds: Omega_aa, Omega_ab, Omega_bb and xi_a, xi_b, with s = nu^T C^-1 nu.
template <int NA, int NB>
struct FactorInformation {
  Eigen::Matrix<double, NA, NA> aa;
  Eigen::Matrix<double, NA, NB> ab;
  Eigen::Matrix<double, NB, NB> bb;
  Eigen::Matrix<double, NA, 1> a;
  Eigen::Matrix<double, NB, 1> b;
  double squared_norm;  ///< s = nu^T C^-1 nu, before the weight
  double weight;        ///< w = rho'(s)
};

/// A factor's Gaussian noise of dimension D, factored once.
template <int D>
class GaussianNoise {
 public:
  using Matrix = Eigen::Matrix<double, D, D>;
  using Vector = Eigen::Matrix<double, D, 1>;

  /// Throws numerical_error naming `what` when C is not positive definite.
  GaussianNoise(const Matrix& C, const std::string& what) : llt_(cholesky_or_throw(C, what)) {}

  /// The information of a factor with innovation nu (measured minus predicted) and Jacobians A, B,
  /// weighted by loss.weight(s).
  template <int NA, int NB>
  FactorInformation<NA, NB> information(const Eigen::Matrix<double, D, NA>& A, const Eigen::Matrix<double, D, NB>& B,
                                        const Vector& nu, const RobustLoss& loss = {}) const {
    const Vector C_nu = llt_.solve(nu);
    const double s = nu.dot(C_nu);
    const double w = loss.weight(s);
    const Eigen::Matrix<double, D, NA> W_A = w * llt_.solve(A);
    const Eigen::Matrix<double, D, NB> W_B = w * llt_.solve(B);
    const Vector W_nu = w * C_nu;
    return {A.transpose() * W_A, A.transpose() * W_B, B.transpose() * W_B, A.transpose() * W_nu, B.transpose() * W_nu,
            s, w};
  }

  const Eigen::LLT<Matrix>& llt() const { return llt_; }

 private:
  Eigen::LLT<Matrix> llt_;
};

}  // namespace sextant
