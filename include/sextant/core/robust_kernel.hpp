#pragma once
/// \file Robust kernels for least squares (Huber 1964; Cauchy/Lorentzian), applied by iteratively
/// reweighted least squares: a factor with squared whitened residual s = r^T W r costs rho(s)
/// instead of s, and Gauss-Newton uses the weight rho'(s) on its information (Triggs et al.,
/// Bundle Adjustment, §6.8). An outlier's pull is bounded (Huber) or fades (Cauchy) instead of
/// growing with its residual.

#include <cmath>
#include <string>

#include "sextant/core/error.hpp"

namespace sextant {

enum class RobustKernel {
  none,    ///< rho(s) = s
  huber,   ///< rho(s) = s for s <= k^2, 2 k sqrt(s) - k^2 beyond: quadratic core, linear tails
  cauchy,  ///< rho(s) = k^2 log(1 + s / k^2): the pull of a residual fades beyond k
};

struct RobustLoss {
  RobustKernel kernel = RobustKernel::none;
  double width = 2.4477;  ///< k, in standard deviations of the whitened residual (default sqrt(chi2_2(0.95)))

  void validate() const {
    if (!(width > 0.0) || !std::isfinite(width))
      throw invalid_input_error("robust kernel width must be positive and finite, got " + std::to_string(width));
  }
  /// rho(s) for a squared whitened residual s >= 0.
  double cost(double s) const {
    const double k2 = width * width;
    switch (kernel) {
      case RobustKernel::huber: return s <= k2 ? s : 2.0 * width * std::sqrt(s) - k2;
      case RobustKernel::cauchy: return k2 * std::log1p(s / k2);
      case RobustKernel::none: break;
    }
    return s;
  }
  /// rho'(s): the factor's weight in the reweighted normal equations, in (0, 1].
  double weight(double s) const {
    const double k2 = width * width;
    switch (kernel) {
      case RobustKernel::huber: return s <= k2 ? 1.0 : width / std::sqrt(s);
      case RobustKernel::cauchy: return 1.0 / (1.0 + s / k2);
      case RobustKernel::none: break;
    }
    return 1.0;
  }
};

}  // namespace sextant
