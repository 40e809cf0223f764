#include "sextant/core/student_t.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <numbers>

namespace sextant {
namespace {

double density(const StudentTNoise& t, const Eigen::MatrixXd& S, const Eigen::VectorXd& nu) {
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  return std::exp(t.log_density_at_nis(llt, nu.dot(llt.solve(nu))));
}

/// With one degree of freedom in one dimension the t is the Cauchy distribution of scale s:
/// 1 / (pi s (1 + x^2 / s^2)), an independent closed form of the normalization and the tails.
TEST(StudentTNoise, WithOneDegreeOfFreedomInOneDimensionIsTheCauchyDensity) {
  const StudentTNoise cauchy{1.0};
  for (const double s : {0.1, 1.0, 3.0})
    for (const double x : {0.0, 0.5, 2.0, 40.0}) {
      const double expected = 1.0 / (std::numbers::pi * s * (1.0 + x * x / (s * s)));
      EXPECT_NEAR(density(cauchy, Eigen::MatrixXd::Constant(1, 1, s * s), Eigen::VectorXd::Constant(1, x)), expected,
                  1e-12 * expected)
          << s << ", " << x;
    }
}

/// In two dimensions with S = I the density depends on r = |nu| only; its integral over the plane,
/// 2 pi times the integral of p(r) r dr (midpoint rule to r = 2000, where the tail left out of
/// nu = 4's is (1 + r^2 / 4)^-2 = 4e-13), is 1. For another S the density is p_I(L^-1 nu) / |L|.
TEST(StudentTNoise, IsADensityWhoseScaleMatrixEntersByItsDeterminant) {
  const StudentTNoise t{4.0};
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  double integral = 0.0;
  const double h = 1e-3;
  for (double r = 0.5 * h; r < 2000.0; r += h) integral += 2.0 * std::numbers::pi * r * h * density(t, I, Eigen::Vector2d(r, 0.0));
  EXPECT_NEAR(integral, 1.0, 1e-6);
  Eigen::Matrix2d S;
  S << 4.0, 0.6, 0.6, 0.25;
  const Eigen::Matrix2d L = S.llt().matrixL();
  const Eigen::Vector2d nu(1.3, -0.7);
  EXPECT_NEAR(density(t, S, nu), density(t, I, L.triangularView<Eigen::Lower>().solve(nu)) / L.determinant(), 1e-14);
}

/// nu -> infinity is the Gaussian: expanding log Gamma and log(1 + q / nu) in 1 / nu, log t_nu - log N
/// = (d (d - 2) - 2 d q + q^2) / (4 nu) + O(1 / nu^2) at NIS q, d = 2 here. nu = 0 is the Gaussian
/// itself (and leaves the noise as it is).
TEST(StudentTNoise, ManyDegreesOfFreedomAndNoneAreTheGaussian) {
  Eigen::Matrix2d S;
  S << 2.0, 0.3, 0.3, 0.5;
  const Eigen::Vector2d nu(0.8, 1.1);
  const Eigen::LLT<Eigen::Matrix2d> llt(S);
  const double nis = nu.dot(llt.solve(nu));
  EXPECT_EQ(StudentTNoise{}.log_density_at_nis(llt, nis), log_gaussian_at_nis(llt, nis));
  for (const double dof : {1e4, 1e5}) {
    const double gap = StudentTNoise{dof}.log_density_at_nis(llt, nis) - log_gaussian_at_nis(llt, nis);
    EXPECT_NEAR(dof * gap, (nis * nis - 4.0 * nis) / 4.0, 20.0 / dof) << dof;  // the O(1 / nu^2) term, generously
  }
  EXPECT_EQ(StudentTNoise{}.noise_factor(50.0, 2), 1.0);
}

/// The noise's factor is 1 / E[lambda | innovation] = (nu + NIS) / (nu + d): an innovation at its
/// expected NIS (d) leaves the noise as it is, a far one scales it with its NIS.
TEST(StudentTNoise, ScalesTheNoiseByTheInnovationsNormalizedSquare) {
  const StudentTNoise t{4.0};
  EXPECT_DOUBLE_EQ(t.noise_factor(2.0, 2), 1.0);
  EXPECT_DOUBLE_EQ(t.noise_factor(0.0, 2), 4.0 / 6.0);
  EXPECT_DOUBLE_EQ(t.noise_factor(100.0, 3), 104.0 / 7.0);
}

TEST(StudentTNoise, RejectsDegreesOfFreedomThatAreNegativeOrNotFinite) {
  for (const double bad : {-1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    EXPECT_THROW(StudentTNoise{bad}.validate("dof"), invalid_input_error) << bad;
  EXPECT_NO_THROW(StudentTNoise{0.0}.validate("dof"));
  EXPECT_NO_THROW(StudentTNoise{4.0}.validate("dof"));
}

}  // namespace
}  // namespace sextant
