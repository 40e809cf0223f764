#pragma once
/// \file State-space policies: how a state is moved along a tangent vector (plus) and how two
/// states differ (minus). Back-ends correct in the tangent space and retract with plus: the
/// error-state formulation.

#include <Eigen/Core>
#include <cmath>
#include <numbers>

namespace sextant {

/// Wraps an angle to (-pi, pi].
inline double wrap_angle(double angle) {
  const double two_pi = 2.0 * std::numbers::pi;
  double wrapped = std::fmod(angle + std::numbers::pi, two_pi);
  if (wrapped <= 0.0) wrapped += two_pi;
  return wrapped - std::numbers::pi;
}

/// Euclidean R^N: plus is +, minus is -.
template <int N>
struct EuclideanSpace {
  static constexpr int kDim = N;
  using Point = Eigen::Matrix<double, N, 1>;
  using Tangent = Eigen::Matrix<double, N, 1>;

  static Point plus(const Point& x, const Tangent& delta) { return x + delta; }
  static Tangent minus(const Point& a, const Point& b) { return a - b; }
  static bool is_finite(const Point& x) { return x.allFinite(); }
};

}  // namespace sextant
