#pragma once
/// \file State-space policies: how a state is moved along a tangent vector (plus) and how two
/// states differ (minus). Back-ends correct in the tangent space and retract with plus: the
/// error-state formulation.

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <utility>

namespace sextant {

/// Wraps an angle to (-pi, pi].
inline double wrap_angle(double angle) {
  const double two_pi = 2.0 * std::numbers::pi;
  double wrapped = std::fmod(angle + std::numbers::pi, two_pi);
  if (wrapped <= 0.0) wrapped += two_pi;
  return wrapped - std::numbers::pi;
}

/// Euler angles name every rotation twice: with the middle angle b of the sequence past pi/2 (after
/// wrapping), (a + pi, +-pi - b, c + pi) is the same rotation, and that name has b within
/// [-pi/2, pi/2] (MRPT's yaw-pitch-roll, Pose3EulerSpace; the globe camera's yxz angles, euler_yxz).
inline bool euler_middle_angle_past_right_angle(double b) { return std::abs(wrap_angle(b)) > std::numbers::pi / 2; }
/// The middle angle of the other name, +-pi - b with b wrapped (see euler_middle_angle_past_right_angle).
inline double mirrored_euler_middle_angle(double b) {
  const double wrapped = wrap_angle(b);
  return (wrapped > 0.0 ? std::numbers::pi : -std::numbers::pi) - wrapped;
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

/// The Jacobians of a space's minus and plus (docs/derivations/state_space_jacobians.md), as manif
/// gives them: with r = minus(a, b),
///   minus_jacobian_first(a, b)  = d minus(plus(a, e), b) / de at e = 0,
///   minus_jacobian_second(a, b) = d minus(a, plus(b, e)) / de at e = 0,
///   plus_jacobian(x, d)         = G with plus(x, d + e) = plus(plus(x, d), G e) to first order in e.
/// A space on a group (Se3Space, Se2WorldSpace) defines them; for an additive chart (plus is +, minus
/// is -, angles wrapped: EuclideanSpace, Se2Space, Pose3EulerSpace, the globe camera's) they are
/// I, -I and I exactly, which these give for a space that does not define them.

/// The dimension of a space's tangent, from minus (which every space has), and the square matrix over it.
template <class Space, class Point>
inline constexpr int tangent_dim_v =
    decltype(Space::minus(std::declval<const Point&>(), std::declval<const Point&>()))::RowsAtCompileTime;
template <class Space, class Point>
using TangentJacobian = Eigen::Matrix<double, tangent_dim_v<Space, Point>, tangent_dim_v<Space, Point>>;

template <class Space, class Point>
TangentJacobian<Space, Point> minus_jacobian_first(const Point& a, const Point& b) {
  if constexpr (requires { Space::minus_jacobian_first(a, b); })
    return Space::minus_jacobian_first(a, b);
  else
    return TangentJacobian<Space, Point>::Identity();
}

template <class Space, class Point>
TangentJacobian<Space, Point> minus_jacobian_second(const Point& a, const Point& b) {
  if constexpr (requires { Space::minus_jacobian_second(a, b); })
    return Space::minus_jacobian_second(a, b);
  else
    return -TangentJacobian<Space, Point>::Identity();
}

template <class Space, class Point, class Tangent>
TangentJacobian<Space, Point> plus_jacobian(const Point& x, const Tangent& d) {
  if constexpr (requires { Space::plus_jacobian(x, d); })
    return Space::plus_jacobian(x, d);
  else
    return TangentJacobian<Space, Point>::Identity();
}

/// An estimate (mean, cov) with its mean in its space's canonical coordinates and its covariance
/// carried along (J cov J^T): a space whose chart names one point several ways defines canonical()
/// and canonical_jacobian() (Pose3EulerSpace); any other space's estimate is returned as it is.
template <class Space, class Estimate>
Estimate in_canonical_coordinates(Estimate estimate) {
  if constexpr (requires { Space::canonical(estimate.mean); }) {
    const auto J = Space::canonical_jacobian(estimate.mean);
    estimate.mean = Space::canonical(estimate.mean);
    estimate.cov = (J * estimate.cov * J.transpose()).eval();
  }
  return estimate;
}

/// Whether minus_jacobian_first<Space> can differ from the identity (the space defines it).
template <class Space, class Point>
inline constexpr bool has_minus_jacobians_v = requires(const Point& a) { Space::minus_jacobian_first(a, a); };

/// Whether plus_jacobian<Space> can differ from the identity (the space defines it).
template <class Space, class Point>
inline constexpr bool has_plus_jacobian_v = requires(const Point& x) { Space::plus_jacobian(x, Space::minus(x, x)); };

}  // namespace sextant
