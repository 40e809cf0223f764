#pragma once
/// \file Exact Jacobians by forward-mode automatic differentiation (Eigen's AutoDiffScalar), for
/// models whose analytic Jacobians are long and error-prone (3D poses with Euler angles). A model
/// writes its function once, templated on the scalar, and gets value and Jacobian in one pass.

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <unsupported/Eigen/AutoDiff>

namespace sextant {

/// Scalar carrying N directional derivatives.
template <int N>
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;

/// Value of a plain or dual scalar.
inline double value_of(double x) { return x; }
template <class Derivatives>
double value_of(const Eigen::AutoDiffScalar<Derivatives>& x) {
  return x.value();
}

/// Wraps an angle to (-pi, pi] by whole turns; the derivative passes through unchanged.
template <class Scalar>
Scalar wrap_angle_generic(const Scalar& angle) {
  const double two_pi = 2.0 * std::numbers::pi;
  const double a = value_of(angle);
  double wrapped = std::fmod(a + std::numbers::pi, two_pi);
  if (wrapped <= 0.0) wrapped += two_pi;
  return angle + ((wrapped - std::numbers::pi) - a);
}

template <int Rows, int Cols>
struct ValueAndJacobian {
  Eigen::Matrix<double, Rows, 1> value;
  Eigen::Matrix<double, Rows, Cols> jacobian;
};

/// f(x) and df/dx at x, where f maps Eigen::Matrix<Dual<N>, N, 1> to Eigen::Matrix<Dual<N>, Rows, 1>.
template <int Rows, int N, class F>
ValueAndJacobian<Rows, N> value_and_jacobian(F f, const Eigen::Matrix<double, N, 1>& x) {
  Eigen::Matrix<Dual<N>, N, 1> seeded;
  for (int i = 0; i < N; ++i) seeded(i) = Dual<N>(x(i), N, i);
  const Eigen::Matrix<Dual<N>, Rows, 1> y = f(seeded);
  ValueAndJacobian<Rows, N> out;
  for (int r = 0; r < Rows; ++r) {
    out.value(r) = y(r).value();
    out.jacobian.row(r) = y(r).derivatives().transpose();
  }
  return out;
}

template <int Rows, int A, int B>
struct ValueAndJacobians {
  Eigen::Matrix<double, Rows, 1> value;
  Eigen::Matrix<double, Rows, A> jacobian_a;  ///< df/da
  Eigen::Matrix<double, Rows, B> jacobian_b;  ///< df/db
};

/// f(a, b) and its Jacobians with respect to a and to b (the shape of every model function: pose
/// and control, pose and landmark, pose and measurement). f takes two Eigen vectors of one dual
/// scalar type and returns an Eigen vector of it.
template <int Rows, int A, int B, class F>
ValueAndJacobians<Rows, A, B> value_and_jacobians(F f, const Eigen::Matrix<double, A, 1>& a,
                                                  const Eigen::Matrix<double, B, 1>& b) {
  Eigen::Matrix<double, A + B, 1> stacked;
  stacked << a, b;
  const auto both = value_and_jacobian<Rows>(
      [&f](const auto& ab) {
        using Scalar = typename std::decay_t<decltype(ab)>::Scalar;
        return f(Eigen::Matrix<Scalar, A, 1>(ab.template head<A>()), Eigen::Matrix<Scalar, B, 1>(ab.template tail<B>()));
      },
      stacked);
  return {both.value, both.jacobian.template leftCols<A>(), both.jacobian.template rightCols<B>()};
}

}  // namespace sextant
