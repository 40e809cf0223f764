#pragma once
// Bounds for tests from the chi-square distribution of NEES: a consistent estimate's NEES is
// chi2(dof); for one of `count` estimates checked together, the Bonferroni bound keeps the chance
// that any exceeds it at most alpha.
#include <cstddef>

#include "sextant/core/chi_square.hpp"

namespace sextant::test {

/// chi2_dof quantile at 1 - alpha / count.
inline double nees_bound(int dof, std::size_t count = 1, double alpha = 0.01) {
  return chi_square_quantile(dof, 1.0 - alpha / static_cast<double>(count));
}

}  // namespace sextant::test
