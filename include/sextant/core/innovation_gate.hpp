#pragma once
/// \file The chi-square test of an innovation, one rule for every back-end (thesis §7.2; Bar-Shalom,
/// Li & Kirubarajan §5.4): an observation whose normalized innovation squared
/// NIS = nu^T S^-1 nu exceeds the chi-square quantile of its dimension at `probability` is an
/// outlier. With probability 0.99, one inlier in a hundred is rejected on average.

#include <Eigen/Cholesky>
#include <algorithm>
#include <string>

#include "sextant/core/chi_square.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"

namespace sextant {

class InnovationGate {
 public:
  /// A gate that lets everything through.
  InnovationGate() = default;
  /// probability in (0, 1) switches the gate on; 0 leaves it off.
  InnovationGate(int dof, double probability) {
    if (!(probability >= 0.0 && probability < 1.0))
      throw invalid_input_error("gate_probability must be in [0, 1) (0 = no gate), got " + std::to_string(probability));
    if (probability > 0.0) threshold_ = chi_square_quantile(dof, probability);
  }

  bool on() const { return threshold_ > 0.0; }
  /// The NIS above which an observation is rejected; 0 when off.
  double threshold() const { return threshold_; }
  bool rejects(double nis) const { return on() && nis > threshold_; }
  /// Whether the innovation nu with covariance factor llt (of S) is an outlier.
  template <class Llt, class Residual>
  bool rejects(const Llt& llt, const Residual& nu) const {
    return on() && mahalanobis_squared(llt, nu) > threshold_;
  }

 private:
  double threshold_ = 0.0;
};

/// log N(nu; 0, S) with the NIS clipped at the gate's threshold (a rejected observation counts as
/// one on the gate's edge: the likelihood of an outlier model that is flat beyond the gate), from
/// the observation's NIS and the Cholesky factor of S. With the gate off, the plain Gaussian one.
template <class Llt>
double gated_log_likelihood(const InnovationGate& gate, const Llt& llt, double nis) {
  return log_gaussian_at_nis(llt, gate.on() ? std::min(nis, gate.threshold()) : nis);
}

}  // namespace sextant
