#include "sextant/core/se3.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "sextant/core/concepts.hpp"
#include "sextant/core/se3_space.hpp"

namespace sextant {
namespace {

using se3::Matrix6d;
using se3::Vector6d;

/// Random tangent vectors with rotation angles spread over [0, pi) and some exactly tiny ones.
std::vector<Vector6d> random_tangents(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> angle(0.0, std::numbers::pi - 1e-3);
  std::vector<Vector6d> out;
  for (int i = 0; i < count; ++i) {
    Vector6d xi;
    xi.head<3>() = 3.0 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    const double a = i % 5 == 0 ? 1e-9 * i : angle(rng);
    xi.tail<3>() = a * Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    out.push_back(xi);
  }
  return out;
}

/// d f(xi + d) / d d at d = 0 by central differences, f mapping R^6 to R^6.
template <class F>
Matrix6d numeric_jacobian(F f, double h = 1e-6) {
  Matrix6d J;
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d(i) = h;
    J.col(i) = (f(d) - f(-d)) / (2.0 * h);
  }
  return J;
}

TEST(Se3, HatAndVeeAreInverse) {
  for (const auto& xi : random_tangents(1, 20)) {
    EXPECT_EQ(se3::vee(se3::hat(xi)), xi);
    EXPECT_TRUE(se3::hat(xi).row(3).isZero(0.0));
  }
}

TEST(Se3, LogInvertsExpAndExpInvertsLog) {
  for (const auto& xi : random_tangents(2, 200)) {
    const Eigen::Matrix4d T = se3::exp(xi);
    EXPECT_TRUE((se3::rotation(T).transpose() * se3::rotation(T)).isIdentity(1e-13));
    EXPECT_EQ(T.row(3), Eigen::RowVector4d(0, 0, 0, 1));
    EXPECT_LT((se3::log(T) - xi).norm(), 1e-8 * (1.0 + xi.norm())) << xi.transpose();
    EXPECT_TRUE(se3::exp(se3::log(T)).isApprox(T, 1e-12));
  }
}

TEST(Se3, ExpMatchesTheMatrixExponentialSeries) {
  // exp(xi^) = sum_k (xi^)^k / k!, summed to convergence for moderate xi: checks J_l(phi) rho.
  for (const auto& xi : random_tangents(3, 30)) {
    const Vector6d small = xi / (1.0 + xi.norm());
    const Eigen::Matrix4d X = se3::hat(small);
    Eigen::Matrix4d sum = Eigen::Matrix4d::Identity(), term = Eigen::Matrix4d::Identity();
    for (int k = 1; k < 30; ++k) {
      term = term * X / k;
      sum += term;
    }
    EXPECT_TRUE(se3::exp(small).isApprox(sum, 1e-13)) << small.transpose();
  }
}

TEST(Se3, AdjointMovesAPerturbationAcrossAPose) {
  const auto tangents = random_tangents(4, 40);
  for (std::size_t i = 0; i + 1 < tangents.size(); i += 2) {
    const Eigen::Matrix4d T = se3::exp(tangents[i]);
    const Vector6d xi = 0.3 * tangents[i + 1];
    EXPECT_TRUE((T * se3::exp(xi) * se3::inverse(T)).isApprox(se3::exp(se3::adjoint(T) * xi), 1e-11));
    EXPECT_TRUE(se3::adjoint(se3::inverse(T)).isApprox(se3::adjoint(T).inverse(), 1e-11));
    // ad is the derivative of Ad: Ad(exp(xi^)) = exp(ad(xi)) (series).
    Matrix6d sum = Matrix6d::Identity(), term = Matrix6d::Identity();
    for (int k = 1; k < 40; ++k) {
      term = term * se3::curly_hat(0.2 * xi) / k;
      sum += term;
    }
    EXPECT_TRUE(se3::adjoint(se3::exp(0.2 * xi)).isApprox(sum, 1e-11));
  }
}

TEST(Se3, OdotTurnsHatTimesPointIntoAMatrixTimesXi) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (const auto& xi : random_tangents(6, 20)) {
    const Eigen::Vector4d s(n(rng), n(rng), n(rng), n(rng));
    EXPECT_TRUE((se3::hat(xi) * s).isApprox(se3::odot(s) * xi, 1e-13));
  }
}

