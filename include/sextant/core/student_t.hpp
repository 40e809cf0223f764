#pragma once
/// \file Heavy-tailed measurement noise: a multivariate Student-t with nu degrees of freedom, i.e. a
/// Gaussian N(0, Q / lambda) whose precision scale lambda ~ Gamma(nu / 2, nu / 2) (Lange, Little and
/// Taylor 1989). Given an innovation of dimension d whose normalized square against its covariance S
/// is NIS, lambda's posterior mean is (nu + d) / (nu + NIS) (Roth, Oezkan and Gustafsson 2013): an
/// update with the noise Q (nu + NIS) / (nu + d) lets a gross outlier pull by a bounded amount, and
/// the t density, whose tails fall polynomially instead of exponentially, weighs it without ruling
/// out everything that explains it. nu -> infinity is the Gaussian.

#include <cmath>
#include <numbers>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"

namespace sextant {

struct StudentTNoise {
  double dof = 0.0;  ///< nu > 0; 0 = Gaussian noise

  bool on() const { return dof > 0.0; }
  /// dof must be 0 (off) or positive and finite; `what` names the option in the message.
  void validate(const std::string& what) const {
    if (!(dof >= 0.0) || !std::isfinite(dof))
      throw invalid_input_error(what + " must be 0 (Gaussian) or positive and finite, got " + std::to_string(dof));
  }
  /// 1 / E[lambda | innovation] = (nu + NIS) / (nu + d): the factor on the noise covariance Q of an
  /// update whose innovation has dimension d and normalized square nis; 1 for Gaussian noise.
  double noise_factor(double nis, int d) const { return on() ? (dof + nis) / (dof + static_cast<double>(d)) : 1.0; }
  /// log t_nu(nu; 0, S) = log Gamma((nu + d) / 2) - log Gamma(nu / 2) - d / 2 log(nu pi) - log det S / 2
  /// - (nu + d) / 2 log(1 + NIS / nu), from the innovation's NIS and the Cholesky factor of S;
  /// log N(nu; 0, S) for Gaussian noise.
  template <class Llt>
  double log_density_at_nis(const Llt& llt, double nis) const {
    if (!on()) return log_gaussian_at_nis(llt, nis);
    const double d = static_cast<double>(llt.rows());
    const double log_det = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
    return std::lgamma(0.5 * (dof + d)) - std::lgamma(0.5 * dof) - 0.5 * d * std::log(dof * std::numbers::pi) -
           0.5 * log_det - 0.5 * (dof + d) * std::log1p(nis / dof);
  }
};

}  // namespace sextant
