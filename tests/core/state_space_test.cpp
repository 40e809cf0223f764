#include "sextant/core/state_space.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace sextant
