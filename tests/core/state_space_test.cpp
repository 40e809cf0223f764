#include "sextant/core/state_space.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/pose3_euler_space.hpp"
#include "sextant/core/se2_space.hpp"
#include "sextant/core/se3_space.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/models/se2_world_frame.hpp"

namespace sextant {
namespace {

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  constexpr double pi = std::numbers::pi;
  EXPECT_DOUBLE_EQ(wrap_angle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(wrap_angle(pi), pi);
  EXPECT_DOUBLE_EQ(wrap_angle(-pi), pi);
  EXPECT_NEAR(wrap_angle(3.0 * pi / 2.0), -pi / 2.0, 1e-15);
  EXPECT_NEAR(wrap_angle(-7.0 * pi / 2.0), pi / 2.0, 1e-14);
  EXPECT_NEAR(wrap_angle(100.0), 100.0 - 16.0 * 2.0 * pi, 1e-12);
}

TEST(EuclideanSpace, PlusAndMinusAreInverse) {
  using Space = EuclideanSpace<3>;
  const Eigen::Vector3d a(1.0, -2.0, 3.0), d(0.5, 0.25, -1.0);
  EXPECT_EQ(Space::minus(Space::plus(a, d), a), d);
  EXPECT_TRUE(Space::is_finite(a));
  EXPECT_FALSE(Space::is_finite(Eigen::Vector3d(1.0, std::numeric_limits<double>::infinity(), 0.0)));
}

/// Random points of a space and tangents of a given size (angles away from the wrap and, for the
/// Euler charts, pitch away from its singularity).
template <class Space>
struct Sampler {
  std::mt19937_64 rng{42};
  typename Space::Tangent tangent(double scale) {
    std::uniform_real_distribution<double> u(-scale, scale);
    typename Space::Tangent d;
    for (int i = 0; i < Space::kDim; ++i) d(i) = u(rng);
    return d;
  }
  typename Space::Point point() {
    if constexpr (std::is_same_v<typename Space::Point, Eigen::Matrix4d>)
      return se3::exp(tangent(2.0));
    else
      return Space::plus(typename Space::Point(Space::Point::Zero()), tangent(1.2));
  }
};

/// Central differences of f(e) in the tangent at e = 0, with f's value compared through `minus`.
template <int N, class F, class Minus>
Eigen::Matrix<double, N, N> numeric_jacobian(F f, Minus minus) {
  constexpr double h = 1e-6;
  Eigen::Matrix<double, N, N> J;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> e = Eigen::Matrix<double, N, 1>::Zero();
    e(i) = h;
    J.col(i) = minus(f(e), f(-e)) / (2.0 * h);
  }
  return J;
}

template <class Space>
class StateSpaceJacobians : public ::testing::Test {};
using Spaces = ::testing::Types<EuclideanSpace<3>, Se2Space, Se2WorldSpace, Pose3EulerSpace, Se3Space, Se3BodySpace,
                                EulerCamera12Space>;
TYPED_TEST_SUITE(StateSpaceJacobians, Spaces);

/// minus_jacobian_first/second and plus_jacobian against numeric differentiation, far from the
/// identity (residuals of up to a radian and more, steps of 0.3): where the Jacobian of plus is not the identity,
/// Gauss-Newton, the prior and marginal factors and the filters' covariance after a step need them.
TYPED_TEST(StateSpaceJacobians, MatchNumericDifferentiationAwayFromZero) {
  using Space = TypeParam;
  using Point = typename Space::Point;
  using Tangent = typename Space::Tangent;
  constexpr int N = Space::kDim;
  Sampler<Space> sample;
  const auto tangent_minus = [](const Tangent& a, const Tangent& b) { return Tangent(a - b); };
  for (int trial = 0; trial < 20; ++trial) {
    const Point a = sample.point();
    const Point b = Space::plus(a, sample.tangent(1.0));
    const Tangent d = sample.tangent(0.3);  // (a step past |pitch| = pi/2 would mirror the globe camera's chart)
    const auto first = numeric_jacobian<N>([&](const Tangent& e) { return Space::minus(Space::plus(a, e), b); },
                                           tangent_minus);
    const auto second = numeric_jacobian<N>([&](const Tangent& e) { return Space::minus(a, Space::plus(b, e)); },
                                            tangent_minus);
    const Point moved = Space::plus(a, d);
    const auto plus = numeric_jacobian<N>([&](const Tangent& e) { return Space::plus(a, Tangent(d + e)); },
                                          [&](const Point& p, const Point& q) {
                                            return Tangent(Space::minus(p, moved) - Space::minus(q, moved));
                                          });
    EXPECT_LT((minus_jacobian_first<Space>(a, b) - first).norm(), 1e-6 * (1.0 + first.norm())) << trial;
    EXPECT_LT((minus_jacobian_second<Space>(a, b) - second).norm(), 1e-6 * (1.0 + second.norm())) << trial;
    // plus(x, d + e) = plus(plus(x, d), G e): minus(., plus(x, d)) of it is G e to first order, up to
    // the Jacobian of minus at zero (the identity in every space).
    EXPECT_LT((plus_jacobian<Space>(a, d) - plus).norm(), 1e-6 * (1.0 + plus.norm())) << trial;
  }
}

/// The group spaces' Jacobians are not the identity away from zero (what the fallback would give).
TEST(StateSpaceJacobians, GroupSpacesDifferFromTheAdditiveFallback) {
  const Eigen::Matrix4d a = se3::exp((se3::Vector6d() << 1, 2, 3, 0.3, -0.2, 0.5).finished());
  EXPECT_GT((Se3Space::minus_jacobian_first(a, Eigen::Matrix4d::Identity()) - se3::Matrix6d::Identity()).norm(), 0.1);
  EXPECT_GT((Se2WorldSpace::plus_jacobian(Eigen::Vector3d(4, 5, 0), Eigen::Vector3d(1, 2, 0.3)) -
             Eigen::Matrix3d::Identity()).norm(), 1.0);
  static_assert(has_plus_jacobian_v<Se3Space, Eigen::Matrix4d> && has_plus_jacobian_v<Se2WorldSpace, Eigen::Vector3d>);
  static_assert(!has_plus_jacobian_v<Se2Space, Eigen::Vector3d> && !has_plus_jacobian_v<EuclideanSpace<2>, Eigen::Vector2d>);
  static_assert(has_minus_jacobians_v<Se3Space, Eigen::Matrix4d> && !has_minus_jacobians_v<Se2Space, Eigen::Vector3d>);
}

/// Past 90° of pitch the Euler chart names a rotation a second way; canonical() gives the one
/// ypr_from_rotation gives, and its Jacobian carries a covariance along.
TEST(Pose3EulerSpace, CanonicalNamesTheSameRotationWithPitchWithinNinetyDegrees) {
  using Space = Pose3EulerSpace;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  for (int i = 0; i < 200; ++i) {
    Space::Point x;
    x << 1.0, -2.0, 0.5, angle(rng), angle(rng), angle(rng);
    const Space::Point c = Space::canonical(x);
    EXPECT_LE(std::abs(c(4)), std::numbers::pi / 2);
    EXPECT_TRUE(c.head<3>() == x.head<3>());
    EXPECT_LT((rotation_of<double>(c) - rotation_of<double>(x)).norm(), 1e-12) << x.transpose();
    EXPECT_TRUE(Space::canonical(c) == c);
    if (std::abs(std::abs(x(4)) - std::numbers::pi / 2) < 0.1) continue;  // a step e must not cross the border
    const Space::Tangent e = 1e-6 * (Space::Tangent() << 1, 2, 3, -2, 1.5, 0.7).finished();
    const Space::Tangent through_jacobian =
        Space::minus(Space::plus(c, Space::canonical_jacobian(x) * e), Space::canonical(Space::plus(x, e)));
    EXPECT_LT(through_jacobian.norm(), 1e-12) << x.transpose();
  }
  Gaussian<Space::Point, 6> flipped{(Space::Point() << 0, 0, 0, 0.2, 2.0, -0.3).finished(), Eigen::Matrix<double, 6, 6>::Identity()};
  flipped.cov(4, 3) = flipped.cov(3, 4) = 0.5;
  const auto canonical = in_canonical_coordinates<Space>(flipped);
  EXPECT_NEAR(canonical.mean(4), std::numbers::pi - 2.0, 1e-15);
  EXPECT_EQ(canonical.cov(4, 3), -0.5);
  EXPECT_EQ(canonical.cov(4, 4), 1.0);
  const auto planar = in_canonical_coordinates<Se2Space>(Gaussian<Eigen::Vector3d, 3>{Eigen::Vector3d(0, 0, 3.0), Eigen::Matrix3d::Identity()});
  EXPECT_EQ(planar.mean(2), 3.0);  // one name per point: unchanged
}

}  // namespace
}  // namespace sextant