TEST(Se3, LeftAndRightJacobiansAreTheDerivativesOfExp) {
  for (const auto& xi : random_tangents(7, 60)) {
    const Eigen::Matrix4d T = se3::exp(xi), T_inv = se3::inverse(T);
    // exp((xi + d)^) = exp((J_l d)^) exp(xi^) to first order: J_l = d log(exp((xi + d)^) T^-1) / d d.
    const Matrix6d left = numeric_jacobian([&](const Vector6d& d) { return se3::log(se3::exp(xi + d) * T_inv); });
    const Matrix6d right = numeric_jacobian([&](const Vector6d& d) { return se3::log(T_inv * se3::exp(xi + d)); });
    EXPECT_TRUE(se3::left_jacobian(xi).isApprox(left, 1e-6)) << xi.transpose();
    EXPECT_TRUE(se3::right_jacobian(xi).isApprox(right, 1e-6)) << xi.transpose();
    EXPECT_TRUE((se3::left_jacobian(xi) * se3::left_jacobian_inverse(xi)).isIdentity(1e-10));
    EXPECT_TRUE((se3::right_jacobian(xi) * se3::right_jacobian_inverse(xi)).isIdentity(1e-10));
    // J_l = Ad(T) J_r (Barfoot eq. 7.93).
    EXPECT_TRUE(se3::left_jacobian(xi).isApprox(se3::adjoint(T) * se3::right_jacobian(xi), 1e-10));
  }
}

TEST(Se3, SeriesAndClosedFormsAgreeAtTheirSwitch) {
  // J_l switches to series below 1e-2 rad: both sides, and the angles where the closed forms
  // would cancel, must match the numeric derivative.
  for (const double a : {1e-6, 1e-4, 1e-3, 0.99e-2, 1.01e-2, 3e-2}) {
    Vector6d xi;
    xi << 0.7, -1.2, 2.0, a * Eigen::Vector3d(0.48, -0.6, 0.64);
    const Matrix6d right = numeric_jacobian(
        [&](const Vector6d& d) { return se3::log(se3::exp(xi + d) * se3::inverse(se3::exp(xi))); }, 1e-7);
    EXPECT_TRUE(se3::left_jacobian(xi).isApprox(right, 1e-7)) << a;
  }
}

TEST(Se3Space, PlusAndMinusAreInverseAndRetractInTheWorldOrBodyFrame) {
  static_assert(StateSpace<Se3Space, Eigen::Matrix4d, 6>);
  static_assert(StateSpace<Se3BodySpace, Eigen::Matrix4d, 6>);
  const auto tangents = random_tangents(8, 40);
  for (std::size_t i = 0; i + 1 < tangents.size(); i += 2) {
    const Eigen::Matrix4d T = se3::exp(tangents[i]);
    const Vector6d d = 0.5 * tangents[i + 1];
    EXPECT_TRUE(Se3Space::plus(T, d).isApprox(se3::exp(d) * T, 1e-12));
    EXPECT_TRUE(Se3BodySpace::plus(T, d).isApprox(T * se3::exp(d), 1e-12));
    EXPECT_LT((Se3Space::minus(Se3Space::plus(T, d), T) - d).norm(), 1e-9 * (1.0 + d.norm()));
    EXPECT_LT((Se3BodySpace::minus(Se3BodySpace::plus(T, d), T) - d).norm(), 1e-9 * (1.0 + d.norm()));
    EXPECT_TRUE(Se3Space::minus(T, T).isZero(1e-12));
    // The two tangents of one perturbation differ by the adjoint: exp(d^) T = T exp((Ad(T^-1) d)^).
    EXPECT_TRUE(Se3BodySpace::minus(Se3Space::plus(T, d), T).isApprox(se3::adjoint(se3::inverse(T)) * d, 1e-9));
  }
}

TEST(Se3Space, PlusKeepsTheRotationOnTheGroupOverManySteps) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  Vector6d step;
  step << 0.1, 0.02, -0.01, 0.013, -0.021, 0.017;
  for (int k = 0; k < 100000; ++k) T = Se3Space::plus(T, step);
  EXPECT_TRUE((se3::rotation(T).transpose() * se3::rotation(T)).isIdentity(1e-13));
  EXPECT_NEAR(se3::rotation(T).determinant(), 1.0, 1e-13);
  EXPECT_FALSE(Se3Space::is_finite(T * std::numeric_limits<double>::quiet_NaN()));
}

}  // namespace
}  // namespace sextant
