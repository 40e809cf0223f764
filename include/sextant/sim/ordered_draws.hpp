#pragma once
/// \file Random vectors drawn in a fixed order. A compiler may evaluate function arguments in any
/// order (gcc right to left, clang left to right), so Eigen::Vector2d(unit(rng), unit(rng)) gives
/// different data on different compilers. Simulators and tests draw through this instead, so that
/// the same seed gives the same data everywhere. The last coordinate is drawn first: that is the
/// order gcc used, which made every data set the results up to 2026-11-23 were measured on.

#include <Eigen/Core>

namespace sextant::sim {

template <int N, class Distribution, class Generator>
Eigen::Matrix<double, N, 1> ordered_draws(Distribution& distribution, Generator& rng) {
  Eigen::Matrix<double, N, 1> out;
  for (int i = N - 1; i >= 0; --i) out(i) = distribution(rng);
  return out;
}

}  // namespace sextant::sim
