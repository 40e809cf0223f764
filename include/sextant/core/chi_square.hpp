#pragma once
/// \file Chi-square quantiles (Boost.Math) for gates and consistency bounds.

#include <boost/math/distributions/chi_squared.hpp>
#include <string>

#include "sextant/core/error.hpp"

namespace sextant {

/// The p-quantile of a chi-square distribution with `dof` degrees of freedom,
/// e.g. chi_square_quantile(2, 0.95) = 5.991 (thesis §4.3.1).
inline double chi_square_quantile(double dof, double p) {
  if (!(dof > 0.0) || !(p > 0.0 && p < 1.0))
    throw invalid_input_error("chi_square_quantile needs dof > 0 and 0 < p < 1, got dof=" + std::to_string(dof) +
                              " p=" + std::to_string(p));
  return boost::math::quantile(boost::math::chi_squared(dof), p);
}

}  // namespace sextant
